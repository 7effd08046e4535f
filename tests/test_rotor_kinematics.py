"""Kinematics of the rotor axis and of the platform angles against closed forms: the thrust follows the
rotor axis when the tower top yaws (a side force ``T sin(psi)``), and the platform roll/yaw are reported as
ElastoDyn's Euler angles (checked against scipy's exact rotation algebra)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import surrogates
from surrogates.simulate import I_HUB, I_ROTOR, Simulator, body_platform_angles, elastodyn_platform_angles


def _elastodyn_angles(rot: Rotation) -> np.ndarray:
    """ElastoDyn's (PtfmRoll, PtfmPitch, PtfmYaw) of an orientation (rad). OpenFAST v5's ``SetCoordSy`` turns the
    platform by its yaw about the vertical, then its pitch about the yawed lateral axis, then its roll about the
    pitched longitudinal axis (``EulerConstructZYX``): intrinsic Z-Y-X Euler angles."""
    yaw, pitch, roll = rot.as_euler("ZYX")
    return np.array([roll, pitch, yaw])


@pytest.mark.parametrize("pitch_deg, roll_deg, yaw_deg", [(4.1, 0.0, 0.5), (4.1, 0.2, -0.8), (-3.0, -0.3, 1.2),
                                                          (8.0, 0.1, 0.3)])
def test_platform_angles_match_elastodyn_euler_angles(pitch_deg, roll_deg, yaw_deg):
    # the model's roll and yaw turn the platform about its own (pitched) axes
    rot = Rotation.from_euler("y", pitch_deg, degrees=True) * Rotation.from_rotvec(
        np.deg2rad([roll_deg, 0.0, yaw_deg]))
    truth = np.rad2deg(_elastodyn_angles(rot))
    y = np.array([[roll_deg, pitch_deg, yaw_deg]])
    elastodyn_platform_angles(y, 0, 1, 2)
    # first order in the small roll and yaw: the residual is second order in them (~ angle^2 in rad)
    small = np.deg2rad(max(abs(yaw_deg), abs(roll_deg)))
    tol = np.rad2deg(2.0 * small * small) + 1e-9
    assert abs(y[0, 0] - truth[0]) < tol
    assert abs(y[0, 1] - truth[1]) < tol
    assert abs(y[0, 2] - truth[2]) < tol
    # without the map the roll error would be the whole coupling y tan(p)
    if yaw_deg and pitch_deg:
        assert abs(roll_deg - truth[0]) > 5 * abs(y[0, 0] - truth[0])
    # and the inverse map returns the body angles
    r, yw = body_platform_angles(*np.deg2rad(y[0]))
    assert np.rad2deg([r, yw]) == pytest.approx([roll_deg, yaw_deg], abs=1e-9)


def test_linearised_platform_angles_are_elastodyns_about_the_mean_pitch():
    # linearize()'s PtfmRoll/PtfmYaw rows: the derivative of ElastoDyn's Euler angles with respect to the body
    # axes roll and yaw at the mean pitch p0 (exact rotation algebra: roll tan(p0), yaw 1 / cos(p0) per body yaw)
    model = surrogates.FOWTModel()
    case = surrogates.operating_case(12.0, 2.5, 10.0)
    sys_ = model.linearize(case)
    p0 = model._system(case, False).mean_pitch
    assert np.deg2rad(3.0) < p0 < np.deg2rad(5.5)
    h = 1e-6
    rot = Rotation.from_euler("y", p0) * Rotation.from_rotvec([0.0, 0.0, h])
    d_euler = (_elastodyn_angles(rot) - np.array([0.0, p0, 0.0])) / h
    i_r, i_y = sys_.output_labels.index("PtfmRoll"), sys_.output_labels.index("PtfmYaw")
    assert np.deg2rad(sys_.C[i_r, 5]) == pytest.approx(d_euler[0], rel=1e-4)
    assert np.deg2rad(sys_.C[i_y, 5]) == pytest.approx(d_euler[2], rel=1e-4)
    assert np.deg2rad(sys_.C[i_r, 3]) == pytest.approx(1.0) and sys_.C[i_y, 3] == 0.0
    # and simulate() adds only the rest of the map: at the mean pitch nothing
    y = np.array([[0.3, np.rad2deg(p0), 1.2]])
    expect = y.copy()
    elastodyn_platform_angles(y, 0, 1, 2, p0)
    assert np.allclose(y, expect)


def test_initial_platform_angles_are_elastodyns():
    # a free decay started from ElastoDyn's roll and yaw at a pitch reports them back at the release
    model = surrogates.FOWTModel()
    initial = {"PtfmPitch": 5.0, "PtfmRoll": 0.4, "PtfmYaw": 2.0}
    rec = surrogates.simulate(model, None, 1.0, 0.0125, transient=0.0, noise=False, initial=initial)
    for name, value in initial.items():
        assert rec[name][0] == pytest.approx(value, abs=1e-6)


def test_thrust_turns_sideways_with_the_tower_top_yaw():
    model = surrogates.FOWTModel().with_effects(rotor_1p=0.0, rotor_3p=0.0, rotor_asymmetry=0.0,
                                                   rotor_skew=0.0)
    case = surrogates.operating_case(12.0, 0.0, 10.0, turbulence_intensity=0.0)
    sim = Simulator(model, case, 0.0125)
    n = 4
    u_ex, vel, _, blade = sim.forcing(n, np.random.SeedSequence(0))
    ctrl = sim.ctrl0.copy()
    action = np.zeros(2)
    x0 = sim.x_eq.copy()
    u0, _ = sim.loads(x0, 0, 0.0, action, u_ex, vel, ctrl.copy(), blade)
    yaw = np.deg2rad(1.0)
    x1 = x0.copy()
    x1[5] += yaw  # platform yaw: the tower top turns with it
    u1, _ = sim.loads(x1, 0, 0.0, action, u_ex, vel, ctrl.copy(), blade)
    thrust = u0[I_ROTOR + 3]
    assert thrust > 5e5  # N, rated-region thrust
    e_s = sim.e_s
    # closed form: the force along the rotated axis, T (e_s + psi e_z x e_s)
    assert u1[I_HUB + 1] - u0[I_HUB + 1] == pytest.approx(thrust * yaw * e_s[0], rel=0.02)
