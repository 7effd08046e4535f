"""Quasi-static catenary mooring of OC3 Hywind: a 6-component load table and its compiled interpolator.

Geometry (Jonkman 2010, NREL/TP-500-47535, Table 4-1; the MAP++ deck ``NRELOffshrBsline5MW_OC3Hywind_MAP.dat``
of the OpenFAST OC3 Hywind case): three identical lines, line 1 anchored at (853.87, 0, -320) m, i.e. **downwind**
(+x, 0 deg), lines 2 and 3 rotated by +-120 deg (the deck's ``repeat 240 120``); fairleads at radius 5.2 m,
70 m below SWL. Each line is solved with MoorPy's quasi-static catenary (``moorpy.Catenary.catenary``, the FAST v7
routine, seabed contact with the deck's friction coefficient CB = 0.001).

What the module gives
---------------------
* :func:`solve_loads` -- the direct solve: total line load on the platform for any rigid-body displacement.
* :func:`mooring_table` -- a cached :class:`MooringTable`: total loads ``(Fx, Fy, Fz, Mx, My, Mz)`` against the
  horizontal offset ``(dx, dy)`` of the fairlead centre and the platform yaw ``psi``, with the zero-offset loads
  (pretension) and the 6x6 tangent stiffness about SWL.
* :func:`mooring_loads` -- numba trilinear interpolation of that table for compiled simulation kernels.

Sign conventions: loads are those the lines exert **on the platform**, in global (earth-fixed) axes, x downwind,
z up; moments are about the displaced fairlead centre ``(dx, dy, -70 m)``. A positive offset gives a negative
restoring force; the pretension pulls down (``Fz < 0``).

Comparison with OC3 (Jonkman 2010, Table 4-2 region; lines only, moments about SWL, from :func:`tangent_stiffness`)

==========  ====================  ==========================
entry       OC3 published         this solver (zero offset)
==========  ====================  ==========================
K11 = K22   41,180 N/m            41,181 N/m
K33         11,940 N/m            11,941 N/m
K44 = K55   3.11e8 N m/rad        3.108e8 N m/rad
K15 = -K24  -2.82e6 N             -2.815e6 N
K66         1.156e7 N m/rad       1.157e7 N m/rad
==========  ====================  ==========================

Pretension (zero offset): Fz = -1.607e6 N (three lines' suspended weight at the fairleads).
(The exact numbers are printed by ``python -m surrogates.mooring``; ``tests/test_mooring.py`` checks them.)
The delta-line crow-foot of the real system adds a yaw spring of 9.834e7 N m/rad that three single lines do not
have; it is *additional* and stays linear in the structural model (``OC3Data.mooring_stiffness``), not here.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numba
import numpy as np

from .oc3 import GRAVITY, RHO_WATER

__all__ = [
    "OC3_LINES",
    "MooringTable",
    "mooring_table",
    "mooring_loads",
    "solve_loads",
    "tangent_stiffness",
    "read_map_deck",
]

# Jonkman 2010, Table 4-1 (OC3 Hywind mooring system properties); the MAP++ deck holds the same values
# (tests/test_mooring.py compares them with the shared deck when it is present).
OC3_LINES = {
    "n_lines": 3,
    "angles_deg": (0.0, 120.0, 240.0),  # anchor azimuths; line 1 downwind (+x)
    "anchor_depth": 320.0,  # m below SWL (= water depth)
    "fairlead_depth": 70.0,  # m below SWL
    "anchor_radius": 853.87,  # m
    "fairlead_radius": 5.2,  # m
    "unstretched_length": 902.2,  # m
    "diameter": 0.09,  # m
    "mass_density": 77.7066,  # kg/m (in air)
    "extensional_stiffness": 384.243e6,  # N
    "seabed_friction": 0.001,  # CB of the MAP++ deck (-)
}

FAIRLEAD_Z = -OC3_LINES["fairlead_depth"]  # m, fairlead-centre height

# Default table grid (m, m, rad). Uniform spacing is required by :func:`mooring_loads`.
_GRID_DX = (-40.0, 60.0, 101)  # 1 m
_GRID_DY = (-40.0, 40.0, 81)  # 1 m
_GRID_YAW_DEG = (-15.0, 15.0, 7)  # 5 deg


def _wet_weight() -> float:
    """Submerged weight of the line per unit length (N/m)."""
    p = OC3_LINES
    return (p["mass_density"] - RHO_WATER * np.pi * p["diameter"] ** 2 / 4) * GRAVITY


def _geometry() -> tuple[np.ndarray, np.ndarray]:
    """Anchor positions ``(3, 3)`` (m, global) and fairlead positions ``(3, 3)`` in the undisplaced platform (m)."""
    p = OC3_LINES
    a = np.deg2rad(np.asarray(p["angles_deg"]))
    e = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=1)
    anchors = p["anchor_radius"] * e
    anchors[:, 2] = -p["anchor_depth"]
    fairs = p["fairlead_radius"] * e
    fairs[:, 2] = -p["fairlead_depth"]
    return anchors, fairs


def _catenary(xf: float, zf: float) -> tuple[float, float, float, float]:
    """One line: fairlead ``(H, V)`` magnitudes (N) and their slopes ``dH/dxf, dV/dxf`` (N/m).

    ``H`` pulls the fairlead horizontally towards the anchor, ``V`` pulls it down.
    """
    from moorpy.Catenary import catenary

    p = OC3_LINES
    _, _, fbh, fbv, info = catenary(float(xf), float(zf), p["unstretched_length"], p["extensional_stiffness"],
                                    _wet_weight(), CB=p["seabed_friction"])
    kb = info["stiffnessB"]  # -d(fBH, fBV)/d(xB, zB): moving the fairlead away from the anchor raises H and V
    return -fbh, -fbv, kb[0][0], kb[1][0]


def _rotation(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation matrix ``Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (body to global)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def solve_loads(displacement: np.ndarray | tuple[float, ...], ref_z: float = FAIRLEAD_Z) -> np.ndarray:
    """Total line load on the platform by a direct catenary solve of the three lines.

    Parameters
    ----------
    displacement : array_like, shape (6,)
        Rigid-body displacement ``(x, y, z, roll, pitch, yaw)`` of the platform point ``(0, 0, ref_z)``
        (m and rad; rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` about that point).
    ref_z : float
        Height of the reference point (m, negative below SWL). The default is the fairlead centre (-70 m), so
        ``solve_loads((dx, dy, 0, 0, 0, psi))`` is exactly what :class:`MooringTable` tabulates.

    Returns
    -------
    ndarray, shape (6,)
        ``(Fx, Fy, Fz, Mx, My, Mz)`` on the platform in global axes (N, N·m), moments about the displaced
        reference point.
    """
    q = np.asarray(displacement, dtype=float)
    if q.shape != (6,) or not np.all(np.isfinite(q)):
        raise ValueError(f"displacement must be 6 finite numbers (x, y, z, roll, pitch, yaw), got {q!r}")
    anchors, fairs = _geometry()
    ref = np.array([0.0, 0.0, ref_z])
    point = ref + q[:3]
    rot = _rotation(*q[3:])
    out = np.zeros(6)
    for anc, f0 in zip(anchors, fairs, strict=True):
        arm = rot @ (f0 - ref)
        fair = point + arm
        span = anc[:2] - fair[:2]
        xf = float(np.hypot(*span))
        h, v, _, _ = _catenary(xf, fair[2] - anc[2])
        force = np.array([h * span[0] / xf, h * span[1] / xf, -v])
        out[:3] += force
        out[3:] += np.cross(arm, force)
    return out


def tangent_stiffness(ref_z: float = 0.0, step: float = 0.05, step_rad: float = 5e-4) -> np.ndarray:
    """6x6 tangent stiffness of the three lines at zero offset by central differences of :func:`solve_loads`.

    Parameters
    ----------
    ref_z : float
        Height of the reference point (m); 0 (SWL) is the point of the OC3 published matrix.
    step, step_rad : float
        Finite-difference steps for translations (m) and rotations (rad).

    Returns
    -------
    ndarray, shape (6, 6)
        ``K[i, j] = -d load_i / d q_j`` (N/m, N, N·m/rad), loads and DOFs ``(surge, sway, heave, roll, pitch, yaw)``
        about ``(0, 0, ref_z)``; moments about the displaced point.
    """
    k = np.empty((6, 6))
    for j in range(6):
        h = step if j < 3 else step_rad
        dq = np.zeros(6)
        dq[j] = h
        k[:, j] = -(solve_loads(dq, ref_z) - solve_loads(-dq, ref_z)) / (2 * h)
    return k


@numba.njit(cache=True, nogil=True)
def mooring_loads(grid_dx, grid_dy, grid_yaw, table, dx, dy, yaw, out):
    """Trilinear interpolation of the mooring table (compiled; for simulation kernels).

    Parameters
    ----------
    grid_dx, grid_dy, grid_yaw : ndarray, shape (n_dx,), (n_dy,), (n_yaw,)
        Uniformly spaced, increasing grids of the fairlead-centre offset (m) and the yaw angle (rad), each with
        at least 2 points (``MooringTable.grid_dx`` ...).
    table : ndarray, shape (n_dx, n_dy, n_yaw, 6)
        Loads on the grid (``MooringTable.table``).
    dx, dy : float
        Horizontal offset of the fairlead centre from its undisplaced position (m, global x downwind, y to port).
    yaw : float
        Platform yaw (rad).
    out : ndarray, shape (6,)
        Overwritten with ``(Fx, Fy, Fz, Mx, My, Mz)``: total line load on the platform, global axes (N, N·m),
        moments about the displaced fairlead centre.

    Notes
    -----
    Outside the grid the edge cell is extrapolated linearly (no clamping), so the restoring force keeps growing
    with the local tangent stiffness; the default grid covers offsets far beyond the operating range.
    """
    n0 = grid_dx.shape[0]
    n1 = grid_dy.shape[0]
    n2 = grid_yaw.shape[0]
    h0 = grid_dx[1] - grid_dx[0]
    h1 = grid_dy[1] - grid_dy[0]
    h2 = grid_yaw[1] - grid_yaw[0]
    s0 = (dx - grid_dx[0]) / h0
    s1 = (dy - grid_dy[0]) / h1
    s2 = (yaw - grid_yaw[0]) / h2
    i = min(max(int(np.floor(s0)), 0), n0 - 2)
    j = min(max(int(np.floor(s1)), 0), n1 - 2)
    k = min(max(int(np.floor(s2)), 0), n2 - 2)
    t0 = s0 - i
    t1 = s1 - j
    t2 = s2 - k
    u0 = 1.0 - t0
    u1 = 1.0 - t1
    u2 = 1.0 - t2
    w000 = u0 * u1 * u2
    w001 = u0 * u1 * t2
    w010 = u0 * t1 * u2
    w011 = u0 * t1 * t2
    w100 = t0 * u1 * u2
    w101 = t0 * u1 * t2
    w110 = t0 * t1 * u2
    w111 = t0 * t1 * t2
    for c in range(6):
        out[c] = (w000 * table[i, j, k, c] + w001 * table[i, j, k + 1, c]
                  + w010 * table[i, j + 1, k, c] + w011 * table[i, j + 1, k + 1, c]
                  + w100 * table[i + 1, j, k, c] + w101 * table[i + 1, j, k + 1, c]
                  + w110 * table[i + 1, j + 1, k, c] + w111 * table[i + 1, j + 1, k + 1, c])


def _cell(grid: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cell index and (unclamped) local coordinate on a uniform grid, as :func:`mooring_loads` computes them."""
    s = (x - grid[0]) / (grid[1] - grid[0])
    i = np.clip(np.floor(s).astype(np.int64), 0, grid.size - 2)
    return i, s - i


@dataclass(frozen=True)
class MooringTable:
    """Total quasi-static line load on the OC3 Hywind platform against fairlead offset and yaw (SI units).

    Attributes
    ----------
    grid_dx, grid_dy : ndarray, shape (n_dx,), (n_dy,)
        Uniform grids of the horizontal fairlead-centre offset (m).
    grid_yaw : ndarray, shape (n_yaw,)
        Uniform grid of the platform yaw (rad).
    table : ndarray, shape (n_dx, n_dy, n_yaw, 6)
        ``(Fx, Fy, Fz, Mx, My, Mz)`` on the platform, global axes (N, N·m), moments about the displaced fairlead
        centre ``(dx, dy, -70 m)``; C-contiguous float64, ready for :func:`mooring_loads`.
    loads0 : ndarray, shape (6,)
        Loads at zero offset and yaw (the pretension: ``Fz`` = minus the lines' suspended weight, N).
    stiffness : ndarray, shape (6, 6)
        Tangent stiffness at zero offset about SWL (:func:`tangent_stiffness`), N/m, N, N·m/rad.
    offset, horizontal_force, vertical_force : ndarray
        Legacy radial slice along +x at zero yaw: offsets (m, from 0), restoring force ``-(Fx - Fx0)`` (N, >= 0)
        and extra downward load ``-(Fz - Fz0)`` (N).
    linear_stiffness : float
        ``stiffness[0, 0]``, the tangent surge stiffness (N/m), a cross-check of K11.
    fairlead_z : float
        Fairlead height (m, negative below SWL).

    Examples
    --------
    >>> tab = mooring_table()
    >>> f = tab.loads(10.0, 0.0, 0.0)          # 10 m downwind
    >>> bool(f[0] < 0 and f[2] < 0)             # pulled back and down
    True
    """

    grid_dx: np.ndarray
    grid_dy: np.ndarray
    grid_yaw: np.ndarray
    table: np.ndarray
    loads0: np.ndarray
    stiffness: np.ndarray
    offset: np.ndarray = field(repr=False)
    horizontal_force: np.ndarray = field(repr=False)
    vertical_force: np.ndarray = field(repr=False)
    linear_stiffness: float = 0.0
    fairlead_z: float = FAIRLEAD_Z

    def loads(self, dx: float | np.ndarray, dy: float | np.ndarray, yaw: float | np.ndarray) -> np.ndarray:
        """Interpolated loads at offsets ``(dx, dy)`` (m) and yaw (rad); arrays broadcast.

        Same trilinear interpolation and linear extrapolation as :func:`mooring_loads`.

        Returns
        -------
        ndarray, shape (..., 6)
            ``(Fx, Fy, Fz, Mx, My, Mz)`` (N, N·m), global axes, moments about the displaced fairlead centre.
        """
        dx, dy, yaw = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (dx, dy, yaw)))
        if not (np.all(np.isfinite(dx)) and np.all(np.isfinite(dy)) and np.all(np.isfinite(yaw))):
            raise ValueError("dx, dy and yaw must be finite")
        i, t0 = _cell(self.grid_dx, dx)
        j, t1 = _cell(self.grid_dy, dy)
        k, t2 = _cell(self.grid_yaw, yaw)
        out = np.zeros(dx.shape + (6,))
        for a in (0, 1):
            wa = t0 if a else 1.0 - t0
            for b in (0, 1):
                wb = t1 if b else 1.0 - t1
                for c in (0, 1):
                    wc = t2 if c else 1.0 - t2
                    out += (wa * wb * wc)[..., None] * self.table[i + a, j + b, k + c]
        return out

    def excess_horizontal(self, rho: np.ndarray, k_linear: float) -> np.ndarray:
        """Legacy: radial restoring along +x beyond the linear ``k_linear * rho`` at offsets ``rho`` (N)."""
        return np.interp(rho, self.offset, self.horizontal_force) - k_linear * np.asarray(rho)


def _line_spline(xf_min: float, xf_max: float, spacing: float = 0.5):
    """Cubic Hermite fits of one line's fairlead ``H(xf), V(xf)`` (N) on ``[xf_min, xf_max]`` (m).

    Nodes are exact MoorPy solves with their analytic slopes, so the fit error is far below the table's
    interpolation error (``|error| < 1e-6`` relative, checked against direct solves in the tests).
    """
    from scipy.interpolate import CubicHermiteSpline

    n = max(int(np.ceil((xf_max - xf_min) / spacing)) + 1, 4)
    xs = np.linspace(xf_min, xf_max, n)
    zf = OC3_LINES["anchor_depth"] - OC3_LINES["fairlead_depth"]
    sol = np.array([_catenary(x, zf) for x in xs])
    return CubicHermiteSpline(xs, sol[:, 0], sol[:, 2]), CubicHermiteSpline(xs, sol[:, 1], sol[:, 3])


def _tabulate(dx: np.ndarray, dy: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Loads ``(..., 6)`` at broadcast ``(dx, dy, yaw)`` from the 1-D line fits (fairleads at -70 m, no tilt)."""
    anchors, fairs = _geometry()
    r = OC3_LINES["fairlead_radius"]
    ang = np.deg2rad(np.asarray(OC3_LINES["angles_deg"]))
    # arms (fairlead minus fairlead centre), per line: (..., 3)
    arm_x = r * np.cos(ang + yaw[..., None])
    arm_y = r * np.sin(ang + yaw[..., None])
    sx = anchors[:, 0] - (dx[..., None] + arm_x)
    sy = anchors[:, 1] - (dy[..., None] + arm_y)
    xf = np.hypot(sx, sy)
    h_fit, v_fit = _line_spline(float(xf.min()) - 1.0, float(xf.max()) + 1.0)
    h = h_fit(xf)
    v = v_fit(xf)
    fx = h * sx / xf
    fy = h * sy / xf
    fz = -v
    out = np.empty(dx.shape + (6,))
    out[..., 0] = fx.sum(-1)
    out[..., 1] = fy.sum(-1)
    out[..., 2] = fz.sum(-1)
    out[..., 3] = (arm_y * fz).sum(-1)
    out[..., 4] = (-arm_x * fz).sum(-1)
    out[..., 5] = (arm_x * fy - arm_y * fx).sum(-1)
    return out


@lru_cache(maxsize=4)
def mooring_table(max_offset: float = 60.0, n: int = 41) -> MooringTable:
    """Tabulate the OC3 catenary loads on the default grid (cached; about 0.4 s).

    Grid: ``dx`` in [-40, 60] m and ``dy`` in [-40, 40] m every 1 m, yaw in [-15, 15] deg every 5 deg (a 2 m grid
    misses 0.5 % by a little; yaw dependence is smooth). For offsets up to 25 m and any yaw in the grid, trilinear
    interpolation is within 0.5 % of the direct :func:`solve_loads`, measured componentwise against the restoring
    load ``max(|F - F0|, 50 kN)`` for forces and ``max(|M - M0|, 1 MN m)`` for moments (at sub-metre offsets the
    restoring load itself vanishes while the interpolation error of the quadratic set-down stays ~200 N, 0.01 % of
    the pretension). Each grid point sums three lines whose loads depend on the horizontal span only; the span is
    evaluated through a cubic Hermite fit of exact MoorPy solves (value and analytic slope every 0.5 m).

    Parameters
    ----------
    max_offset : float
        Largest offset of the legacy radial slice ``offset`` (m).
    n : int
        Number of points of the legacy radial slice.

    Returns
    -------
    MooringTable
    """
    gx = np.linspace(*_GRID_DX)
    gy = np.linspace(*_GRID_DY)
    gpsi = np.deg2rad(np.linspace(*_GRID_YAW_DEG))
    mx, my, mpsi = np.meshgrid(gx, gy, gpsi, indexing="ij")
    radial = np.linspace(0.0, max_offset, n)
    zeros = np.zeros_like(radial)
    both = _tabulate(np.concatenate([mx.ravel(), radial]), np.concatenate([my.ravel(), zeros]),
                     np.concatenate([mpsi.ravel(), zeros]))
    table = np.ascontiguousarray(both[: mx.size].reshape(mx.shape + (6,)))
    line = both[mx.size:]
    loads0 = solve_loads(np.zeros(6))
    k = tangent_stiffness()
    return MooringTable(grid_dx=gx, grid_dy=gy, grid_yaw=gpsi, table=table, loads0=loads0, stiffness=k,
                        offset=radial, horizontal_force=-(line[:, 0] - loads0[0]),
                        vertical_force=-(line[:, 2] - loads0[2]), linear_stiffness=float(k[0, 0]),
                        fairlead_z=FAIRLEAD_Z)


def read_map_deck(path: str | Path) -> dict:
    """Read the line geometry of a single-line-type MAP++ input file (the OC3 Hywind deck).

    Parameters
    ----------
    path : str or Path
        MAP++ ``.dat`` file with one line type, one anchor (``fix``) node, one ``Vessel`` node, one line and an
        optional ``repeat`` option.

    Returns
    -------
    dict
        Keys as in :data:`OC3_LINES` (``angles_deg`` sorted, degrees in [0, 360)), except ``anchor_depth``,
        which is ``None`` when the deck says ``depth`` (the water depth of the driver file).
    """
    text = Path(path).read_text(encoding="utf-8", errors="replace").splitlines()
    section = None
    rows: dict[str, list[list[str]]] = {"line dictionary": [], "node properties": [], "line properties": [],
                                         "solver options": []}
    for raw in text:
        s = raw.strip()
        if s.startswith("---"):
            name = re.sub(r"[-\s]+", " ", s).strip().lower()
            section = next((k for k in rows if name.startswith(k)), None)
            continue
        tok = s.split()
        if section and tok and not s.startswith("(") and tok[0].lower() not in ("id", "linetype", "option"):
            rows[section].append(tok)
    (ltype,) = rows["line dictionary"]
    nodes = {t[1].lower(): t for t in rows["node properties"]}
    anc, ves = nodes["fix"], nodes["vessel"]
    (line,) = rows["line properties"]
    base = float(np.degrees(np.arctan2(float(anc[3]), float(anc[2]))))
    repeats = [float(x) for t in rows["solver options"] if t[0].lower() == "repeat" for x in t[1:]]
    angles = sorted(((base + a) % 360.0) for a in [0.0, *repeats])
    return {
        "n_lines": len(angles),
        "angles_deg": tuple(angles),
        "anchor_depth": None if anc[4].lower() == "depth" else -float(anc[4]),
        "fairlead_depth": -float(ves[4]),
        "anchor_radius": float(np.hypot(float(anc[2]), float(anc[3]))),
        "fairlead_radius": float(np.hypot(float(ves[2]), float(ves[3]))),
        "unstretched_length": float(line[2]),
        "diameter": float(ltype[1]),
        "mass_density": float(ltype[2]),
        "extensional_stiffness": float(ltype[3]),
        "seabed_friction": float(ltype[4]),
    }


if __name__ == "__main__":  # pragma: no cover - a quick report
    import time

    t = time.perf_counter()
    tab = mooring_table()
    print(f"table {tab.table.shape} built in {time.perf_counter() - t:.2f} s")
    np.set_printoptions(precision=4, linewidth=150)
    print("loads0", tab.loads0)
    print("K about SWL\n", tab.stiffness)
