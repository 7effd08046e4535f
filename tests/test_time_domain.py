"""The surrogate against OpenFAST's time series, started where OpenFAST starts.

Independent truth: two OpenFAST v5.0.0 runs of the shared OC3 Hywind deck with output from t = 0
(``tools/openfast_time_domain_runs.py``; compact copy at 10 Hz in ``fowt_env/data/openfast_time_domain``): steady
12 m/s wind from the deck's initial conditions (the shared steady-wind run with its start kept) and the parked rotor
without aerodynamics from rest, both in the shared steady run's sea. The surrogate starts from the deck's initial
state and replays each run's own wave elevation; R² = 1 - mean((s - o)²) / var(o) over 20-400 s.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import surrogates
from fowt_env import time_domain as td
from fowt_env.cli import main as cli_main
from fowt_env.validation import surrogate_case

DATA = td.packaged_time_domain_dir()
STEADY = "t_steady12_Hs2p5_Tp10_from0"
PARKED = "t_parked_Hs2p5_Tp10"


def test_the_runs_are_packaged_with_their_start_and_provenance():
    summary = json.loads((DATA / "summary.json").read_text())
    assert set(summary["runs"]) == {STEADY, PARKED}
    for name, info in summary["runs"].items():
        assert len(info["source"]["sha256"]) == 64 and info["source"]["fs_hz"] == pytest.approx(80.0)
        case = json.loads((DATA / f"{name}.case.json").read_text())
        assert case["transient_s"] == 0.0 and case["hs"] == 2.5 and case["wave_seed"] == 1201
        assert set(case["start"]) >= {"PtfmSurge", "PtfmPitch", "RotSpeed"}
        rec = surrogates.Record.load(DATA / f"{name}.npz")
        assert rec.t[0] == pytest.approx(0.0) and rec.duration >= 399.0
        assert rec["PtfmSurge"][0] == pytest.approx(case["start"]["PtfmSurge"], abs=0.05)


@pytest.fixture(scope="module")
def scores() -> dict[tuple[str, str], td.TimeDomainScore]:
    return {(s.run, s.channel): s for s in td.time_domain()}


@pytest.mark.parametrize("channel", ["PtfmSurge", "PtfmHeave", "PtfmPitch", "RotSpeed", "BldPitch1", "GenPwr",
                                     "RotThrust", "TwrBsMyt", "TwHt9ALxt"])
def test_the_operating_turbine_follows_openfasts_series(scores, channel):
    """Steady wind and waves from the deck's initial state: the platform's slow start (its 120 s surge and 30 s
    heave and pitch periods, 4 m of surge), the controller's pitch in and out of fine pitch, the rotor speed and the
    tower-base moment follow OpenFAST's with R² >= 0.9 and the std within 10 %."""
    s = scores[(STEADY, channel)]
    assert s.r2 >= 0.9, (channel, s)
    assert 0.9 <= s.std_ratio <= 1.1, (channel, s)


@pytest.mark.parametrize("channel", ["PtfmSurge", "PtfmPitch", "TwrBsMyt", "TwHt9ALxt", "RotThrust"])
def test_the_parked_turbine_follows_openfasts_series_in_waves(scores, channel):
    """Waves alone (WAMIT excitation and radiation, Morison drag, the additional damping, the catenary lines):
    surge, pitch and the fore-aft tower response follow OpenFAST's with R² >= 0.9; ``RotThrust`` of a parked rotor
    is its weight along the tilted shaft and its inertia (ElastoDyn's definition)."""
    s = scores[(PARKED, channel)]
    assert s.r2 >= 0.9, (channel, s)
    assert 0.9 <= s.std_ratio <= 1.1, (channel, s)


@pytest.mark.xfail(strict=True, reason="OpenFAST's parked spar pumps heave at its 31 s period from pitch (0.06 m "
                                       "std below 0.05 Hz in these waves, 0.28 m in the shared pitch decay) through "
                                       "MAP++ (gone with MAP replaced by its tangent stiffness in HydroDyn's AddCLin; "
                                       "a quasi-static catenary on the recorded motion reproduces MAP's tensions but "
                                       "not the heave): mechanism not found, not modelled")
def test_the_parked_heave_follows_openfasts_series(scores):
    assert scores[(PARKED, "PtfmHeave")].r2 >= 0.5


def test_the_parked_rotor_thrust_is_its_weight_along_the_shaft():
    """Closed form: a parked rotor on a level platform pushes its weight's share ``m g sin(5 deg)`` down the tilted
    shaft (ElastoDyn's ``RotThrust``): 94.0 kN for the NREL 5 MW rotor's 110,000 kg and 5 deg of shaft tilt
    (Jonkman et al. 2009, Table 1-1)."""
    sim = surrogates.simulate(surrogates.FOWTModel(), None, 20.0, 0.05, 0, transient=0.0, noise=False)
    expected = 110_000.0 * 9.80665 * math.sin(math.radians(5.0)) / 1e3
    assert float(np.mean(sim["RotThrust"])) == pytest.approx(expected, rel=0.03)


def test_a_windless_case_is_the_parked_rotor_in_its_sea():
    lc = surrogate_case({"name": "p", "wind_speed": 0.0, "hs": 2.5, "tp": 10.0})
    assert lc.rotor_rpm == 0.0 and lc.wind_speed == 0.0 and lc.hs == 2.5 and lc.turbulence_intensity == 0.0
    assert surrogate_case({"name": "d", "initial": {"PtfmPitch": 5.0}}) is None  # a free decay stays one


def test_bad_input_gets_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="skip"):
        td.time_domain(skip=-1.0)
    with pytest.raises(ValueError, match="no run"):
        td.time_domain(tmp_path)
    with pytest.raises(ValueError, match="matching"):
        td.time_domain(runs=["no_such_run"])


def test_the_cli_prints_and_writes_the_time_domain_scores(tmp_path, capsys):
    out = tmp_path / "td.json"
    assert cli_main(["validate", "time-domain", "--runs", "t_parked", "--json", str(out),
                     "--plot", str(tmp_path / "figs")]) == 0
    text = capsys.readouterr().out
    assert PARKED in text and "PtfmPitch" in text and STEADY not in text
    rows = json.loads(out.read_text())
    assert {r["channel"] for r in rows} >= {"PtfmSurge", "PtfmPitch"} and all(r["run"] == PARKED for r in rows)
    assert (tmp_path / "figs" / f"{PARKED}.png").is_file()


def test_a_folder_of_runs_that_start_at_zero_is_scored_from_the_cli(tmp_path, capsys):
    """``fowt-env validate DIR --time-domain``: a user's own runs (here a copy of the parked one)."""
    import shutil

    for suffix in (".npz", ".case.json"):
        shutil.copyfile(DATA / f"{PARKED}{suffix}", tmp_path / f"{PARKED}{suffix}")
    assert cli_main(["validate", str(tmp_path), "--time-domain"]) == 0
    out = capsys.readouterr().out
    assert PARKED in out and "TwrBsMyt" in out
    scores = td.time_domain(tmp_path, channels=["TwrBsMyt"], skip=50.0)
    assert len(scores) == 1 and scores[0].r2 >= 0.9
