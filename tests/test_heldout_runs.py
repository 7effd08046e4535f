"""The surrogate on OpenFAST runs nothing in it was calibrated on: the packaged held-out runs.

Independent truth: OpenFAST v5.0.0 on the shared OC3 deck with new TurbSim and wave seeds at 10, 12, 14 and 18 m/s
(``tools/openfast_heldout_runs.py``; compact copy in ``fowt_env/data/openfast_heldout``, statistics at 80 Hz). The
surrogate's physics and gains were calibrated on the shared runs (8, 12, 18 m/s, one seed each) and on AeroDyn; at
10 and 14 m/s it has never been compared with OpenFAST, and the other two runs are other realisations.
"""

from __future__ import annotations

import json

import pytest

import surrogates
from fowt_env import validation
from fowt_env.cli import main as cli_main

HELDOUT = validation.packaged_heldout_dir()
RUNS = ("c_op10_Hs2p5_Tp10_s1001", "c_op12_Hs2p5_Tp10_s1203", "c_op14_Hs3p0_Tp10p5_s1401",
        "c_op18_Hs4p0_Tp11_s1802")


def test_the_heldout_runs_are_packaged_with_their_provenance():
    summary = json.loads((HELDOUT / "summary.json").read_text())
    assert set(summary["runs"]) == set(RUNS)
    for name, info in summary["runs"].items():
        assert len(info["source"]["sha256"]) == 64 and info["source"]["fs_hz"] == pytest.approx(80.0)
        case = json.loads((HELDOUT / f"{name}.case.json").read_text())
        assert case["turbulence_seed"] == case["wave_seed"] and "not in the shared set" in case["source"]
        assert (HELDOUT / f"{name}.inflow.npz").is_file()  # the replay's wind field
    runs, skipped = validation.load_reference("heldout")
    assert sorted(r.name for r in runs) == sorted(RUNS) and not skipped


@pytest.fixture(scope="module")
def report() -> validation.ValidationReport:
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS, effects={"rotor_1p": 0.0})
    return validation.validate("heldout", model=model, seeds=8)  # the 8 seeds (4 leave the scatter too narrow)


def test_the_operating_means_hold_on_runs_never_calibrated_on(report):
    """Rotor speed, pitch, power, thrust, surge, pitch and tower-base moment within the issue's 5 % (0.5 deg)."""
    means = [c for c in report.graded if c.statistic == "mean"]
    assert len(means) >= 4 * 6
    assert [c for c in means if not c.passed] == []


def test_most_spread_checks_hold_on_runs_never_calibrated_on(report):
    """Each run's standard deviations, bands and DELs: at most 6 of its graded checks fail (a perfect model fails
    7.4 of ~170 on the shared runs by chance alone, `tools/validate_perfect_model.py`), and over the four runs at
    least 90 % pass."""
    graded = report.graded
    for run in RUNS:
        fails = [c for c in graded if c.run == run and c.passed is False]
        assert len(fails) <= 6, [(c.channel, c.statistic, round(c.ratio, 2)) for c in fails]
    assert sum(bool(c.passed) for c in graded) >= 0.9 * len(graded)


def test_the_cli_validates_the_heldout_runs(capsys):
    assert cli_main(["validate", "heldout", "--seeds", "1", "--duration", "120",
                     "--runs", "c_op18_Hs4p0_Tp11_s1802"]) == 0
    assert "c_op18_Hs4p0_Tp11_s1802" in capsys.readouterr().out
