"""The command line and the examples run end to end (quick settings)."""

import json

import numpy as np
import pytest

import surrogates
from fowt_env.cli import main


def test_modes_json(tmp_path, capsys):
    out = tmp_path / "modes.json"
    assert main(["modes", "--json", str(out)]) == 0
    table = json.loads(out.read_text())
    labels = {row["label"] for row in table}
    assert {"surge", "pitch", "tower_fa_1", "tower_ss_2"} <= labels
    assert "tower_fa_1" in capsys.readouterr().out


def test_simulate_writes_a_loadable_record(tmp_path):
    out = tmp_path / "rec.npz"
    assert main(["simulate", "--case", "3", "--duration", "20", "--seed", "2", "--effects", "rotor_3p=0",
                 "--out", str(out)]) == 0
    rec = surrogates.Record.load(out)
    assert rec.n_channels == len(surrogates.ALL_CHANNELS) and rec.duration == pytest.approx(20 - 0.0125)
    assert rec.meta["model"]["effects"]["rotor_3p"] == 0.0


def test_episode_saves_measured_and_truth(tmp_path):
    out = tmp_path / "ep.npz"
    assert main(["episode", "--case", "5", "--plane", "FA", "--fault", "scenario:A", "--duration", "5",
                 "--out", str(out)]) == 0
    meas = surrogates.Record.load(out)
    truth = surrogates.Record.load(tmp_path / "ep_truth.npz")
    hidden = np.isnan(meas.y).all(axis=0)
    assert set(np.nonzero(hidden)[0]) == {2, 3, 5, 7, 11, 12, 14, 16}
    assert np.all(np.isfinite(truth.y))


def test_bad_effect_name_is_a_clean_error(capsys):
    assert main(["simulate", "--effects", "warp_drive=1", "--out", "x.npz"]) == 2
    assert "warp_drive" in capsys.readouterr().err


def test_demo_runs_and_writes_the_figure(tmp_path):
    assert main(["demo", "--duration", "60", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "psd_tower_top_acceleration.png").stat().st_size > 10_000



def test_discrepancy_command_names_the_hidden_mooring(tmp_path):
    """The record has catenary mooring, the candidate model linear mooring: the command names the effect (1200 s,
    the workflow's verified record length: at 600 s, with the blades' in-plane side force, the set-down's heave
    mean sits at or below its significance level on some seeds)."""
    rec = tmp_path / "measured.npz"
    assert main(["simulate", "--case", "7", "--duration", "1200", "--seed", "4", "--out", str(rec)]) == 0
    out = tmp_path / "report.json"
    # no --case: the record states its load case (as identify reads it)
    assert main(["discrepancy", str(rec), "--model-effects", "mooring_nonlinear=0", "--candidates",
                 "mooring_nonlinear,rotor_3p", "--seeds", "3", "--json", str(out), "--plot", str(tmp_path)]) == 0
    report = json.loads(out.read_text())
    assert report["effect"] == "mooring_nonlinear"
    assert report["gap_after"] <= 0.5 * report["gap_before"]
    assert (tmp_path / "discrepancy.png").exists()
    with pytest.raises(SystemExit) as exit_:  # a usage error: the subcommand's usage and one line, exit 2
        main(["discrepancy", str(rec), "--case", "99"])
    assert exit_.value.code == 2


# ---------------------------------------------------------------------------------------------- CLI habits (issue 19)

SUBCOMMANDS = ["demo", "simulate", "episode", "discrepancy", "identify", "sense", "compare", "campaign", "modes"]


def _help(command: str) -> str:
    from fowt_env.cli import build_parser

    return build_parser().subcommands[command].format_help()


def test_version(capsys):
    import fowt_env

    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0 and capsys.readouterr().out.strip() == f"fowt-env {fowt_env.__version__}"


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_every_option_is_documented_with_its_default(command):
    from fowt_env.cli import build_parser

    sub = build_parser().subcommands[command]
    for action in sub._actions:
        if not action.option_strings or action.default == "==SUPPRESS==":  # positionals, -h
            continue
        assert action.help, f"{command} {action.option_strings[0]} has no help"
        if action.default not in (None, False) and not action.required:
            text = " ".join(sub._get_formatter()._get_help_string(action).split())
            assert "default" in text, f"{command} {action.option_strings[0]}: default not shown"
    text = _help(command)
    assert "``" not in text and ":func:" not in text and ":class:" not in text


def test_top_level_help_has_no_markup():
    from fowt_env.cli import build_parser

    text = build_parser().format_help()
    assert "``" not in text and "--version" in text


def test_help_imports_no_heavy_module():
    """``fowt-env --help`` must not import the physics, SciPy, Matplotlib, Numba or Dask (it took ~1 s of CPU)."""
    import subprocess
    import sys

    code = ("import sys, fowt_env.cli\n"
            "heavy = {'scipy', 'matplotlib', 'numba', 'dask', 'distributed', 'surrogates', 'estimators', 'control'}\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_unknown_case_is_a_usage_error_without_internal_names(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "--case", "13", "--out", "x.npz"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2
    assert err.startswith("usage: fowt-env simulate") and "1 to 12" in err and "13" in err and " n " not in err


def test_misspelt_option_gets_the_subcommand_usage_and_a_suggestion(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["identify", "rec.npz", "--plnae", "FA"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.startswith("usage: fowt-env identify") and "did you mean --plane?" in err
    with pytest.raises(SystemExit) as exit_:
        main(["idenitfy", "rec.npz"])
    assert exit_.value.code == 2 and "did you mean identify?" in capsys.readouterr().err


def test_text_file_named_npz_gets_no_unsafe_advice(tmp_path):
    bogus = tmp_path / "bogus.npz"
    bogus.write_text("time,TwHt1ALxt\n0,1\n")
    with pytest.raises(SystemExit) as exit_:
        main(["identify", str(bogus)])
    text = str(exit_.value.code)
    assert "bogus.npz" in text and "not an .npz" in text and "pickle" not in text


@pytest.mark.parametrize("command", ["identify", "episode", "sense", "compare"])
def test_plane_in_any_case(command):
    from fowt_env.cli import build_parser

    argv = {"identify": ["identify", "r.npz"], "episode": ["episode", "--out", "e.npz"],
            "sense": ["sense", "r.npz", "--out", "o.npz"], "compare": ["compare"]}[command]
    assert build_parser().parse_args([*argv, "--plane", "fa"]).plane == "FA"
    assert build_parser().parse_args([*argv, "--plane", "Ss"]).plane == "SS"


@pytest.mark.parametrize("spec", ["stuck:TwHt1ALxt", "dropout:0.1", "spike:0.1:1:2", "stuck:TwHt1ALxt:",
                                  "warp:1"])
def test_incomplete_fault_is_rejected(spec, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["episode", "--fault", spec, "--duration", "1", "--out", "e.npz"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.startswith("usage: fowt-env episode") and spec in err
    if spec.startswith("stuck"):
        assert "stuck:CH:START_S" in err


def test_discrepancy_without_a_case_anywhere_is_a_usage_error(tmp_path, capsys):
    t = np.arange(100) * 0.0125
    rec = surrogates.Record(t, np.zeros((100, 1)), ["TwHt9ALxt"], ["m/s^2"], {})
    path = rec.save(tmp_path / "nocase.npz")
    with pytest.raises(SystemExit) as exit_:
        main(["discrepancy", str(path)])
    assert exit_.value.code == 2 and "give --case" in capsys.readouterr().err


def test_simulate_reports_the_simulation_speed(tmp_path, capsys):
    assert main(["simulate", "--duration", "2", "--out", str(tmp_path / "r.npz")]) == 0
    assert "x real time" in capsys.readouterr().out
