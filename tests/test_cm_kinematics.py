"""The platform's second-order CM kinematics (effect ``cm_kinematics``): a closed form and OpenFAST's pitch decay."""

from __future__ import annotations

import numpy as np
import pytest

import surrogates
from fowt_env.validation import load_reference


def _pitch_decay(strength: float, duration: float = 60.0) -> surrogates.Record:
    model = surrogates.FOWTModel(effects={"cm_kinematics": strength})
    return surrogates.simulate(model, None, duration=duration, dt=0.0125, transient=0.0, noise=False, seed=0,
                               initial={"PtfmPitch": 5.0})


def test_heave_follows_the_rising_centre_of_mass_in_closed_form():
    """Released at 5 deg pitch from rest, the structure's centre of mass (z_G < 0) is accelerated upwards by
    M z_G theta theta'' at first: the heave equation's first-step force, divided by the heave mass (structure +
    added mass), gives the initial heave acceleration z''(0) = M z_G theta_0 theta''(0) / (M + A33), with
    theta''(0) read from the pitch itself. Without the effect the heave does not move at first (a spar has no
    linear heave-pitch coupling)."""
    st = surrogates.FOWTModel().system(None).structure
    m_zg = st.mass[0, 4] - st.data.added_mass[0, 4]  # M z_G, kg m
    m33 = st.mass[2, 2]
    assert m_zg < 0.0
    on, off = _pitch_decay(1.0, 4.0), _pitch_decay(0.0, 4.0)
    t = on.t - on.t[0]
    sel = t <= 1.0
    theta = np.deg2rad(np.asarray(on["PtfmPitch"]))
    thdd0 = 2.0 * np.polyfit(t[sel], theta[sel], 2)[0]
    zdd_on = 2.0 * np.polyfit(t[sel], np.asarray(on["PtfmHeave"])[sel], 2)[0]
    zdd_off = 2.0 * np.polyfit(t[sel], np.asarray(off["PtfmHeave"])[sel], 2)[0]
    expected = m_zg * theta[0] * thdd0 / m33
    assert expected > 0.0  # the centre of mass rises: the reference point heaves up
    assert zdd_on - zdd_off == pytest.approx(expected, rel=0.1)


def test_openfast_pitch_decay_heave_needs_the_cm_kinematics():
    """OpenFAST's 5 deg pitch decay (packaged record): the platform heaves +-0.2..0.3 m at twice the pitch
    frequency in the first minute. With cm_kinematics the surrogate's heave follows it (R^2 >= 0.8 over the first
    60 s; measured 0.94), without it the heave stays within a few cm (R^2 < 0.3; measured 0.14)."""
    run = load_reference(runs=["b_decay_pitch5deg"])[0][0]
    rec = run.record

    def r2(sim: surrogates.Record) -> float:
        ref = np.interp(sim.t, rec.t, rec["PtfmHeave"])
        got = np.asarray(sim["PtfmHeave"])
        return 1.0 - float(np.var(got - ref) / np.var(ref))

    assert r2(_pitch_decay(1.0)) >= 0.8
    assert r2(_pitch_decay(0.0)) < 0.3
