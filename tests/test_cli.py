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
    assert rec.n_channels == 45 and rec.duration == pytest.approx(20 - 0.0125)
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
    """The record has catenary mooring, the candidate model linear mooring: the command names the effect."""
    rec = tmp_path / "measured.npz"
    assert main(["simulate", "--case", "7", "--duration", "300", "--seed", "4", "--out", str(rec)]) == 0
    out = tmp_path / "report.json"
    assert main(["discrepancy", str(rec), "--case", "7", "--model-effects", "mooring_nonlinear=0", "--candidates",
                 "mooring_nonlinear,rotor_3p", "--seeds", "3", "--json", str(out), "--plot", str(tmp_path)]) == 0
    report = json.loads(out.read_text())
    assert report["effect"] == "mooring_nonlinear"
    assert report["gap_after"] <= 0.5 * report["gap_before"]
    assert (tmp_path / "discrepancy.png").exists()
    with pytest.raises(SystemExit, match="load-case number"):  # one line, no traceback
        main(["discrepancy", str(rec), "--case", "99"])
