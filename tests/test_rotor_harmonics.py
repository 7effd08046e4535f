"""The rotor's 3P loads on the tower across the operating range, against OpenFAST in steady wind at 8-18 m/s.

The runs are ``tools/openfast_rotor_harmonics_runs.py``'s (OpenFAST v5.0.0 on the shared OC3 deck, steady wind
with the deck's shear exponent 0.2, still water, 160 s from near the steady state), packaged in
``fowt_env/data/openfast_rotor_harmonics/`` with the rotor azimuth unwrapped. Both models' lines are demodulated
against their own azimuth over the last 60 s (OpenFAST's ``Azimuth``; the surrogate's integrated from its rotor
speed, started at 0: the amplitudes do not depend on the phase).
"""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest
from side_decays import decay_model  # tests/ is on sys.path (pytest prepend mode): validate's default model

import surrogates
from fowt_env.io import load_record
from fowt_env.validation import azimuth_from_rotor_speed, harmonic_amplitude

DATA = resources.files("fowt_env") / "data" / "openfast_rotor_harmonics"
SPEEDS = (8, 10, 12, 14, 18)
WINDOW_S = 60.0


def _amplitude(t: np.ndarray, azimuth_deg: np.ndarray, x: np.ndarray) -> float:
    """The 3P amplitude over the last :data:`WINDOW_S`."""
    return harmonic_amplitude(t, azimuth_deg, x, order=3, window_s=WINDOW_S)


def _openfast(speed: int) -> dict[str, float]:
    rec = load_record(DATA / f"h_st{speed:02d}.npz")
    t = np.asarray(rec.t)
    return {ch: _amplitude(t, np.asarray(rec["Azimuth"]), np.asarray(rec[ch])) for ch in ("TwrBsMxt", "RotThrust")}


def _surrogate(speed: int) -> dict[str, float]:
    case = json.loads((DATA / f"h_st{speed:02d}.case.json").read_text())
    lc = surrogates.operating_case(float(case["wind_speed"]), 0.0, 10.0, turbulence_intensity=0.0)
    sim = surrogates.simulate(decay_model(), lc, float(case["duration_s"]), 0.0125, 0, transient=0.0, noise=False,
                              initial={**case["start"], "Azimuth": 0.0})
    t = np.asarray(sim.t)
    azimuth = azimuth_from_rotor_speed(t, sim["RotSpeed"])
    return {ch: _amplitude(t, azimuth, np.asarray(sim[ch])) for ch in ("TwrBsMxt", "RotThrust")}


@pytest.fixture(scope="module")
def lines() -> dict[int, tuple[dict[str, float], dict[str, float]]]:
    return {u: (_openfast(u), _surrogate(u)) for u in SPEEDS}


def test_the_packaged_runs_are_the_steady_operating_points():
    """Each record is OpenFAST settled at its case's steady wind: below rated at the optimal tip-speed ratio (the
    deck's region-2 torque law: 8.9 and 10.9 rpm at 8 and 10 m/s), above it at 12.1 rpm; the azimuth unwrapped."""
    for u in SPEEDS:
        rec = load_record(DATA / f"h_st{u:02d}.npz")
        t = np.asarray(rec.t)
        m = t > t[-1] - WINDOW_S
        rpm = np.asarray(rec["RotSpeed"])[m]
        tsr = rpm.mean() * math.pi / 30.0 * 63.0 / u
        if u < 11:
            assert 7.0 < tsr < 8.0, u  # the deck's optimal tip-speed ratio, ~7.5
        else:
            assert rpm.mean() == pytest.approx(12.1, abs=0.1), u
        assert rpm.std() < 0.1, u  # settled (at 12 m/s the platform's slow surge still swings it by +-0.1 rpm)
        assert np.all(np.diff(np.asarray(rec["Azimuth"])) > 0.0)  # unwrapped


def test_the_side_to_side_3p_line_follows_openfast_across_the_operating_range(lines):
    """The tower base's side-to-side 3P moment (``TwrBsMxt``) within a factor 1.6 of OpenFAST's at each of
    8, 10, 12, 14 and 18 m/s. OpenFAST: 198, 453, 345, 378, 646 kN m; the surrogate 140, 291, 298, 407, 753
    (0.64-1.16x) with its side force following ``V^2 dQ/dV`` (:func:`surrogates.simulate.side_force_law`); scaled
    with the thrust it was 403, 562, 302, 204, 81 (2.03x at 8 m/s, 0.13x at 18 m/s)."""
    for u, (of, sur) in lines.items():
        assert of["TwrBsMxt"] / 1.6 < sur["TwrBsMxt"] < 1.6 * of["TwrBsMxt"], u


def test_the_side_to_side_3p_line_rises_above_rated_as_openfasts(lines):
    """From 8 to 18 m/s OpenFAST's side-to-side 3P moment rises 3.3-fold (while the thrust falls above rated);
    the surrogate's rise within a factor 2 of it (measured 5.4, its 8 m/s line being the low one; scaled with the
    thrust the side force fell and with it the line, 5-fold)."""
    rise_of = lines[18][0]["TwrBsMxt"] / lines[8][0]["TwrBsMxt"]
    rise_sur = lines[18][1]["TwrBsMxt"] / lines[8][1]["TwrBsMxt"]
    assert rise_of > 2.0
    assert rise_of / 2.0 < rise_sur < 2.0 * rise_of


def test_the_3p_thrust_is_openfasts_within_a_factor_two(lines):
    """The collective 3P thrust (``RotThrust``) within a factor 2 of OpenFAST's at each speed (OpenFAST 2.8, 8.9,
    9.8, 10.6, 13.7 kN, the surrogate 5.1, 9.4, 9.0, 8.6, 9.0: the measured harmonics scale with the thrust and
    hold the tower shadow's share, the sampled shear carries the rest): a guard on the harmonics' other terms."""
    for u, (of, sur) in lines.items():
        assert of["RotThrust"] / 2.0 < sur["RotThrust"] < 2.0 * of["RotThrust"], u


def test_harmonic_amplitude_recovers_a_known_line_whatever_the_azimuths_wrap():
    """Closed form: a 3P line of amplitude 2.0 on a constant, a slow swing and a 1P line; the same from the
    wrapped and the unwrapped azimuth and from any starting angle; clear errors for bad input."""
    t = np.arange(0.0, 60.0, 0.0125)
    az = 72.6 * t + 40.0  # 12.1 rpm
    x = 5.0 + 2.0 * np.cos(np.radians(3.0 * az) + 0.4) + 0.8 * np.sin(0.2 * t) + 0.5 * np.cos(np.radians(az))
    assert harmonic_amplitude(t, az, x) == pytest.approx(2.0, rel=2e-3)
    assert harmonic_amplitude(t, az % 360.0, x) == pytest.approx(2.0, rel=2e-3)
    assert harmonic_amplitude(t, az, x, order=1) == pytest.approx(0.5, rel=5e-2)  # the slow swing leaks a little
    with pytest.raises(ValueError, match="finite"):
        harmonic_amplitude(t, az, np.where(t > 30.0, np.nan, x))
    with pytest.raises(ValueError, match="order"):
        harmonic_amplitude(t, az, x, order=0)
