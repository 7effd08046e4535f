"""The platform's hydrodynamic matrices applied in the fixed axes, as OpenFAST's HydroDyn applies them.

HydroDyn (``PtfmYMod = 0``) applies its WAMIT matrices -- added mass ``A``, hydrostatic restoring ``C`` -- and the
deck's additional linear damping and stiffness (``AddBLin``, ``AddCLin``: the OC3 extra damping and the
crow-foot yaw spring) to the platform's displacement in the *fixed* axes: ElastoDyn's ``PtfmRoll/Pitch/Yaw``
components. The surrogate's platform roll and yaw are rotations about the platform's own axes, which pitch with
it (a slender spar yaws about its long axis). Under the mean pitch ``theta0`` that the thrust holds (~4 deg at
rated wind), the body's yaw ``y`` is, in the fixed axes, a yaw ``y cos(theta0)`` *and a roll* ``y sin(theta0)``:

    (roll, pitch, yaw)_fixed = R_y(theta0) (roll, pitch, yaw)_body,

so HydroDyn loads a spar spinning about its own axis with ``sin^2(theta0)`` of the roll added inertia ``A44``
(3.8e10 kg m^2 about the SWL) and of the roll hydrostatic restoring ``C44`` (-5.0e9 N m/rad: the buoyancy acting
below the reference point), less what the sway added mass (``A24``) takes back. At 4 deg that is +1.9e8 kg m^2 on
the yaw inertia (about twice the platform's own 1.6e8) and -2.6e7 N m/rad on the yaw stiffness: OpenFAST's yaw
mode in operation sits at 0.08-0.10 Hz (its records' yaw spectra; the yaw-bearing moment over the yaw angle crosses
zero there), not at the 0.12 Hz of the parked, untilted spar. The same matrices in the body axes give the
generalised loads ``T^T X T`` with ``T = diag(I_3, R_y(theta0))``; the difference from ``X`` is what this module
returns. Not transformed: the viscous drag (Morison strips on the displaced members in both) and the rigid body's
own inertia (exact in ElastoDyn). The stiffness is turned as a whole block -- HydroDyn's matrices with the linear
mooring and the platform weight's restoring that the structure holds in it -- which is what matches OpenFAST: its
spar turning at 12.1 rpm without aerodynamics, pitched 4.9 deg by a constant load, yaws at 0.092 Hz, this model at
0.093 Hz; turning HydroDyn's own matrices only would put a mean yaw of -2.9 deg into the steady 12 m/s equilibrium
(OpenFAST: +0.1 deg).

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
                           strength: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The model's mass and stiffness with the added mass and the platform's restoring acting in the fixed axes.

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

    Returns
    -------
    (mass, stiffness) : tuple of ndarray, shape (n, n)
        New arrays: ``M - A + T^T A T`` and ``K`` with its platform block ``K_pp`` replaced by ``T^T K_pp T``
        (``T`` :func:`fixed_axes_transform`), blended by ``strength``. The couplings of the platform with the other
        DOFs (the weights' P-delta couplings with the tower's bending) are left as they are: turned, the roll's
        coupling with the side-to-side bending would reach the yaw a second time beside
        :func:`surrogates.model.tilted_yaw_gravity_stiffness` (0.31 MN/rad at 4 deg, doubled).
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
    k_new[:6, :6] += s * (t6.T @ k[:6, :6] @ t6 - k[:6, :6])
    return 0.5 * (m_new + m_new.T), k_new
