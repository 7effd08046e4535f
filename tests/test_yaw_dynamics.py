"""The platform's yaw in operation: HydroDyn's matrices in the fixed axes and the blades' cyclic flap lag.

Independent truth: closed forms (a rotation of the axes, the phase of a damped oscillator forced below its
resonance), the WAMIT added mass of the deck and, where ``../shared`` holds them, OpenFAST's own records: the
yaw-bearing moment over the yaw angle (the platform's dynamic stiffness) crosses zero at 0.08-0.11 Hz, and the
steady-wind run's yaw answers the platform's pitch rate with 0.39-0.54 s at 0.08-0.12 Hz.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import surrogates
from surrogates.hydro_axes import fixed_axes_transform, platform_in_fixed_axes
from surrogates.model import cyclic_flap_lag

SHARED = Path(__file__).resolve().parents[2] / "shared" / "reference" / "openfast" / "runs"


def test_fixed_axes_transform_is_the_rotation_of_the_axes():
    theta = np.deg2rad(4.0)
    t = fixed_axes_transform(theta)
    assert np.allclose(t.T @ t, np.eye(6))
    # a body yaw of 1 rad about the spar's axis (sin, 0, cos): fixed-axes roll sin, yaw cos
    assert np.allclose(t @ np.eye(6)[5], [0, 0, 0, math.sin(theta), 0, math.cos(theta)])
    assert np.allclose(fixed_axes_transform(0.0), np.eye(6))
    with pytest.raises(ValueError, match="mean_pitch"):
        fixed_axes_transform(float("nan"))


def test_yaw_inertia_gains_the_roll_added_inertia_times_sin_squared():
    data = surrogates.oc3.load_oc3()
    a = data.added_mass
    m = np.diag([1e7, 1e7, 1e7, 1e11, 1e11, 2e8]) + a
    k = np.diag([4e4, 4e4, 3e5, 1.3e9, 1.3e9, 1.1e8])
    theta = np.deg2rad(4.0)
    m2, k2 = platform_in_fixed_axes(m, k, a, theta)
    s, c = math.sin(theta), math.cos(theta)
    assert m2[5, 5] - m[5, 5] == pytest.approx(a[3, 3] * s * s, rel=1e-9)  # ~1.9e8 kg m^2 at 4 deg
    assert m2[1, 5] == pytest.approx(a[1, 3] * s, rel=1e-9)  # the sway-roll added mass reaches the yaw
    assert np.array_equal(k2, k)  # the restoring stays in the body axes
    assert np.allclose(m2, m2.T) and np.all(np.linalg.eigvalsh(m2) > 0)
    # the former form turned the restoring too: the roll's stiffness reached the yaw by sin^2
    _, k2t = platform_in_fixed_axes(m, k, a, theta, turn_stiffness=True)
    assert k2t[5, 5] == pytest.approx(k[3, 3] * s * s + k[5, 5] * c * c, rel=1e-9)
    assert k2t[3, 5] == pytest.approx(c * s * (k[3, 3] - k[5, 5]), rel=1e-9)
    m0, k0 = platform_in_fixed_axes(m, k, a, theta, strength=0.0)
    assert np.array_equal(m0, m) and np.array_equal(k0, k)
    # a 7th DOF coupled to the roll by the weights (P-delta) keeps that coupling and gains none with the yaw:
    # the pitched yaw's share is tilted_yaw_gravity_stiffness's, from the exact kinematics, not a second copy
    k7 = np.zeros((7, 7))
    k7[:6, :6], k7[6, 6], k7[3, 6] = k, 2.4e6, -4.2e6
    k7[6, 3] = k7[3, 6]
    m7 = np.zeros((7, 7))
    m7[:6, :6], m7[6, 6] = m, 4e5
    _, k7b = platform_in_fixed_axes(m7, k7, a, theta, turn_stiffness=True)
    assert np.array_equal(k7b[6, :], k7[6, :]) and np.array_equal(k7b[:, 6], k7[:, 6])
    assert np.allclose(k7b[:6, :6], k2t)
    with pytest.raises(ValueError, match="added_mass"):
        platform_in_fixed_axes(m, k, a[:5, :5], theta)


def test_operating_yaw_mode_where_openfast_has_it():
    """OpenFAST's yaw-bearing moment over the platform yaw (the dynamic stiffness below the bearing) crosses zero
    at 0.10-0.12 Hz in the shared 8/12/18 m/s runs, and their yaw spectra peak at 0.08-0.11 Hz; the parked,
    untilted spar's yaw mode is at 0.12 Hz (Jonkman 2010: 0.121 Hz)."""
    model = surrogates.FOWTModel()
    parked = model.modal_analysis(None)
    f_parked = parked.frequencies_hz[list(parked.labels).index("yaw")]
    assert 0.11 < f_parked < 0.13
    rated = model.modal_analysis(surrogates.operating_case(12.0, 2.5, 10.0))
    f_rated = rated.frequencies_hz[list(rated.labels).index("yaw")]
    assert 0.08 < f_rated < 0.105
    body = model.with_effects(hydro_fixed_axes=0.0).modal_analysis(surrogates.operating_case(12.0, 2.5, 10.0))
    assert body.frequencies_hz[list(body.labels).index("yaw")] > 0.11  # the effect is what moves it


def test_cyclic_flap_lag_is_the_phase_of_the_blade_mode_at_one_per_rev():
    data = surrogates.oc3.load_oc3()
    flap = data.blade_flap
    assert cyclic_flap_lag(flap, 8e4, 0.0) == 0.0
    omega = 12.1 * math.pi / 30.0
    # without aerodynamics: the structural damping's phase at r = Omega / omega_f, from the mode's own frequency
    f_rot = flap.frequency_hz(12.1)
    r = omega / (2 * math.pi * f_rot)
    zeta_s = flap.damping_ratio * math.sqrt(flap.stiffness / (flap.stiffness + omega**2 * flap.centrifugal))
    assert cyclic_flap_lag(flap, 0.0, omega) == pytest.approx(math.atan2(2 * zeta_s * r, 1 - r * r), rel=1e-6)
    # the blade's aerodynamic damping (zeta ~0.5 at rated) makes it 15-20 deg
    lag = cyclic_flap_lag(flap, 8.08e4, omega)
    assert np.deg2rad(12.0) < lag < np.deg2rad(25.0)
    assert cyclic_flap_lag(flap, 4e4, omega) < lag


def test_cyclic_flap_modes_answer_a_steady_disc_gradient_with_the_closed_form_lag():
    """A steady vertical wind gradient loads each blade once per revolution (``cos psi_b``); the cyclic flap modes
    of the linear model (multi-blade coordinates, with the blades' aerodynamic damping in the rotating frame) must
    deflect the blades the single blade's phase later in azimuth: ``atan2(q_yaw, q_tilt)`` is the closed form
    :func:`cyclic_flap_lag` (a blade on a fixed hub under a 1P load; Johnson, *Helicopter Theory*)."""
    from surrogates.model import INPUT_BLOCKS
    from surrogates.structure import N_DOF

    model = surrogates.FOWTModel()
    lc = surrogates.operating_case(12.0, 0.0, 10.0)
    sys = model.system(lc)
    labels = list(model.structure.labels)
    cyc = [labels.index("blade_flap_tilt"), labels.index("blade_flap_yaw")]
    # the static answer of the structure (velocities zero: the rotating frame's Omega q terms sit in the
    # stiffness block)
    a_qq = sys.A[N_DOF:2 * N_DOF, :N_DOF]
    f = sys.B[N_DOF:2 * N_DOF, INPUT_BLOCKS["shear"].start + 1]  # per unit dU/dz
    q = -np.linalg.solve(a_qq, f)[cyc]
    lag = cyclic_flap_lag(model.structure.data.blade_flap, sys.op.dT_dV, sys.op.rotor_speed)
    assert math.atan2(q[1], q[0]) == pytest.approx(lag, rel=0.01)
    assert np.deg2rad(12.0) < lag < np.deg2rad(25.0)


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_dir(), reason="needs ../shared/reference/openfast")
def test_steady_wind_yaw_answers_pitch_rate_as_openfast():
    from scipy import signal

    from fowt_env import validation as V

    runs, _ = V.load_reference(SHARED, runs=["d_steady12_Hs2p5_Tp10"])
    run = runs[0]
    lc = V.surrogate_case(V._with_measured_inputs(run))
    sim = surrogates.simulate(surrogates.FOWTModel().with_effects(rotor_1p=0.0), lc, duration=600.0, seed=1,
                              noise=False)

    def gain(rec):
        q = np.deg2rad(np.gradient(np.asarray(rec["PtfmPitch"], float), 1 / 80))
        y = np.deg2rad(np.asarray(rec["PtfmYaw"], float))
        f, pqq = signal.welch(q, 80, nperseg=80 * 100)
        _, pqy = signal.csd(q, y, 80, nperseg=80 * 100)
        band = (f >= 0.075) & (f <= 0.125)
        return float(np.mean(np.abs(pqy[band] / pqq[band]))), float(np.std(y))

    g_of, s_of = gain(run.record)
    g_sur, s_sur = gain(sim)
    assert 0.35 < g_of < 0.6  # the record's own figure (0.39-0.54 s), a guard on the reading
    # measured 0.79 and 0.87 (before the blades answered the disc's rates late, DISC_RATE_LAG_DEG: std 1.29)
    assert 0.65 < g_sur / g_of < 1.25
    assert 0.75 < s_sur / s_of < 1.2
