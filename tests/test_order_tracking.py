"""Computed order tracking (estimators.order_tracking) against closed forms and a known mixed signal.

Truths used: the azimuth of a linearly ramping speed (a quadratic), a rotor-locked cosine ``cos(k psi)`` that
is an exact line at order ``k`` once resampled, and a synthetic record (a randomly excited resonance plus a 3P
load on a rotor whose speed wanders with a known law) whose only rotor-locked line is order 3.
"""

from __future__ import annotations

import doctest

import numpy as np
import pytest
from scipy import signal

import estimators.order_tracking as ot
from estimators import harmonic_candidates, resample_to_azimuth, rotor_azimuth, rotor_harmonics


def test_azimuth_of_a_ramping_speed_is_the_quadratic():
    dt, t = 0.01, np.arange(0.0, 50.0, 0.01)
    w = 1.0 + 0.02 * t  # rad/s
    assert rotor_azimuth(w, dt) == pytest.approx(t + 0.01 * t**2, abs=1e-9)


def test_rotor_locked_cosine_is_a_line_in_azimuth():
    dt, t = 0.05, np.arange(0.0, 300.0, 0.05)
    w = 1.3 + 0.2 * np.sin(2 * np.pi * t / 40.0)
    psi = rotor_azimuth(w, dt)
    ang = resample_to_azimuth(np.c_[np.cos(3 * psi), np.sin(psi)], dt, rotor_speed=w)
    assert ang.y.shape == (t.size, 2)
    assert np.diff(ang.azimuth) == pytest.approx(np.full(t.size - 1, psi[-1] / (t.size - 1)))
    assert ang.y[:, 0] == pytest.approx(np.cos(3 * ang.azimuth), abs=1e-4)
    assert ang.y[:, 1] == pytest.approx(np.sin(ang.azimuth), abs=1e-4)
    assert ang.mean_speed == pytest.approx(psi[-1] / (t[-1] - t[0]))
    assert ang.dt == pytest.approx(dt)  # as many samples as the input, over the same span
    lo, hi = ang.speed_percentiles_hz
    assert 1.1 / (2 * np.pi) < lo < ang.rotor_frequency_hz < hi < 1.5 / (2 * np.pi)
    # an azimuth given directly (e.g. OpenFAST's Azimuth channel, unwrapped) gives the same result
    same = resample_to_azimuth(np.c_[np.cos(3 * psi), np.sin(psi)], dt, azimuth=psi + 2.0)
    assert same.y == pytest.approx(ang.y, abs=1e-9)


def _turbine_like(seed: int, duration: float = 1200.0, dt: float = 0.05):
    """A 0.49 Hz resonance (zeta 1 %) under white noise + a 3P load on a wandering rotor, 3 channels."""
    rng = np.random.default_rng(seed)
    n = int(duration / dt)
    # rotor speed: 12.1 rpm with a slow random wander of about 8 % (std), like near-rated turbulence
    slow = signal.lfilter([0.002], [1.0, -0.998], rng.standard_normal(n))
    w = 12.1 * np.pi / 30 * (1.0 + 0.08 * slow / slow.std())
    psi = rotor_azimuth(w, dt)
    wn, zeta = 2 * np.pi * 0.49, 0.01
    b, a = signal.cont2discrete(([wn**2], [1.0, 2 * zeta * wn, wn**2]), dt, method="bilinear")[:2]
    q = signal.lfilter(np.ravel(b), a, rng.standard_normal(n))
    q /= q.std()
    shape_mode, shape_3p = np.array([1.0, 0.6, 0.2]), np.array([0.3, 0.8, 1.0])
    Y = (np.outer(q, shape_mode) + 0.7 * np.outer(np.cos(3 * psi + 0.3), shape_3p)
         + 0.2 * rng.standard_normal((n, 3)))
    return Y, dt, w


@pytest.mark.parametrize("seed", [0, 1])
def test_a_smeared_3p_band_is_a_harmonic_in_the_order_domain(seed):
    Y, dt, w = _turbine_like(seed)
    f3 = 3 * np.mean(w) / (2 * np.pi)
    # in time, the 3P band (+-8 % speed) is no undamped line at any delay
    in_time = harmonic_candidates(Y, dt, delays=(30, 40, 50), rank=12)
    assert not [r for r in in_time if abs(r["frequency_hz"] - f3) < 0.15 * f3]
    rows = rotor_harmonics(Y, dt, rotor_speed=w, delays=(30, 40, 50), rank=12)
    assert len(rows) == 1
    (h,) = rows
    assert h["order"] == pytest.approx(3.0, abs=0.01)
    assert h["frequency_hz"] == pytest.approx(f3, rel=0.01)
    assert h["phase_locking"] > 0.9 and h["damping_ratio"] < 0.01 and h["kind"] == "harmonic"
    lo, hi = h["frequency_range_hz"]
    assert lo < 0.93 * f3 and hi > 1.07 * f3  # the band the line sweeps in time: +-1.64 sigma of 8 %


def test_constant_speed_order_tracking_changes_nothing():
    dt, t = 0.05, np.arange(0.0, 600.0, 0.05)
    rng = np.random.default_rng(3)
    w = np.full(t.size, 1.25)
    Y = np.c_[np.cos(3 * 1.25 * t), np.cos(3 * 1.25 * t + 1.0)] + 0.05 * rng.standard_normal((t.size, 2))
    ang = resample_to_azimuth(Y, dt, rotor_speed=w)
    assert ang.y == pytest.approx(Y, abs=1e-9)
    (h,) = rotor_harmonics(Y, dt, rotor_speed=w, rank=4)
    assert h["order"] == pytest.approx(3.0, abs=1e-3)


def test_bad_input_gets_clear_errors():
    dt = 0.05
    Y = np.random.default_rng(0).standard_normal((100, 2))
    w = np.full(100, 1.2)
    with pytest.raises(ValueError, match="exactly one"):
        resample_to_azimuth(Y, dt)
    with pytest.raises(ValueError, match="exactly one"):
        resample_to_azimuth(Y, dt, rotor_speed=w, azimuth=np.arange(100.0))
    with pytest.raises(ValueError, match="turning rotor"):
        rotor_azimuth(np.r_[w[:50], np.zeros(50)], dt)
    with pytest.raises(ValueError, match=r"finite: NaN/inf at samples \[7\]"):
        rotor_azimuth(np.where(np.arange(100) == 7, np.nan, w), dt)
    with pytest.raises(ValueError, match="99 samples, the data have 100"):
        resample_to_azimuth(Y, dt, rotor_speed=w[:99])
    with pytest.raises(ValueError, match="increase strictly"):
        resample_to_azimuth(Y, dt, azimuth=np.mod(np.arange(100.0), 6.0))
    with pytest.raises(ValueError, match="Y must be finite"):
        rotor_harmonics(np.where(np.arange(100)[:, None] == 3, np.nan, Y), dt, rotor_speed=w)
    with pytest.raises(ValueError, match="1-D"):
        rotor_azimuth(w[:, None], dt)


def test_docstring_example_runs():
    assert doctest.testmod(ot).failed == 0


def test_many_channels_are_tracked_on_their_leading_components():
    """Issue 19: 36 channels are reduced to 8 principal components before the Hankel-DMD (Gram matrices of
    8 x delays rows, not 36 x delays): the 3P line at order 3 and 3 x mean 1P, the same as with every channel."""
    Y3, dt, w = _turbine_like(0, duration=600.0)
    f3 = 3 * np.mean(w) / (2 * np.pi)
    rng = np.random.default_rng(5)
    Y = Y3 @ rng.uniform(0.2, 1.0, (3, 36)) + 0.05 * rng.standard_normal((Y3.shape[0], 36))
    reduced = rotor_harmonics(Y, dt, rotor_speed=w, delays=(30, 40, 50), rank=12)
    full = rotor_harmonics(Y, dt, rotor_speed=w, delays=(30, 40, 50), rank=12, components=None)
    assert [round(h["order"], 2) for h in reduced] == [round(h["order"], 2) for h in full] == [3.0]
    assert reduced[0]["frequency_hz"] == pytest.approx(f3, rel=0.01)
    assert reduced[0]["frequency_hz"] == pytest.approx(full[0]["frequency_hz"], rel=1e-3)
    with pytest.raises(ValueError, match="components"):
        rotor_harmonics(Y, dt, rotor_speed=w, components=0)
