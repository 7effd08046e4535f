"""The platform's roll mode against OpenFAST's roll free decays, parked and in operation.

The runs are ``tools/openfast_side_decay_runs.py``'s (OpenFAST v5.0.0 on the shared OC3 deck, still water, output
from t = 0), packaged in ``fowt_env/data/openfast_side_decays/``: the parked spar released from 3 deg of roll, and
the turbine operating in steady 12 m/s wind released from 2 deg more roll than its steady state. The surrogate
starts from the same ElastoDyn initial conditions.
"""

from __future__ import annotations

import numpy as np
import pytest
from side_decays import decay_model, decay_run  # tests/ is on sys.path (pytest prepend mode)

import surrogates
from fowt_env.validation import DECAY_TOLERANCE, decay_analysis


def _operating():
    rec, case = decay_run("rd_op12_roll2")
    lc = surrogates.operating_case(float(case["wind_speed"]), 0.0, 10.0, turbulence_intensity=0.0)
    sim = surrogates.simulate(decay_model(), lc, float(case["duration_s"]), 0.05, 0, transient=0.0, noise=False,
                              initial=case["start"])
    return rec, sim


def test_the_parked_roll_decay_is_openfasts():
    """Parked, still water: period within 3 % and damping within 25 % (the issue's free-decay criteria); measured
    29.49 / 29.95 s (-1.5 %), 0.051 / 0.047 (+7 %). (Parked the platform is upright: no fixed-axes terms.)"""
    rec, case = decay_run("rd_parked_roll3")
    sim = surrogates.simulate(decay_model(), None, float(case["duration_s"]), 0.05, 0, transient=0.0, noise=False,
                              initial=case["initial"])
    ref = decay_analysis(rec.t, rec["PtfmRoll"])
    sur = decay_analysis(sim.t, sim["PtfmRoll"])
    assert 29.0 < ref.period_s < 31.0  # the record is the roll decay
    assert sur.period_s == pytest.approx(ref.period_s, rel=DECAY_TOLERANCE["period"])
    assert sur.damping_ratio == pytest.approx(ref.damping_ratio, rel=DECAY_TOLERANCE["damping"])


def test_the_operating_roll_decay_is_openfasts():
    """Operating in steady 12 m/s wind, still water: period within 3 % and damping within 25 % of OpenFAST's over
    the first three cycles; measured 29.17 / 29.54 s (-1.3 %; parked -1.5 %), 0.048 / 0.056 (-15 %). With the
    platform's restoring turned into the fixed axes (``surrogates.hydro_axes``'s former form) it was 30.21 s; with
    the mooring's moments about the fixed axes taken for its own roll and yaw, 28.74 s and 0.041."""
    rec, sim = _operating()
    ref = decay_analysis(rec.t, rec["PtfmRoll"])
    sur = decay_analysis(sim.t, sim["PtfmRoll"])
    assert 29.0 < ref.period_s < 30.0  # the record is the operating roll decay
    assert sur.period_s == pytest.approx(ref.period_s, rel=DECAY_TOLERANCE["period"])
    assert sur.damping_ratio == pytest.approx(ref.damping_ratio, rel=DECAY_TOLERANCE["damping"])


def test_the_operating_platform_yaws_with_its_roll_as_openfasts():
    """In the operating roll decay (5-80 s, well below the yaw mode) OpenFAST's yaw follows the roll by +0.16
    deg/deg (regression slope). Within 0.1 deg/deg; measured +0.155. The pitched spar's roll and yaw are coupled
    only through what acts off its axis: the lines act at the fairlead centre on the axis, so their moment about the
    fixed vertical (the mean line force times the fairlead's sideways shift as the spar rolls, ~0.26 MN m at the
    steady state) has no share about the spar's own axis. With that moment taken for the yaw the surrogate yawed
    +0.54 deg/deg, and with the platform's restoring turned into the fixed axes (``surrogates.hydro_axes``'s
    former form) -0.38."""
    rec, sim = _operating()

    def slope(r):
        t = np.asarray(r.t)
        m = (t > 5.0) & (t < 80.0)
        roll = np.asarray(r["PtfmRoll"])[m]
        yaw = np.asarray(r["PtfmYaw"])[m]
        roll, yaw = roll - roll.mean(), yaw - yaw.mean()
        return float(np.dot(yaw, roll) / np.dot(roll, roll))

    assert 0.1 < slope(rec) < 0.2
    assert slope(sim) == pytest.approx(slope(rec), abs=0.1)
