"""The steady 12 m/s run in five seas of one spectrum: the surrogate against OpenFAST's expectation, not one sea.

OpenFAST v5.0.0 on the shared OC3 deck, steady 12 m/s wind (shear 0.2), JONSWAP Hs 2.5 m, Tp 10 s, 300 s after a
100 s start-up from the deck's initial conditions, wave seeds 1201 (the shared ``d_steady12_Hs2p5_Tp10``) to 1205
(``tools/openfast_steady_seed_runs.py``; packaged in ``fowt_env/data/openfast_steady_seas``). Near rated the
platform's slow surge is a limit cycle in both models, so one 300 s sea holds two or three of its cycles: OpenFAST's
own slow (< 0.05 Hz) std over the five seas is 1.99-3.20 m in surge, 0.60-0.92 deg in blade pitch and
0.0136-0.0180 deg in yaw, the shared sea the lowest in each. The surrogate (8 seeds per sea, each in its sea's
realised height) is compared with OpenFAST's mean over the seas (:func:`fowt_env.validation.pooled_over_seas`),
with the issue-15 tolerances (15 %; 25 % for yaw, roll and the side-to-side moment).
"""

from __future__ import annotations

import pytest

from fowt_env.validation import ValidationReport, pooled_over_seas, validate


@pytest.fixture(scope="module")
def pooled() -> dict[tuple[str, str], dict]:
    report = validate("steady-seas", seeds=8)
    rows = pooled_over_seas(report)
    assert rows and len(rows[0]["runs"]) == 5  # the five seas form one ensemble
    return {(r["channel"], r["statistic"]): r for r in rows}


# measured at 0ecf84f: 1.08, 1.11, 1.07, 1.09, 1.11, 1.13 (and std 1.08, 1.11, 1.09, 1.07, 1.11, 1.00); since the
# rotor's in-plane wind loads (surrogates.aero.inplane_wind_loads) 1.08, 1.11, 1.07, 1.09, 1.11, 1.06 (yaw std 1.01)
SLOW = [("PtfmSurge", 0.15), ("PtfmPitch", 0.15), ("BldPitch1", 0.15), ("RotSpeed", 0.15), ("TwrBsMyt", 0.15),
        ("PtfmYaw", 0.25)]


@pytest.mark.parametrize(("channel", "tol"), SLOW)
def test_slow_response_in_steady_wind_is_openfasts_over_five_seas(pooled, channel, tol):
    """Below 0.05 Hz and in total: the limit cycle near rated and what it drives, pooled over the seas. (Against
    the shared sea alone the slow yaw was 1.26x, outside 25 %, and is 1.17x since the rotor's in-plane wind loads;
    OpenFAST's other four seas give 0.96-1.18x.)"""
    for stat in ("std:platform", "std"):
        row = pooled[(channel, stat)]
        assert row["ratio"] == pytest.approx(1.0, abs=tol), (channel, stat, row["ratio"], row["openfast"])


def test_wave_band_in_steady_wind_is_openfasts_over_five_seas(pooled):
    """0.05-0.25 Hz: measured 0.95-1.06 for surge aside (not graded there), heave, pitch, yaw, blade pitch, rotor
    speed and the fore-aft tower-base moment."""
    for channel in ("PtfmHeave", "PtfmPitch", "PtfmYaw", "BldPitch1", "RotSpeed", "TwrBsMyt"):
        row = pooled[(channel, "std:wave")]
        assert row["ratio"] == pytest.approx(1.0, abs=0.15), (channel, row["ratio"])


@pytest.mark.xfail(strict=True, reason="the steady-wind roll at its resonance (0.03-0.05 Hz) is ~1.8x OpenFAST's "
                   "over five seas (pooled roll < 0.05 Hz 1.53x, side-to-side tower-base moment 1.37x; 1.75x and "
                   "1.53x before the rotor's in-plane wind loads), mostly the start-up's ring-down from zero roll "
                   "(0.009 deg from the equilibrium), which the surrogate damps less (envelope damping 0.040-0.058 "
                   "against OpenFAST's 0.042-0.086 from t = 0 in the same five seas); the shared sea, where "
                   "OpenFAST's own roll is the largest of the five, hides it (1.06x)")
def test_slow_roll_in_steady_wind_is_openfasts_over_five_seas(pooled):
    for channel in ("PtfmRoll", "TwrBsMxt"):
        row = pooled[(channel, "std:platform")]
        assert row["ratio"] == pytest.approx(1.0, abs=0.25), (channel, row["ratio"])


def _report(runs: dict[str, dict], values: dict[str, tuple[float, float]]) -> ValidationReport:
    from fowt_env.validation import Comparison

    rep = ValidationReport()
    rep.runs = [{"name": n, "kind": "operating", "case": c} for n, c in runs.items()]
    for n, (of, sur) in values.items():
        rep.comparisons.append(Comparison(n, "PtfmSurge", "m", "std:platform", of, sur, 0.1, 0.15 * of, "15 %"))
    return rep


def test_pooling_groups_seas_of_one_case_only():
    base = {"wind_speed": 12.0, "hs": 2.5, "tp": 10.0}
    runs = {"a": {**base, "name": "a", "wave_seed": 1, "hs": 2.9}, "b": {**base, "name": "b", "wave_seed": 2},
            "c": {**base, "name": "c", "wave_seed": 3, "wind_speed": 18.0}}
    rows = pooled_over_seas(_report(runs, {"a": (2.0, 2.6), "b": (3.0, 2.9), "c": (1.0, 5.0)}))
    assert len(rows) == 1 and rows[0]["runs"] == ["a", "b"]  # c is another case: alone, not pooled
    assert rows[0]["ratio"] == pytest.approx((2.6 + 2.9) / (2.0 + 3.0))
    assert rows[0]["passed"] is True  # 1.10 within 15 %; run a alone (1.30) would not be
    assert rows[0]["openfast_cv"] == pytest.approx(0.7071 / 2.5, rel=1e-3)
