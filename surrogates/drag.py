"""Morison viscous drag on the spar and its equivalent (stochastic) linearisation about a sea state.

The drag per unit length is ``0.5 rho Cd D |u_r| u_r`` with ``u_r`` the horizontal relative velocity (wave
particle velocity minus the platform's). A linear model of the floating turbine in a sea state holds its
statistical linearisation (Borgman 1967; what frequency-domain FOWT tools such as RAFT use): for Gaussian
relative velocity along the wave direction with standard deviation ``sigma``, the equivalent linear
coefficient is ``sqrt(8/pi) sigma`` along that direction and ``sqrt(2/pi) sigma`` (``E|u_along|``) across it.
The surrogate's linear model (``surrogates.model``, ``_stochastic_drag``) takes ``sigma(z)`` as the std of the
*relative* velocity and iterates it with the linear model's own stationary response to the sea state and the
rotor-effective turbulence, as RAFT does (``with_relative_velocity_std`` builds the strips for each iterate).
The functions here that take only a sea state (``drag_strips``, ``equivalent_drag_damping``) use the
wave-particle velocity's ``sigma(z)`` alone, from the JONSWAP spectrum through linear (Airy) kinematics at the
strip's depth, without the platform's own velocity -- the value the iteration starts from, not the one the
surrogate uses.

The split used by the surrogate: the linear model carries the equivalent damping (and the equivalent drag
excitation ``B_eq u_wave``), and the ``quadratic_drag`` effect carries the remainder ``|u_r| u_r`` minus its
linearisation, so that the effect at strength 1 gives exactly the Morison drag and at 0 the linear model.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .oc3 import RHO_WATER
from .waves import WATER_DEPTH, SparGeometry, jonswap_spectrum, wave_number

__all__ = ["N_STRIPS", "DragStrips", "drag_strips", "equivalent_drag_damping", "wave_velocity_rao",
           "with_relative_velocity_std"]

N_STRIPS = 24
"""Depth strips of the drag integration (the same strips as the wave kinematics)."""


@dataclass(frozen=True)
class DragStrips:
    """Strip data of the drag and its equivalent linearisation (SI).

    Attributes
    ----------
    z : ndarray (n,)
        Strip mid-heights (m, negative below SWL).
    coef : ndarray (n,)
        ``0.5 rho Cd D dz`` per strip (kg/m).
    along, across : ndarray (n,)
        Equivalent linear coefficients per strip, along and across the wave direction (N·s/m): ``coef`` times
        ``sqrt(8/pi) sigma`` and ``sqrt(2/pi) sigma``. Zero in still water.
    direction : ndarray (2,)
        Unit vector of the wave direction in the horizontal plane (x downwind).
    """

    z: np.ndarray
    coef: np.ndarray
    along: np.ndarray
    across: np.ndarray
    direction: np.ndarray

    def strip_matrices(self) -> np.ndarray:
        """Equivalent 2x2 damping matrix of every strip, shape (n, 2, 2) (N·s/m)."""
        e = self.direction
        ee = np.outer(e, e)
        return self.along[:, None, None] * ee + self.across[:, None, None] * (np.eye(2) - ee)

    def platform_damping(self) -> np.ndarray:
        """Equivalent linear damping on the 6 platform DOFs about the SWL reference point (6, 6)."""
        out = np.zeros((6, 6))
        for z, d in zip(self.z, self.strip_matrices(), strict=True):
            t = np.zeros((2, 6))
            t[0, 0], t[0, 4] = 1.0, z
            t[1, 1], t[1, 3] = 1.0, -z
            out += t.T @ d @ t
        return out

    def excitation(self, velocity: np.ndarray) -> np.ndarray:
        """Equivalent linear drag excitation on the 6 platform DOFs from wave-particle velocities.

        Parameters
        ----------
        velocity : ndarray (n_t, n_strips, 2)
            Horizontal wave-particle velocity at the strips (m/s).

        Returns
        -------
        ndarray (n_t, 6)
            Generalised forces (N, N·m).
        """
        v = np.asarray(velocity, dtype=float)
        if v.ndim != 3 or v.shape[1:] != (self.z.size, 2):
            raise ValueError(f"velocity must have shape (n_t, {self.z.size}, 2), got {v.shape}")
        # one matrix product: strip s's force D_s v_s acts at height z_s on surge/sway and, as -z F_y and
        # z F_x, on roll and pitch
        d = self.strip_matrices()  # (n, 2, 2): d[s, i, j] = force i per velocity j
        gain = np.zeros((self.z.size, 2, 6))
        gain[:, :, 0] = d[:, 0, :]
        gain[:, :, 1] = d[:, 1, :]
        gain[:, :, 3] = -self.z[:, None] * d[:, 1, :]
        gain[:, :, 4] = self.z[:, None] * d[:, 0, :]
        return v.reshape(v.shape[0], -1) @ gain.reshape(-1, 6)


def wave_velocity_rao(z: np.ndarray, f_hz: np.ndarray, depth: float = WATER_DEPTH) -> np.ndarray:
    """Horizontal wave-particle velocity per metre of wave amplitude at depths ``z`` along the wave direction,
    in phase with the elevation at the origin (Airy), shape (len(f_hz), len(z)) (1/s)."""
    w = 2 * np.pi * np.asarray(f_hz, float)[:, None]
    k = wave_number(w, depth)
    zz = np.asarray(z, float)[None, :]
    # cosh(k (z + h)) / sinh(k h) without overflow
    return w * np.exp(k * zz) * (1.0 + np.exp(-2.0 * k * (zz + depth))) / (1.0 - np.exp(-2.0 * k * depth))


def _velocity_std(z: np.ndarray, hs: float, tp: float, gamma: float, depth: float = WATER_DEPTH) -> np.ndarray:
    """Standard deviation of the horizontal wave-particle velocity at depths ``z`` (m/s), Airy kinematics."""
    f = np.linspace(0.01, 1.0, 2000)
    s = jonswap_spectrum(f, hs, tp, gamma)
    w = 2 * np.pi * f
    k = wave_number(w, depth)
    zz = np.asarray(z, float)[:, None]
    # cosh(k (z + h)) / sinh(k h) without overflow: exp(k z) (1 + exp(-2k(z+h))) / (1 - exp(-2kh))
    h_u = w * np.exp(k * zz) * (1.0 + np.exp(-2.0 * k * (zz + depth))) / (1.0 - np.exp(-2.0 * k * depth))
    return np.sqrt(np.trapezoid(h_u**2 * s, f, axis=1))


@lru_cache(maxsize=64)
def drag_strips(hs: float = 0.0, tp: float = 10.0, gamma: float = 1.0, wave_dir_deg: float = 0.0) -> DragStrips:
    """Drag strips of the OC3 spar and their equivalent linearisation in a sea state (cached).

    Parameters
    ----------
    hs, tp, gamma : float
        Sea state (m, s, -); ``hs = 0`` is still water (no equivalent damping).
    wave_dir_deg : float
        Wave direction relative to the wind (deg).

    Returns
    -------
    DragStrips
    """
    geo = SparGeometry()
    z, dz, diam = geo.strips(N_STRIPS)
    coef = 0.5 * RHO_WATER * geo.cd * np.asarray(diam) * np.asarray(dz)
    theta = np.deg2rad(wave_dir_deg)
    direction = np.array([np.cos(theta), np.sin(theta)])
    if hs > 0:
        sigma = _velocity_std(z, hs, tp, gamma)
    else:
        sigma = np.zeros_like(z)
    along = coef * np.sqrt(8.0 / np.pi) * sigma
    across = coef * np.sqrt(2.0 / np.pi) * sigma
    return DragStrips(np.asarray(z, float), coef, along, across, direction)


def with_relative_velocity_std(strips: DragStrips, sigma: np.ndarray) -> DragStrips:
    """The same strips linearised for a relative-velocity standard deviation ``sigma`` per strip (m/s), along
    the wave direction."""
    sigma = np.asarray(sigma, float)
    return DragStrips(strips.z, strips.coef, strips.coef * np.sqrt(8.0 / np.pi) * sigma,
                      strips.coef * np.sqrt(2.0 / np.pi) * sigma, strips.direction)


def equivalent_drag_damping(hs: float, tp: float, gamma: float = 1.0, wave_dir_deg: float = 0.0) -> np.ndarray:
    """Equivalent linear drag damping on the platform DOFs in a sea state (6, 6), SI."""
    return drag_strips(float(hs), float(tp), float(gamma), float(wave_dir_deg)).platform_damping()
