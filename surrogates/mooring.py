"""Quasi-static catenary mooring of OC3 Hywind: the offset-dependent part behind ``mooring_nonlinear``.

Three catenary lines (Jonkman 2010, NREL/TP-500-47535, Table 4-1) are solved with MoorPy's quasi-static line
solver (the FAST v7 catenary routine) for a range of horizontal fairlead offsets. The linear model already
holds the undisplaced tangent stiffness (``OC3Data.mooring_stiffness``); the nonlinear effect adds only the
*excess* of the true restoring force over that linear term, tabulated against the radial offset. Lines are
assumed to react to the radial offset only (the three-line pattern is close to axisymmetric in stiffness; the
small direction dependence is neglected), applied at the fairlead depth so that the pitch/roll coupling of the
real system follows. The delta-line crow-foot yaw spring stays linear.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .oc3 import GRAVITY, RHO_WATER

__all__ = ["MooringTable", "mooring_table", "OC3_LINES"]

# Jonkman 2010, Table 4-1 (OC3 Hywind mooring system properties).
OC3_LINES = {
    "n_lines": 3,
    "angles_deg": (180.0, 60.0, 300.0),
    "anchor_depth": 320.0,  # m
    "fairlead_depth": 70.0,  # m below SWL
    "anchor_radius": 853.87,  # m
    "fairlead_radius": 5.2,  # m
    "unstretched_length": 902.2,  # m
    "diameter": 0.09,  # m
    "mass_density": 77.7066,  # kg/m
    "extensional_stiffness": 384.243e6,  # N
}


@dataclass(frozen=True)
class MooringTable:
    """Mooring restoring against horizontal fairlead offset (SI units).

    Attributes
    ----------
    offset : ndarray
        Radial horizontal offsets of the fairleads (m), from 0.
    horizontal_force : ndarray
        Total horizontal restoring force of the three lines, directed against the offset (N, >= 0).
    vertical_force : ndarray
        Change of the total downward line load at the fairleads relative to zero offset (N, >= 0 pulls down).
    linear_stiffness : float
        Tangent surge stiffness at zero offset from the same solver (N/m), a cross-check of K11.
    fairlead_z : float
        Fairlead height (m, negative below SWL).
    """

    offset: np.ndarray
    horizontal_force: np.ndarray
    vertical_force: np.ndarray
    linear_stiffness: float
    fairlead_z: float

    def excess_horizontal(self, rho: np.ndarray, k_linear: float) -> np.ndarray:
        """Restoring force beyond the linear ``k_linear * rho`` at radial offsets ``rho`` (N)."""
        return np.interp(rho, self.offset, self.horizontal_force) - k_linear * np.asarray(rho)


def _line_forces(dx: float, dy: float) -> tuple[float, float, float]:
    """Total (Fx, Fy, Fz) on the platform from the three lines with the fairleads shifted by (dx, dy)."""
    from moorpy.Catenary import catenary

    p = OC3_LINES
    w = (p["mass_density"] - RHO_WATER * np.pi * p["diameter"] ** 2 / 4) * GRAVITY
    zf = p["anchor_depth"] - p["fairlead_depth"]
    fx = fy = fz = 0.0
    for ang in np.deg2rad(p["angles_deg"]):
        e = np.array([np.cos(ang), np.sin(ang)])
        anchor = p["anchor_radius"] * e
        fair = p["fairlead_radius"] * e + np.array([dx, dy])
        span = anchor - fair
        xf = float(np.hypot(*span))
        fah, fav, fbh, fbv, _ = catenary(xf, zf, p["unstretched_length"], p["extensional_stiffness"], w, CB=0.0)
        direction = span / xf  # from fairlead towards anchor
        # MoorPy returns the force the line exerts at its end B (the fairlead), horizontal along the
        # anchor->fairlead direction (fBH < 0: towards the anchor) and vertical (fBV < 0: downwards).
        fx += -fbh * direction[0]
        fy += -fbh * direction[1]
        fz += fbv
    return fx, fy, fz


@lru_cache(maxsize=1)
def mooring_table(max_offset: float = 60.0, n: int = 41) -> MooringTable:
    """Tabulate the OC3 catenary restoring force against radial offset (cached; ~0.1 s).

    Parameters
    ----------
    max_offset : float
        Largest horizontal offset tabulated (m); the table is extrapolated linearly beyond it.
    n : int
        Number of offsets.

    Returns
    -------
    MooringTable
    """
    offs = np.linspace(0.0, max_offset, n)
    fx0, _, fz0 = _line_forces(0.0, 0.0)
    h = np.empty(n)
    v = np.empty(n)
    for i, r in enumerate(offs):
        fx, _, fz = _line_forces(r, 0.0)
        h[i] = -(fx - fx0)
        v[i] = -(fz - fz0)
    k_lin = float((-(_line_forces(0.01, 0.0)[0] - fx0)) / 0.01)
    return MooringTable(offs, h, v, k_lin, -OC3_LINES["fairlead_depth"])
