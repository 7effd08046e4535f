"""The platform's added mass applied in the fixed axes, as OpenFAST's HydroDyn applies it.

HydroDyn (``PtfmYMod = 0``) loads the platform with its WAMIT added mass ``A`` times the platform's angular
acceleration in the *fixed* (global) axes, and applies its restoring -- the hydrostatic matrix ``C`` and the deck's
additional stiffness ``AddCLin`` (the crow-foot yaw spring) -- to ElastoDyn's Euler angles (``EulerExtractZYX``:
yaw about the vertical, pitch, roll about the pitched longitudinal axis), as moments about the fixed axes. The
surrogate's platform roll and yaw are rotations about the platform's own axes, which pitch with it (a slender spar
yaws about its long axis). Under the mean pitch ``theta0`` that the thrust holds (~4-5 deg at rated wind), the
body's yaw rate ``y'`` is, in the fixed axes, a yaw rate ``y' cos(theta0)`` *and a roll rate* ``y' sin(theta0)``:

    (roll, pitch, yaw)_fixed = R_y(theta0) (roll, pitch, yaw)_body,

so HydroDyn loads a spar spinning about its own axis with ``sin^2(theta0)`` of the roll added inertia ``A44``
(3.8e10 kg m^2 about the SWL), less what the sway added mass (``A24``) takes back: at 4.9 deg +2.8e8 kg m^2 on the
yaw inertia (about 1.5 times the platform's own 1.9e8). OpenFAST's yaw mode in operation sits at 0.094 Hz (its
operating yaw free decay), not at the 0.12 Hz of the parked, untilted spar. The same added mass in the body axes is
``T^T A T`` with ``T = diag(I_3, R_y(theta0))``; the difference from ``A`` is what this module adds.

The restoring is *not* turned. HydroDyn's restoring on the Euler angles, ElastoDyn's exact weights and the mean
moments they hold under the pitch (each fixed-direction moment's share when the axes turn) exert no yaw moment on
the pitched platform's own roll: the terms ``sin(theta0) C44 roll`` of the hydrostatics and of the weights cancel
against their mean pitching moments. OpenFAST shows it: released in roll in steady 12 m/s wind, its platform yaws
+0.16 deg per degree of roll, and in its yaw decay it rolls 1.23 deg per degree of yaw; with the restoring block
turned as the added mass is (``T^T K T``, this module's form until now) the surrogate gave -0.38 and 0.24 -- the
coupling ``cos sin (K44 - K66)`` dragged the yaw along with every roll, softened the operating roll statically by
7 % and, against the rotor's yaw moment, put the steady mean yaw at 0.05 deg where OpenFAST holds 0.10 (its
yaw-bearing moment, 182 kN m, over the yaw stiffness). Untransformed -- and with the mooring's moments taken along
the platform's own axes (the lines act at the fairlead centre, on the spar's axis, so they have no moment about it,
``surrogates.simulate._mooring_generalised``) -- +0.155, 0.83, the operating yaw mode at 0.094 Hz and the steady
mean yaw at 0.17 deg (``tests/test_yaw_decay.py``, ``tests/test_roll_decay.py``). ``turn_stiffness=True`` gives
the former form for comparison. Not transformed either: the viscous drag (Morison strips on the displaced members
in both) and the rigid body's own inertia (exact in ElastoDyn).

Whether the true flow around a tilted spar would load its spin like this is another matter (a circular cylinder
spinning about its axis displaces no water); the surrogate reproduces the referee's model, by name
(``hydro_fixed_axes``), so that switching it off gives the body-axes model.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["fixed_axes_transform", "platform_in_fixed_axes"]


def fixed_axes_transform(mean_pitch: float) -> np.ndarray:
    """Map of the platform's body-axes displacement to the fixed-axes one at a mean pitch.

    Parameters
    ----------
    mean_pitch : float
        Mean platform pitch (rad; positive: the tower leans downwind).

    Returns
    -------
    ndarray, shape (6, 6)
        ``T`` with ``q_fixed = T q_body``: translations unchanged, rotations turned by ``R_y(mean_pitch)``.

    Examples
    --------
    >>> t = fixed_axes_transform(np.deg2rad(4.0))
    >>> round(float(t[3, 5]), 4)  # a body yaw shows as a fixed-axes roll sin(theta0)
    0.0698
    """
    theta = float(mean_pitch)
    if not math.isfinite(theta) or abs(theta) > 0.5:
        raise ValueError(f"mean_pitch must be finite and within +-0.5 rad, got {mean_pitch!r}")
    c, s = math.cos(theta), math.sin(theta)
    t = np.eye(6)
    t[3:, 3:] = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return t


def platform_in_fixed_axes(mass: np.ndarray, stiffness: np.ndarray, added_mass: np.ndarray, mean_pitch: float,
                           strength: float = 1.0, *, turn_stiffness: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The model's mass with the added mass acting in the fixed axes (and, on request, the stiffness turned too).

    Parameters
    ----------
    mass, stiffness : ndarray, shape (n, n)
        Generalised mass and stiffness (n >= 6; the first six DOFs the platform's, body axes), SI.
    added_mass : ndarray, shape (6, 6)
        The added mass included in ``mass`` (kg, kg m, kg m^2), about the platform reference point.
    mean_pitch : float
        Mean platform pitch (rad).
    strength : float
        1: as OpenFAST; 0: unchanged (body axes); values between blend the two.
    turn_stiffness : bool
        Also replace the platform block ``K_pp`` of the stiffness by ``T^T K_pp T`` (the former form, which
        OpenFAST's roll and yaw decays refute: see the module docstring). Default False: the stiffness is
        returned unchanged.

    Returns
    -------
    (mass, stiffness) : tuple of ndarray, shape (n, n)
        New arrays: ``M - A + T^T A T`` (``T`` :func:`fixed_axes_transform`) and ``K`` (with
        ``turn_stiffness``, its platform block turned), blended by ``strength``. The couplings of the platform with
        the other DOFs (the weights' P-delta couplings with the tower's bending) are left as they are.
    """
    m = np.asarray(mass, dtype=float)
    k = np.asarray(stiffness, dtype=float)
    a = np.asarray(added_mass, dtype=float)
    n = m.shape[0]
    if m.shape != (n, n) or k.shape != (n, n) or n < 6 or a.shape != (6, 6):
        raise ValueError(f"mass and stiffness must be square (n >= 6) and added_mass (6, 6); got {m.shape}, "
                         f"{k.shape}, {a.shape}")
    if not (np.all(np.isfinite(m)) and np.all(np.isfinite(k)) and np.all(np.isfinite(a))):
        raise ValueError("mass, stiffness and added_mass must be finite")
    s = float(strength)
    if not math.isfinite(s) or s < 0:
        raise ValueError(f"strength must be finite and >= 0, got {strength!r}")
    t6 = fixed_axes_transform(mean_pitch)
    m_new = m.copy()
    m_new[:6, :6] += s * (t6.T @ a @ t6 - a)
    # the platform's own block only: the tower's couplings to the platform's rotations are the weights' (P-delta),
    # whose pitched-yaw share surrogates.model.tilted_yaw_gravity_stiffness holds from the exact kinematics
    k_new = k.copy()
    if turn_stiffness:
        k_new[:6, :6] += s * (t6.T @ k[:6, :6] @ t6 - k[:6, :6])
    return 0.5 * (m_new + m_new.T), k_new
