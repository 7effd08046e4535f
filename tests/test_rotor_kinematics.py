"""Kinematics of the rotor axis and of the platform angles against closed forms: the thrust follows the
rotor axis when the tower top yaws (a side force ``T sin(psi)``), and the platform roll/yaw are reported as
ElastoDyn's rotation components (checked against scipy's exact rotation algebra)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import surrogates
from surrogates.simulate import I_HUB, I_ROTOR, Simulator, elastodyn_platform_angles


def _elastodyn_angles(rot: Rotation) -> np.ndarray:
    """ElastoDyn's (theta1, theta2, theta3) of an orientation: SmllRotTrans is the orthonormal matrix closest to
    ``I + [theta]x``, i.e. the rotation by ``atan|theta|`` about ``theta`` (so ``theta = axis tan(angle)``)."""
    phi = rot.as_rotvec()
    angle = np.linalg.norm(phi)
    return phi if angle == 0 else phi / angle * np.tan(angle)


@pytest.mark.parametrize("pitch_deg, roll_deg, yaw_deg", [(4.1, 0.0, 0.5), (4.1, 0.2, -0.8), (-3.0, -0.3, 1.2),
                                                          (8.0, 0.1, 0.3)])
def test_platform_angles_match_elastodyn_rotation_components(pitch_deg, roll_deg, yaw_deg):
    # the model's roll and yaw turn the platform about its own (pitched) axes
    rot = Rotation.from_euler("y", pitch_deg, degrees=True) * Rotation.from_rotvec(
        np.deg2rad([roll_deg, 0.0, yaw_deg]))
    truth = np.rad2deg(_elastodyn_angles(rot))
    y = np.array([[roll_deg, pitch_deg, yaw_deg]])
    elastodyn_platform_angles(y, 0, 1, 2)
    # second-order composition: the residual is third order (the pitch-yaw product p y / 2 times ~p / 6, and
    # ElastoDyn's tan scaling of each angle, ~p^2 / 3)
    p = abs(np.deg2rad(pitch_deg))
    tol = (p / 6 + p * p / 3 + 0.01) * max(abs(yaw_deg), abs(roll_deg)) + 1e-9
    assert abs(y[0, 0] - truth[0]) < tol
    assert abs(y[0, 2] - truth[2]) < tol
    # without the map the roll error would be the whole coupling p y / 2
    if yaw_deg and pitch_deg:
        assert abs(roll_deg - truth[0]) > 5 * abs(y[0, 0] - truth[0])


def test_thrust_turns_sideways_with_the_tower_top_yaw():
    model = surrogates.FOWTModel().with_effects(rotor_1p=0.0, rotor_3p=0.0, rotor_asymmetry=0.0)
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
