"""Radiation damping of the OC3 Hywind spar (WAMIT), applied to the structure's flexible modes.

A body vibrating at the free surface radiates waves: the potential-flow damping ``B(omega)`` that OpenFAST's
HydroDyn takes from the WAMIT file of the OC3 deck (``Spar.1``) and applies through its radiation memory
convolution. The spar's rigid-body modes lie at 0.008-0.12 Hz, where ``B`` is negligible (``B11`` 40 N s/m at
0.1 rad/s against the deck's extra linear damping of 1e5 N s/m), and in the wave band the platform's
response is mass-dominated; but the tower's first modes (0.49 Hz, 3.1 rad/s) move the platform too (0.2 m of
surge at the waterline per metre of tower-top deflection, as in OpenFAST's parked tower decay), and at that
frequency the 6.5 m column radiates 7 m waves efficiently: ``B11`` = 7.3e4 N s/m, ``B55`` = 9.7e4 N m s.

The surrogate has no radiation states. The damping is applied modally instead (:func:`modal_radiation_damping`):
each flexible mode ``phi`` of the undamped structure (frequency above ``min_frequency_hz``) receives the modal
damping ``phi^T B(omega) phi`` at its own frequency, as the matrix ``M phi phi^T M c / m^2`` which, by mass
orthogonality, leaves every other undamped mode untouched. For the tower's first fore-aft and side-to-side
modes this adds 0.18 % of critical (0.68 % -> 0.87 %: OpenFAST's parked fore-aft decay measures 0.93 % over
ten cycles); the second tower modes (2.2-2.6 Hz) barely move the platform (+0.001 %).

The table ``data/oc3_spar_radiation.csv`` is written by ``tools/extract_wamit_radiation.py`` from the deck's
``Spar.1`` (axisymmetric: ``B22 = B11``, ``B24 = -B15``, ``B44 = B55``, ``B66 = 0``).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import scipy.linalg

__all__ = ["radiation_damping_matrix", "modal_radiation_damping", "RADIATION_TABLE"]

RADIATION_TABLE = Path(__file__).with_name("data") / "oc3_spar_radiation.csv"
"""Radiation damping of the OC3 spar against frequency (rad/s), SI, from WAMIT ``Spar.1``."""


@lru_cache(maxsize=1)
def _table() -> np.ndarray:
    data = np.loadtxt(RADIATION_TABLE, delimiter=",", skiprows=2)
    if data.ndim != 2 or data.shape[1] != 5 or not np.all(np.diff(data[:, 0]) > 0):
        raise ValueError(f"{RADIATION_TABLE}: expected increasing frequencies and 5 columns")
    return data


def radiation_damping_matrix(omega: float) -> np.ndarray:
    """Platform radiation damping matrix (6, 6) at a circular frequency, about the waterline reference point.

    Parameters
    ----------
    omega : float
        Circular frequency (rad/s), >= 0. Linear interpolation in the WAMIT table; 0 below its first frequency
        (B vanishes at zero frequency) and held at its last value (5 rad/s) above it.

    Returns
    -------
    ndarray, shape (6, 6)
        ``B`` in SI units (N s/m, N s, N m s), DOF order surge, sway, heave, roll, pitch, yaw.

    Examples
    --------
    >>> b = radiation_damping_matrix(3.05)
    >>> round(float(b[0, 0]) / 1e4, 1), bool(b[1, 3] == -b[0, 4]), float(b[5, 5])
    (7.3, True, 0.0)
    """
    w = float(omega)
    if not np.isfinite(w) or w < 0:
        raise ValueError(f"omega must be finite and >= 0 rad/s, got {omega!r}")
    t = _table()
    if w < t[0, 0]:
        vals = t[0, 1:] * (w / t[0, 0])
    else:
        vals = np.array([np.interp(w, t[:, 0], t[:, i]) for i in range(1, 5)])
    b11, b15, b33, b55 = vals
    b = np.zeros((6, 6))
    b[0, 0] = b[1, 1] = b11
    b[2, 2] = b33
    b[3, 3] = b[4, 4] = b55
    b[0, 4] = b[4, 0] = b15
    b[1, 3] = b[3, 1] = -b15  # a roll about +x moves the submerged column towards +y: the opposite sign
    return b


def modal_radiation_damping(mass: np.ndarray, stiffness: np.ndarray, *, min_frequency_hz: float = 0.2
                            ) -> np.ndarray:
    """Damping matrix that gives each flexible mode its radiation damping at its own frequency.

    Parameters
    ----------
    mass, stiffness : ndarray, shape (n, n)
        Generalised mass and stiffness (SI), the first six DOFs the platform's (surge, sway, heave, roll, pitch,
        yaw about the waterline), the rest elastic.
    min_frequency_hz : float
        Modes at or below this frequency (Hz) are left alone (the rigid-body modes, < 0.12 Hz for OC3).

    Returns
    -------
    ndarray, shape (n, n)
        Symmetric, positive semi-definite; zero when no mode lies above ``min_frequency_hz``.

    Examples
    --------
    >>> m = np.eye(7); k = np.diag([1e-3] * 6 + [(2 * np.pi * 0.5) ** 2]); k[0, 6] = k[6, 0] = 0.0
    >>> float(np.abs(modal_radiation_damping(m, k)).max())  # the elastic DOF does not move the platform
    0.0
    """
    m = np.asarray(mass, dtype=float)
    k = np.asarray(stiffness, dtype=float)
    n = m.shape[0]
    if m.shape != (n, n) or k.shape != (n, n) or n < 6:
        raise ValueError(f"mass and stiffness must be square (n, n) with n >= 6, got {m.shape} and {k.shape}")
    lam, vec = scipy.linalg.eigh(0.5 * (k + k.T), 0.5 * (m + m.T))
    c = np.zeros((n, n))
    for li, phi in zip(lam, vec.T, strict=True):
        if li <= 0:
            continue
        w = float(np.sqrt(li))
        if w / (2 * np.pi) <= min_frequency_hz:
            continue
        p = phi[:6]
        c_modal = float(p @ radiation_damping_matrix(w) @ p)
        m_modal = float(phi @ m @ phi)
        mp = m @ phi
        c += np.outer(mp, mp) * (c_modal / m_modal**2)
    return 0.5 * (c + c.T)
