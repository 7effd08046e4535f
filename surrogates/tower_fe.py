"""Finite-element tower on the rigid OC3 platform: the source of the tower mode shapes (the BModes way).

Per bending plane, Euler-Bernoulli Hermite beam elements (real OC3 tower mass and stiffness), gravity
geometric stiffness from the weight above each element, the rotor-nacelle assembly as a rigid body at the
tower top (mass, CM offset, rotary inertia about the bending axis) and the platform as a rigid body with its
in-plane added mass, hydrostatic, mooring and weight restoring at the base. The coupled eigenproblem gives the
system modes; a tower mode shape is a mode's elastic part -- its deflection minus the platform's rigid-body
motion -- normalised to 1 at the tower top, exactly what ElastoDyn's shape polynomials represent. Using these
shapes as Ritz vectors in :mod:`surrogates.structure` reproduces the coupled FE frequencies.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy.interpolate import CubicHermiteSpline

from .oc3 import GRAVITY, OC3Data

__all__ = ["PlaneShapes", "tower_plane_modes"]


def _beam_element(ei: float, mu: float, axial: float, length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness, consistent mass and geometric stiffness (per unit compressive force) of a Hermite element."""
    l = length
    k = ei / l**3 * np.array(
        [[12, 6 * l, -12, 6 * l], [6 * l, 4 * l**2, -6 * l, 2 * l**2],
         [-12, -6 * l, 12, -6 * l], [6 * l, 2 * l**2, -6 * l, 4 * l**2]]
    )
    m = mu * l / 420.0 * np.array(
        [[156, 22 * l, 54, -13 * l], [22 * l, 4 * l**2, 13 * l, -3 * l**2],
         [54, 13 * l, 156, -22 * l], [-13 * l, -3 * l**2, -22 * l, 4 * l**2]]
    )
    kg = axial / (30.0 * l) * np.array(
        [[36, 3 * l, -36, 3 * l], [3 * l, 4 * l**2, -3 * l, -l**2],
         [-36, -3 * l, 36, -3 * l], [3 * l, -l**2, -3 * l, 4 * l**2]]
    )
    return k, m, kg


@dataclass(frozen=True)
class PlaneShapes:
    """Elastic tower mode shapes of one bending plane from the coupled FE model.

    Attributes
    ----------
    frequencies_hz : ndarray
        Coupled FE natural frequencies of all in-plane modes (Hz), ascending.
    tower_frequencies_hz : ndarray, (2,)
        Frequencies of the two tower modes used as shapes (Hz).
    z : ndarray
        Node heights above still water level (m).
    values, slopes : ndarray, (2, n_nodes)
        Elastic deflection (normalised to 1 at the tower top) and its slope (1/m) at the nodes.
    """

    frequencies_hz: np.ndarray
    tower_frequencies_hz: np.ndarray
    z: np.ndarray
    values: np.ndarray
    slopes: np.ndarray

    def splines(self) -> list[CubicHermiteSpline]:
        """Hermite interpolants of the shapes (exactly the FE interpolation)."""
        return [CubicHermiteSpline(self.z, v, s) for v, s in zip(self.values, self.slopes, strict=True)]


def tower_plane_modes(
    data: OC3Data,
    plane: str,
    rna_mass: float,
    rna_cm: np.ndarray,
    rna_rot_inertia: float,
    platform_mass_2x2: np.ndarray,
    platform_stiffness_2x2: np.ndarray,
    n_elements: int = 40,
    gravity_softening: bool = True,
) -> PlaneShapes:
    """Solve the coupled in-plane FE eigenproblem and extract two tower mode shapes.

    Parameters
    ----------
    data : OC3Data
        Reference data (tower properties).
    plane : {"FA", "SS"}
        Fore-aft (x, rotation about y) or side-to-side (y, rotation about -x).
    rna_mass : float
        RNA mass (kg).
    rna_cm : ndarray, (2,)
        RNA CM relative to the tower top: (in-plane lateral offset, vertical offset) (m).
    rna_rot_inertia : float
        RNA rotary inertia about its CM for rotation in this plane (kg·m²).
    platform_mass_2x2, platform_stiffness_2x2 : ndarray
        Platform (translation, tilt) mass incl. added mass and restoring about the SWL reference point
        (kg, kg·m, kg·m²; N/m, N, N·m/rad), tilt measured so that it moves the tower top in +lateral.
    n_elements : int
        Number of beam elements along the tower.
    gravity_softening : bool
        Include the geometric stiffness of the tower's and RNA's weight.

    Returns
    -------
    PlaneShapes
    """
    if plane not in ("FA", "SS"):
        raise ValueError(f"plane must be 'FA' or 'SS', got {plane!r}")
    z0, length = data.tower_base_height, data.tower_length
    stiff = data.tower_fa_stiffness if plane == "FA" else data.tower_ss_stiffness
    nodes = np.linspace(z0, z0 + length, n_elements + 1)
    n_dof = 2 * (n_elements + 1)
    k = np.zeros((n_dof, n_dof))
    m = np.zeros((n_dof, n_dof))
    # weight above each element's mid-point (compressive axial force)
    zmid = 0.5 * (nodes[1:] + nodes[:-1])
    fine = np.linspace(z0, z0 + length, 2001)
    mu_fine = np.interp((fine - z0) / length, data.tower_station, data.tower_mass_density)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (mu_fine[1:] + mu_fine[:-1]) * np.diff(fine))])
    tower_above = cum[-1] - np.interp(zmid, fine, cum)
    for e in range(n_elements):
        le = nodes[e + 1] - nodes[e]
        xi = (zmid[e] - z0) / length
        ei = float(np.interp(xi, data.tower_station, stiff))
        mu = float(np.interp(xi, data.tower_station, data.tower_mass_density))
        axial = GRAVITY * (tower_above[e] + rna_mass) if gravity_softening else 0.0
        ke, me, kge = _beam_element(ei, mu, axial, le)
        idx = slice(2 * e, 2 * e + 4)
        k[idx, idx] += ke - kge
        m[idx, idx] += me
    # RNA rigid body at the top node: CM translation = w + dz * w', rotation = w'
    top = slice(n_dof - 2, n_dof)
    dx, dzc = float(rna_cm[0]), float(rna_cm[1])
    link = np.array([1.0, dzc])
    m[top, top] += rna_mass * np.outer(link, link) + rna_rot_inertia * np.diag([0.0, 1.0])
    if gravity_softening:
        # RNA weight above the top node acts through its CM lever (dz) on the top rotation
        k[top, top] -= rna_mass * GRAVITY * dzc * np.diag([0.0, 1.0])
    _ = dx  # a lateral CM offset gives a static load, not stiffness

    # platform (x_ref, theta) rigidly attached at the base node: w0 = x + theta * z0, w0' = theta
    n_tot = n_dof + 2
    tmat = np.zeros((n_tot, n_tot - 2))  # map reduced DOFs [x, theta, w1, w1', ...] -> full [x, th, w0, w0', w1...]
    tmat[0, 0] = 1.0
    tmat[1, 1] = 1.0
    tmat[2, 0] = 1.0
    tmat[2, 1] = z0
    tmat[3, 1] = 1.0
    tmat[4:, 2:] = np.eye(n_dof - 2)
    kf = np.zeros((n_tot, n_tot))
    mf = np.zeros((n_tot, n_tot))
    kf[2:, 2:] = k
    mf[2:, 2:] = m
    kf[:2, :2] += platform_stiffness_2x2
    mf[:2, :2] += platform_mass_2x2
    if gravity_softening:
        # weight above SWL of the rigid column between SWL and the tower base tilts with the platform
        w_total = (cum[-1] + rna_mass) * GRAVITY
        kf[1, 1] -= w_total * z0
    kr = tmat.T @ kf @ tmat
    mr = tmat.T @ mf @ tmat
    w2, vecs = sla.eigh(0.5 * (kr + kr.T), 0.5 * (mr + mr.T))
    freqs = np.sqrt(np.abs(w2)) / (2 * np.pi)
    full = tmat @ vecs
    x_ref, theta = full[0], full[1]
    w = full[2::2][: n_elements + 1]
    ws = full[3::2][: n_elements + 1]
    elastic = w - (x_ref[None, :] + theta[None, :] * nodes[:, None])
    elastic_slope = ws - theta[None, :]
    # tower modes: the ones with most elastic strain energy share beyond the two rigid platform modes
    strain = np.array([vecs[:, i] @ kr @ vecs[:, i] for i in range(vecs.shape[1])])
    rigid = np.array(
        [full[:2, i] @ platform_stiffness_2x2 @ full[:2, i] for i in range(vecs.shape[1])]
    )
    tower_like = [i for i in range(vecs.shape[1]) if abs(rigid[i]) < 0.5 * abs(strain[i])][:2]
    vals = np.array([elastic[:, i] / elastic[-1, i] for i in tower_like])
    slopes = np.array([elastic_slope[:, i] / elastic[-1, i] for i in tower_like])
    return PlaneShapes(freqs, freqs[tower_like], nodes, vals, slopes)
