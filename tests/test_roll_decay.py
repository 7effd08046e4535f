"""The platform's roll mode against OpenFAST's roll free decays, parked and in operation.

The runs are ``tools/openfast_side_decay_runs.py``'s (OpenFAST v5.0.0 on the shared OC3 deck, still water, output
from t = 0), packaged in ``fowt_env/data/openfast_side_decays/``: the parked spar released from 3 deg of roll, and
the turbine operating in steady 12 m/s wind released from 2 deg more roll than its steady state. The surrogate
starts from the same ElastoDyn initial conditions.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt
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
    the first three cycles; measured 29.18 / 29.54 s (-1.2 %; parked -1.5 %), 0.053 / 0.056 (-6 %). With the
    platform's restoring turned into the fixed axes (``surrogates.hydro_axes``'s former form) it was 30.21 s; with
    the mooring's moments about the fixed axes taken for its own roll and yaw, 28.74 s and 0.041; without the rotor's
    force along its lateral in-plane wind and moment across it (:func:`surrogates.aero.inplane_wind_loads`: the
    blades' downwind bend doubles the one and triples the other), 0.048 (-15 %). OpenFAST itself, by hand with its
    blades rigid (FlapDOF1/2 and EdgeDOF off; not shipped), damps the roll with 0.050."""
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


def _rate_regression(r, channel: str) -> np.ndarray:
    """``channel`` regressed on the roll (rad), its rate and its acceleration over 5-150 s of the decay, all
    low-passed at 0.1 Hz: the coefficients per rad, per rad/s and per rad/s^2."""
    t = np.asarray(r.t, float)
    sos = butter(4, 0.1, fs=1.0 / float(np.median(np.diff(t))), output="sos")
    roll = sosfiltfilt(sos, np.deg2rad(np.asarray(r["PtfmRoll"], float)))
    rate = np.gradient(roll, t)
    m = (t >= 5.0) & (t <= 150.0)
    x = np.column_stack([roll[m], rate[m], np.gradient(rate, t)[m], np.ones(m.sum())])
    return np.linalg.lstsq(x, sosfiltfilt(sos, np.asarray(r[channel], float))[m], rcond=None)[0][:3]


def test_the_operating_platform_yaws_with_its_roll_rate_as_openfasts():
    """The yaw's share in quadrature with the roll (per roll rate) is what the rotor's lateral in-plane wind sets:
    the rolling platform moves the hub sideways (~160 m per rad of roll), and the rotor meets that as a lateral
    in-plane wind that yaws it (the moment across the wind, :func:`surrogates.aero.inplane_wind_loads`). Yaw per roll
    and per roll rate within 25 % of OpenFAST's (the issue's yaw criterion); measured -30.4 deg per rad/s, the
    surrogate -24.1 (-40.7 without that moment and force: +34 %), and -45.5 / -41.3 deg per rad (-32.5 without)."""
    rec, sim = _operating()
    of, sur = _rate_regression(rec, "PtfmYaw"), _rate_regression(sim, "PtfmYaw")
    assert -60.0 < of[0] < -30.0 and -40.0 < of[1] < -20.0  # the record's own figures, a guard on the reading
    assert sur[1] == pytest.approx(of[1], rel=0.25)
    assert sur[0] == pytest.approx(of[0], rel=0.25)
