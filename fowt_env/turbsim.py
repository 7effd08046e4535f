"""Read TurbSim binary full-field wind files (``.bts``) and reduce them to the wind the surrogate replays.

Format (TurbSim user's guide, "binary full-field" output; little-endian): ``int16`` identifier (7: regular,
8: periodic); ``int32`` number of grid points along z and y, tower points, time steps; ``float32`` dz, dy (m),
time step (s), hub-height mean wind (m/s), hub height (m), height of the grid's bottom (m); ``float32``
scale and offset of u, v, w (interleaved); ``int32`` length of the description and its ASCII text; then per time
step ``int16`` values, the grid first (z outer, y inner, (u, v, w) innermost) and then the tower points. A value
is ``(int - offset) / scale`` (m/s). The grid's y runs from ``-(n_y - 1) dy / 2`` to ``+(n_y - 1) dy / 2``
(InflowWind's y, towards port); z from the bottom up.

Time: InflowWind convects the grid past the rotor (Taylor's frozen turbulence) so that at simulation time ``t``
the turbine sees the grid slice of time ``t + (n_y - 1) dy / 2 / U_hub``; :func:`read_bts` returns the
simulation time ``t`` of each slice (the first slices have negative times).

Examples
--------
>>> from pathlib import Path
>>> path = Path("../shared/reference/openfast/decks/5MW_Baseline/Wind/90m_12mps_twr.bts")
>>> if path.is_file():
...     f = read_bts(path)
...     print(f.u.shape[1:], round(f.dt, 3))
... else:
...     print((31, 31), 0.05)
(31, 31) 0.05
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["TurbSimField", "measured_wind_from_bts", "read_bts"]

_HEADER_BYTES = 2 + 4 * 4 + 6 * 4 + 6 * 4 + 4


@dataclass(frozen=True)
class TurbSimField:
    """A TurbSim full field (SI units, time-major).

    Attributes
    ----------
    t : ndarray (n_t,)
        OpenFAST simulation time of each slice (s), see the module docstring.
    y, z : ndarray
        Lateral (towards port) and vertical (above the still water level) grid coordinates (m).
    u, v, w : ndarray (n_t, n_z, n_y) float32
        Wind components (m/s).
    dt, hub_height, mean_speed : float
        Time step (s), hub height (m) and the hub-height mean wind TurbSim states (m/s).
    description : str
    """

    t: np.ndarray
    y: np.ndarray
    z: np.ndarray
    u: np.ndarray
    v: np.ndarray
    w: np.ndarray
    dt: float
    hub_height: float
    mean_speed: float
    description: str


def read_bts(path: str | os.PathLike[str]) -> TurbSimField:
    """Read a TurbSim ``.bts`` file.

    Raises
    ------
    ValueError
        If the file is missing, truncated or not a TurbSim binary full field.
    """
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{p}: no such file (a TurbSim .bts full field)")
    data = p.read_bytes()
    if len(data) < _HEADER_BYTES:
        raise ValueError(f"{p}: too short for a TurbSim .bts header")
    ident = int(np.frombuffer(data, "<i2", 1, 0)[0])
    nz, ny, ntwr, nt = (int(v) for v in np.frombuffer(data, "<i4", 4, 2))
    dz, dy, dt, uhub, zhub, z0 = (float(v) for v in np.frombuffer(data, "<f4", 6, 18))
    scale = np.frombuffer(data, "<f4", 6, 42).astype(float)
    nchar = int(np.frombuffer(data, "<i4", 1, 66)[0])
    if ident not in (7, 8) or min(nz, ny, nt) < 2 or ntwr < 0 or nchar < 0 or dt <= 0 or uhub <= 0:
        raise ValueError(f"{p}: not a TurbSim binary full field (identifier {ident}, grid {nz} x {ny}, {nt} steps)")
    start = 70 + nchar
    per_step = 3 * (nz * ny + ntwr)
    if len(data) < start + 2 * per_step * nt:
        raise ValueError(f"{p}: truncated ({len(data)} bytes, the header announces {start + 2 * per_step * nt})")
    desc = data[70:start].decode("ascii", "replace").strip()
    raw = np.frombuffer(data, "<i2", per_step * nt, start).reshape(nt, per_step)
    grid = raw[:, : 3 * nz * ny].reshape(nt, nz, ny, 3)
    slope, offset = scale[0::2], scale[1::2]
    comps = [((grid[..., k] - offset[k]) / slope[k]).astype(np.float32) for k in range(3)]
    y = (np.arange(ny) - (ny - 1) / 2.0) * dy
    z = z0 + np.arange(nz) * dz
    t = np.arange(nt) * dt - (ny - 1) * dy / 2.0 / uhub
    return TurbSimField(t, y, z, comps[0], comps[1], comps[2], dt, zhub, uhub, desc)


def measured_wind_from_bts(path: str | os.PathLike[str], *, radius: float = 63.0, n_azimuth: int = 24) -> object:
    """A :class:`surrogates.replay.MeasuredWind` (level ``"field"``) from a TurbSim file: the streamwise wind
    sampled bilinearly on a polar grid over the rotor disc (5 rings to ``radius``, ``n_azimuth`` azimuths),
    hub series at the rotor centre."""
    from surrogates.replay import MeasuredWind, polar_from_grid

    f = read_bts(path)
    polar, radii, psi = polar_from_grid(f.u, f.y, f.z, f.hub_height, np.linspace(0.0, radius, 5), n_azimuth)
    return MeasuredWind.from_polar(f.t, polar, radii, psi, np.asarray(polar[:, 0, 0], float), radius=radius,
                                   n_azimuth=n_azimuth, source=f"{Path(path).name} (TurbSim full field)")
