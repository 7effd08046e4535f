"""Replay measured conditions: a measured wave elevation and wind drive the surrogate instead of random draws.

A digital twin runs beside its turbine under the conditions actually measured. This module turns measured
inputs into exactly the forcing that :meth:`surrogates.Simulator.forcing` synthesises from random phases, so
that :func:`surrogates.simulate` (``waves=...``, ``wind=...``) reproduces a measurement sample by sample.

Waves (:class:`MeasuredWaves`)
------------------------------
A free-surface elevation series at the platform's reference point (the spar axis, OpenFAST's ``Wave1Elev`` at
(0, 0)) and the propagation direction. The record's Fourier amplitudes and phases take the place of the random
phases of the JONSWAP synthesis; the excitation (Morison inertia + Froude-Krylov, :func:`surrogates.waves.
excitation_rao`) and the particle velocities at the drag strips follow by the same per-frequency linear (Airy)
transfer functions. Long-crested waves are assumed (one direction).

Honest edges and band:

* the mean is removed (a linear sea has none); the record is extended at each end by its mirror image over
  ``taper_s``, faded to zero (cosine half-windows), and zero-padded before the FFT, so it is neither treated as
  periodic nor cut with a jump. The elevation -> load transfer functions are zero-phase low-pass kernels a few
  seconds long (the deep-water depth decay ``exp(omega^2 z / g)``), so the loads are exact except within those
  few seconds of either end, where the unknown past/future of the sea is stood in for by the mirror image
  (the elevation itself by up to a few percent in the last second, from the kink at the reflection).
  Discard a start-up of a few platform periods
  (:func:`surrogates.simulate`'s ``transient``, 60 s or more) -- the platform starts from rest at its mean
  offset and the slow surge mode (~125 s) needs that long to forget it;
* reproduced band: ``f_min_hz`` (default 0: everything but the mean; a brick-wall cut inside the record's
  content rings, and the deep strips' velocities, which peak near 0.03 Hz, magnify that ringing -- give a
  cut only to remove drift or tide, below the sea's energy) to ``f_max_hz`` (default the lower of 2 Hz and the
  record's Nyquist frequency). Above about
  0.2 Hz the loads lack diffraction (Morison inertia, see :mod:`surrogates.waves`), as in the random synthesis.

Wind (:class:`MeasuredWind`), three levels
------------------------------------------
* ``"hub"``: a hub-height streamwise wind series (nacelle anemometer, lidar, OpenFAST's ``Wind1VelX``). The
  rotor-effective wind is its best linear (Wiener) estimate under the IEC Kaimal/exponential-coherence model the
  surrogate synthesises with: ``U_eff(f) = G(f) U_hub(f)`` with ``G`` the hub-to-disc cross-spectrum ratio of
  :func:`surrogates.wind.rotor_averaging` (real, so zero-phase), plus the mean profile's disc average. The disc
  gradients are the mean shear only; no rotationally sampled turbulence.
* ``"rotor_effective"``: a rotor-effective (disc-averaged) wind series given directly (e.g. from a lidar wind
  field reconstruction or an estimator); optional hub series for the ``Wind1VelX`` channel (else the same).
* ``"field"``: the streamwise wind on a polar grid over the rotor disc (OpenFAST reference ``*.inflow.npz``, or a
  TurbSim full field sampled with :func:`polar_from_grid`). Disc mean and linear gradients come from
  :func:`surrogates.wind.rotor_plane_fit`; each blade's effective wind (radius-weighted along the blade, at
  :data:`surrogates.simulate.N_BLADE_AZIMUTH` azimuths) drives the rotationally sampled loads (1P, 3P, tilt and
  yaw moments), as for the synthesised field.

Time axes: inputs carry their own time axis (s); the simulation runs over the span every given input covers,
starting at the latest start. Each series is interpolated linearly onto the simulator's internal step (the wave
series after band-limited FFT upsampling to at least that rate).

Examples
--------
>>> import numpy as np
>>> t = np.arange(0.0, 200.0, 0.1)
>>> waves = MeasuredWaves(t, 1.0 * np.sin(2 * np.pi * 0.1 * t))
>>> loads = waves.loads(np.arange(50.0, 150.0, 0.05))
>>> round(float(np.abs(loads.elevation).max()), 2)
1.0
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft

from .aero import inplane_ring_weights
from .oc3 import WATER_DEPTH
from .validation import check_number
from .waves import SparGeometry, WaveLoads, _loads_from_transfer_series, _wave_transfer_rows
from .wind import rotor_averaging, rotor_plane_fit

if TYPE_CHECKING:  # pragma: no cover
    from .simulate import Simulator

__all__ = [
    "MIN_RECORD_SECONDS",
    "advection_delay",
    "record_wind_plane",
    "MeasuredWaves",
    "MeasuredWind",
    "as_measured_waves",
    "as_measured_wind",
    "blade_effective_wind",
    "stepper_blade_winds",
    "delayed_blade_winds",
    "measured_azimuth",
    "with_measured_azimuth",
    "polar_from_grid",
    "replay_forcing",
    "replay_window",
    "sea_state",
]

MIN_RECORD_SECONDS = 20.0
"""Shortest replayed input (s): the FFT must resolve the wave band (0.05 Hz) at least once."""
DEFAULT_TAPER_S = 10.0
"""Faded mirror extension at each end of a measured series before its FFT (s)."""
_PAD_SECONDS = 60.0  # zero padding after a measured series (at least), so the FFT does not wrap around
_STEP_TOLERANCE = 1e-3  # relative deviation of a time step from the median step accepted as a regular grid


# ------------------------------------------------------------------------------------------------ checks
def _time_series(name: str, t: object, x: object, *, columns: bool = False) -> tuple[np.ndarray, np.ndarray, float]:
    """Checked time axis (s), data (time-major) and step: regular, increasing, finite, long enough."""
    try:
        tt = np.asarray(t, dtype=float)
        xx = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: time and values must be arrays of numbers") from exc
    if tt.ndim != 1 or tt.size < 3:
        raise ValueError(f"{name}: the time axis must be 1-D with at least 3 samples, got shape {tt.shape}")
    if xx.shape[0:1] != tt.shape or (xx.ndim != 1 and not columns):
        raise ValueError(f"{name}: values of shape {xx.shape} do not match the time axis of {tt.size} samples")
    if not np.all(np.isfinite(tt)):
        raise ValueError(f"{name}: the time axis holds NaN or inf")
    bad = ~np.isfinite(xx.reshape(xx.shape[0], -1)).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}: {int(bad.sum())} non-finite sample(s) (NaN/inf), the first at t = {tt[i]:g} s; "
                         "fill or cut the gaps before replaying (replay needs a gap-free series)")
    steps = np.diff(tt)
    dt = float(np.median(steps))
    if dt <= 0 or np.any(steps <= 0):
        raise ValueError(f"{name}: the time axis must be strictly increasing")
    dev = np.abs(steps - dt)
    if np.any(dev > _STEP_TOLERANCE * dt):
        i = int(np.argmax(dev))
        raise ValueError(f"{name}: the time axis is not regular (step {steps[i]:g} s at t = {tt[i]:g} s, median "
                         f"{dt:g} s); resample it onto a regular grid first")
    span = float(tt[-1] - tt[0])
    if span < MIN_RECORD_SECONDS:
        raise ValueError(f"{name}: the series covers {span:g} s, shorter than {MIN_RECORD_SECONDS:g} s")
    return tt, xx, dt


def _extend(x: np.ndarray, dt: float, taper_s: float) -> tuple[np.ndarray, int]:
    """``x`` (mean removed) extended at both ends by its mirror image over ``taper_s``, faded to zero there by
    cosine half-windows; returns the extended series and the number of samples added at each end.

    The record itself is left intact; the even reflection keeps the series continuous at its ends (a point
    reflection would also keep the slope, but drifts and puts spurious low-frequency content into the deep
    strips' kinematics), and the fade lets the zero padding that follows meet it without a jump."""
    n = x.size
    m = min(int(round(taper_s / dt)), n - 1)
    x = x - x.mean()
    if m <= 0:
        return x, 0
    ramp = 0.5 * (1.0 - np.cos(np.pi * (np.arange(m) + 0.5) / m))
    head = x[1:m + 1][::-1] * ramp
    tail = x[n - m - 1:n - 1][::-1] * ramp[::-1]
    return np.concatenate([head, x, tail]), m


def _fft_filter(x: np.ndarray, dt: float, transfer: Any, taper_s: float, up: int = 1,
                band: tuple[float, float] | None = None) -> np.ndarray:
    """Filter a series (mean removed, ends extended by :func:`_extend`, zero-padded) in the frequency domain.

    ``transfer(f)`` returns the complex transfer functions ``(n_out, len(f))``; the result is the filtered
    series ``(n * up, n_out)`` on the grid ``dt / up`` from the first sample (band-limited upsampling by
    zero-padding the spectrum).
    """
    n = x.size
    ext, m = _extend(x, dt, taper_s)
    n_fft = next_fast_len(ext.size + max(n // 4, int(math.ceil(_PAD_SECONDS / dt))), real=True)
    spec = rfft(ext, n=n_fft)
    f = np.fft.rfftfreq(n_fft, dt)
    keep = f < 0.5 / dt  # the Nyquist bin of an even FFT is ambiguous
    if band is not None:
        keep &= (f >= band[0]) & (f <= band[1])
    idx = np.flatnonzero(keep)
    rows = np.atleast_2d(transfer(f[idx]))
    n_used = int(idx[-1]) + 1 if idx.size else 1
    full = np.zeros((rows.shape[0], n_used), dtype=complex)
    full[:, idx] = rows * spec[idx]
    out = irfft(full, n=n_fft * up, axis=-1) * up
    return np.ascontiguousarray(out[:, m * up: (m + n) * up].T)


# ------------------------------------------------------------------------------------------------- waves
@dataclass(frozen=True)
class MeasuredWaves:
    """A measured wave elevation at the platform's reference point, to replay (SI units).

    Parameters
    ----------
    t : array_like (n,)
        Time (s), regular and increasing, at least :data:`MIN_RECORD_SECONDS` long.
    elevation : array_like (n,)
        Free-surface elevation at the spar axis (m), finite (no gaps).
    direction_deg : float or None
        Propagation direction (deg; 0 = along +x, downwind). None: the load case's ``wave_dir_deg``.
    f_min_hz, f_max_hz : float
        Band replayed (Hz). Default 0 (all but the mean) and the lower of 2 Hz and the Nyquist frequency.
    taper_s : float
        Length of the faded mirror extension at each end (s), default :data:`DEFAULT_TAPER_S`.
    source : str
        Where the series came from (kept in the record's ``meta``).

    Examples
    --------
    >>> t = np.arange(0.0, 120.0, 0.25)
    >>> w = MeasuredWaves(t, np.cos(2 * np.pi * t / 10.0), direction_deg=0.0)
    >>> w.dt, w.f_max_hz
    (0.25, 2.0)
    """

    t: np.ndarray
    elevation: np.ndarray
    direction_deg: float | None = None
    f_min_hz: float = 0.0
    f_max_hz: float | None = None
    taper_s: float = DEFAULT_TAPER_S
    source: str = ""
    dt: float = field(init=False)

    def __post_init__(self) -> None:
        t, x, dt = _time_series("waves", self.t, self.elevation)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "elevation", x)
        object.__setattr__(self, "dt", dt)
        if self.direction_deg is not None:
            object.__setattr__(self, "direction_deg", check_number("direction_deg", self.direction_deg))
        f_lo = check_number("f_min_hz", self.f_min_hz, nonneg=True)
        nyquist = 0.5 / dt
        f_hi = min(2.0, nyquist) if self.f_max_hz is None else check_number("f_max_hz", self.f_max_hz, positive=True)
        if f_hi <= f_lo:
            raise ValueError(f"f_max_hz ({f_hi} Hz) must be above f_min_hz ({f_lo} Hz)")
        object.__setattr__(self, "f_min_hz", f_lo)
        object.__setattr__(self, "f_max_hz", float(f_hi))
        object.__setattr__(self, "taper_s", check_number("taper_s", self.taper_s, nonneg=True))

    @classmethod
    def from_record(cls, record: Any, channel: str = "Wave1Elev", **kwargs: Any) -> MeasuredWaves:
        """The elevation channel of a :class:`surrogates.Record` (an OpenFAST record's ``Wave1Elev``, m)."""
        if channel not in getattr(record, "channels", ()):
            raise ValueError(f"waves: the record has no {channel!r} channel (a measured wave elevation, m)")
        return cls(np.asarray(record.t), np.asarray(record[channel]), source=f"record channel {channel}", **kwargs)

    def loads(self, t_out: np.ndarray, direction_deg: float = 0.0, *, n_strips: int = 24,
              depth: float = WATER_DEPTH, geometry: SparGeometry | None = None) -> WaveLoads:
        """Elevation, first-order excitation and strip velocities at times ``t_out`` (s), from this record.

        The record's spectrum times the transfer functions of :func:`surrogates.waves.synthesize_waves` (the
        same model and quadrature), inverse FFT, band-limited upsampling to at least the rate of ``t_out``, and
        linear interpolation onto ``t_out``. ``self.direction_deg`` overrides ``direction_deg`` when set.

        Returns
        -------
        WaveLoads
            ``t = t_out``; ``frequencies_hz``/``spectrum`` describe the record's FFT grid and its one-sided
            periodogram (m²/Hz, 0 outside the band).

        Raises
        ------
        ValueError
            If ``t_out`` reaches outside the record.
        """
        t_out = np.asarray(t_out, dtype=float)
        if t_out.size and (t_out.min() < self.t[0] - 1e-9 or t_out.max() > self.t[-1] + 1e-6):
            raise ValueError(f"waves: times {t_out.min():g}-{t_out.max():g} s reach outside the record "
                             f"({self.t[0]:g}-{self.t[-1]:g} s)")
        beta = np.deg2rad(self.direction_deg if self.direction_deg is not None else direction_deg)
        geo = SparGeometry() if geometry is None else geometry
        z, dz, diam = geo.strips(n_strips)
        step_out = float(np.median(np.diff(t_out))) if t_out.size > 1 else self.dt
        up = max(1, int(math.ceil(self.dt / step_out - 1e-9)))

        def transfer(f: np.ndarray) -> np.ndarray:
            return _wave_transfer_rows(f, depth, geo, z)

        fine = _fft_filter(self.elevation, self.dt, transfer, self.taper_s, up, (self.f_min_hz, self.f_max_hz))
        t_fine = self.t[0] + np.arange(fine.shape[0]) * (self.dt / up)
        series = np.empty((t_out.size, fine.shape[1]))
        for j in range(fine.shape[1]):
            series[:, j] = np.interp(t_out, t_fine, fine[:, j])
        excitation, velocity = _loads_from_transfer_series(series, beta)
        n = self.elevation.size
        freqs = np.fft.rfftfreq(n, self.dt)
        per = 2.0 * np.abs(np.fft.rfft(self.elevation - self.elevation.mean())) ** 2 * self.dt / n
        per[(freqs < self.f_min_hz) | (freqs > self.f_max_hz)] = 0.0
        meta = {"replayed": True, "source": self.source, "direction_deg": float(np.rad2deg(beta)),
                "f_min_hz": self.f_min_hz, "f_max_hz": self.f_max_hz, "taper_s": self.taper_s, "depth": depth,
                "dt": step_out}
        return WaveLoads(t_out, series[:, 0].copy(), excitation, z, dz, diam, velocity, freqs, per, meta)


def sea_state(t: np.ndarray, elevation: np.ndarray) -> tuple[float, float]:
    """Significant wave height ``4 sigma`` (m) and peak period (s, of a Welch PSD) of a measured elevation.

    Examples
    --------
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> hs, tp = sea_state(t, np.sin(2 * np.pi * t / 8.0))
    >>> round(hs, 2), round(tp, 1)
    (2.83, 8.0)
    """
    from scipy.signal import welch

    tt, x, dt = _time_series("elevation", t, elevation)
    f, p = welch(x - x.mean(), fs=1.0 / dt, nperseg=min(x.size, int(round(200.0 / dt))))
    sel = f >= 0.02
    fp = float(f[sel][np.argmax(p[sel])])
    return 4.0 * float(np.std(x)), 1.0 / fp


# -------------------------------------------------------------------------------------------------- wind
def _profile_disc_mean(exponent: float, hub_height: float = 90.0, radius: float = 63.0) -> float:
    """Area-weighted disc mean of the power-law profile ``((H + z) / H)^alpha`` (-)."""
    r = (np.arange(200) + 0.5) * radius / 200
    a = np.arange(180) * 2 * np.pi / 180
    z = r[:, None] * np.cos(a)[None, :]
    return float(np.sum(r[:, None] * ((hub_height + z) / hub_height) ** exponent) / (np.sum(r) * a.size))


def blade_effective_wind(polar_u: np.ndarray, radii: np.ndarray, azimuth_rad: np.ndarray,
                         n_azimuth: int = 24, weights: np.ndarray | None = None) -> np.ndarray:
    """Each blade's effective streamwise wind around the rotor from a polar-grid field (m/s).

    The wind along a blade at azimuth ``psi`` averaged over the rings with weights proportional to the radius
    (what the surrogate's rotationally sampled thrust and torque use) or with the given ring ``weights``
    (e.g. :func:`surrogates.aero.inplane_ring_weights` for the in-plane force), at ``n_azimuth`` uniform
    azimuths from the top towards +y, interpolated periodically from the grid's azimuths.

    Parameters
    ----------
    polar_u : array_like (n_t, n_radii, n_grid_azimuth)
        Streamwise wind (m/s).
    radii : array_like (n_radii,)
        Ring radii (m), increasing, from 0 (hub) or above.
    azimuth_rad : array_like (n_grid_azimuth,)
        Uniform azimuths (rad) from the top towards +y.
    n_azimuth : int
        Azimuths of the result.
    weights : array_like (n_radii,), optional
        Ring weights (normalised to sum 1); default proportional to the radius.

    Returns
    -------
    ndarray (n_t, n_azimuth) float32
    """
    u = np.asarray(polar_u, dtype=float)
    r = np.asarray(radii, dtype=float)
    psi = np.asarray(azimuth_rad, dtype=float)
    if u.ndim != 3 or u.shape[1:] != (r.size, psi.size):
        raise ValueError(f"polar_u must have shape (n_t, {r.size}, {psi.size}), got {u.shape}")
    if weights is None:
        w = np.where(r > 0, r, 0.0)
        if w.sum() <= 0:
            raise ValueError("radii must include a ring of radius > 0")
    else:
        w = np.asarray(weights, dtype=float)
        if w.shape != r.shape or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
            raise ValueError(f"weights must be {r.size} finite non-negative ring weights, got {weights!r}")
    along = np.einsum("tra,r->ta", u, w / w.sum())
    target = np.arange(n_azimuth) * 2.0 * np.pi / n_azimuth
    ext = np.concatenate([psi, [psi[0] + 2.0 * np.pi]])
    cols = np.concatenate([along, along[:, :1]], axis=1)
    out = np.empty((u.shape[0], n_azimuth), dtype=np.float32)
    pos = (target - psi[0]) % (2.0 * np.pi) + psi[0]
    j = np.clip(np.searchsorted(ext, pos, side="right") - 1, 0, psi.size - 1)
    frac = (pos - ext[j]) / (ext[j + 1] - ext[j])
    out[:] = (1.0 - frac) * cols[:, j] + frac * cols[:, j + 1]
    return out


def polar_from_grid(u: np.ndarray, y: np.ndarray, z: np.ndarray, hub_height: float = 90.0,
                    radii: np.ndarray | None = None, n_azimuth: int = 24) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample a Cartesian wind grid (TurbSim full field) on a polar grid over the rotor disc (bilinear).

    Parameters
    ----------
    u : array_like (n_t, n_z, n_y)
        Streamwise wind (m/s) on the grid, time-major.
    y, z : array_like (n_y,), (n_z,)
        Grid coordinates (m): y lateral (towards port, +y), z height above the still water level.
    hub_height : float
        Height of the rotor centre (m).
    radii : array_like, optional
        Ring radii (m); default 0, 15.75, 31.5, 47.25, 63 (5 rings to the tip).
    n_azimuth : int
        Azimuths per ring from the top towards +y.

    Returns
    -------
    polar_u (n_t, n_radii, n_azimuth) float32, radii (m), azimuth_rad (rad)
    """
    uu = np.asarray(u)
    yy = np.asarray(y, dtype=float)
    zz = np.asarray(z, dtype=float)
    if uu.ndim != 3 or uu.shape[1:] != (zz.size, yy.size):
        raise ValueError(f"u must have shape (n_t, {zz.size}, {yy.size}), got {uu.shape}")
    r = np.linspace(0.0, 63.0, 5) if radii is None else np.asarray(radii, dtype=float)
    psi = np.arange(n_azimuth) * 2.0 * np.pi / n_azimuth
    py = r[:, None] * np.sin(psi)[None, :]
    pz = hub_height + r[:, None] * np.cos(psi)[None, :]
    if py.min() < yy[0] - 1e-6 or py.max() > yy[-1] + 1e-6 or pz.min() < zz[0] - 1e-6 or pz.max() > zz[-1] + 1e-6:
        raise ValueError("the rotor disc reaches outside the wind grid")
    iy = np.clip(np.searchsorted(yy, py) - 1, 0, yy.size - 2)
    iz = np.clip(np.searchsorted(zz, pz) - 1, 0, zz.size - 2)
    ty = (py - yy[iy]) / (yy[iy + 1] - yy[iy])
    tz = (pz - zz[iz]) / (zz[iz + 1] - zz[iz])
    out = ((1 - tz) * ((1 - ty) * uu[:, iz, iy] + ty * uu[:, iz, iy + 1])
           + tz * ((1 - ty) * uu[:, iz + 1, iy] + ty * uu[:, iz + 1, iy + 1]))
    return out.astype(np.float32), r, psi


@dataclass(frozen=True)
class MeasuredWind:
    """Measured wind to replay: hub series, rotor-effective series and, for a field, gradients and blade winds.

    Build it with :meth:`from_hub`, :meth:`from_rotor_effective`, :meth:`from_polar`, :meth:`from_record` or
    :meth:`from_inflow` (see the module docstring for the three levels).

    Attributes
    ----------
    t : ndarray (n,)
        Time (s), regular.
    hub : ndarray (n,)
        Streamwise wind at the hub point (m/s), the ``Wind1VelX`` channel.
    rotor_effective : ndarray (n,)
        Disc-averaged streamwise wind (m/s) that drives thrust and torque.
    shear_y, shear_z : ndarray (n,) or None
        Linear gradients of the wind over the disc (1/s); None: the load case's mean shear.
    blade : ndarray (n, n_azimuth) float32 or None
        Blade-effective wind at uniform azimuths from the top towards +y (m/s); None: no rotational sampling of
        turbulence.
    level : str
        ``"hub"``, ``"rotor_effective"`` or ``"field"``.
    source : str
    x_ref : float or None
        Downwind position (m, inertial frame, from the platform's undisplaced axis) of the plane where the wind
        was measured; default 0: OpenFAST's convention (``Wind1VelX`` at (0, 0, hub height), the TurbSim field
        passing x = 0 at its own time). The replay carries it to the rotor's mean position by Taylor's frozen
        turbulence: it reaches the rotor ``(x_rotor - x_ref) / U`` later (:func:`advection_delay`; 2.1 s at
        12 m/s, where the rotor sits ~21 m downwind of x = 0). None: measured at the moving rotor (a rotor
        wind estimate, a spinner anemometer or a lidar referenced to the rotor): no delay.
    blade_inplane : ndarray (n, n_azimuth) float32 or None
        The wind along each blade weighted as its in-plane force answers it (m/s,
        :func:`surrogates.aero.inplane_ring_weights`, same azimuths as ``blade``); None: ``blade`` stands in.
    """

    t: np.ndarray
    hub: np.ndarray
    rotor_effective: np.ndarray
    shear_y: np.ndarray | None = None
    shear_z: np.ndarray | None = None
    blade: np.ndarray | None = None
    level: str = "rotor_effective"
    source: str = ""
    x_ref: float | None = 0.0
    blade_inplane: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.x_ref is not None and not np.isfinite(self.x_ref):
            raise ValueError(f"wind: x_ref must be a finite position (m) or None, got {self.x_ref!r}")
        t, hub, _ = _time_series("wind", self.t, self.hub)
        _, eff, _ = _time_series("wind (rotor-effective)", t, self.rotor_effective)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "hub", hub)
        object.__setattr__(self, "rotor_effective", eff)
        for name in ("shear_y", "shear_z"):
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, _time_series(f"wind ({name})", t, v)[1])
        if self.blade is not None:
            b = _time_series("wind (blade)", t, self.blade, columns=True)[1]
            if b.ndim != 2 or b.shape[1] < 3:
                raise ValueError(f"wind: blade must have shape (n, n_azimuth >= 3), got {b.shape}")
            object.__setattr__(self, "blade", b.astype(np.float32))
        if self.blade_inplane is not None:
            if self.blade is None:
                raise ValueError("wind: blade_inplane needs blade (the thrust and torque's blade wind) too")
            b = _time_series("wind (blade_inplane)", t, self.blade_inplane, columns=True)[1]
            if b.shape != self.blade.shape:
                raise ValueError(f"wind: blade_inplane must have the shape of blade {self.blade.shape}, got {b.shape}")
            object.__setattr__(self, "blade_inplane", b.astype(np.float32))
        if self.level not in ("hub", "rotor_effective", "field"):
            raise ValueError(f"wind: level must be 'hub', 'rotor_effective' or 'field', got {self.level!r}")
        if float(np.mean(eff)) <= 0:
            raise ValueError("wind: the mean rotor-effective wind must be > 0 m/s (the rotor must operate)")

    @classmethod
    def from_hub(cls, t: np.ndarray, hub: np.ndarray, *, shear_exponent: float = 0.2, hub_height: float = 90.0,
                 radius: float = 63.0, taper_s: float = DEFAULT_TAPER_S, source: str = "",
                 x_ref: float | None = 0.0) -> MeasuredWind:
        """Hub-height wind (m/s) -> rotor-effective wind through the rotor-averaging (Wiener) filter ``G(f)``.

        ``U_eff = A_profile mean(U_hub) + G(f) * (U_hub - mean)``: ``G`` from :func:`surrogates.wind.
        rotor_averaging` at the record's mean speed, ``A_profile`` the disc mean of the power-law profile.
        """
        tt, u, dt = _time_series("wind", t, hub)
        v = float(np.mean(u))
        if v <= 0:
            raise ValueError(f"wind: the mean hub wind must be > 0 m/s, got {v:g}")
        alpha = check_number("shear_exponent", shear_exponent, nonneg=True)
        eff = _fft_filter(u, dt, lambda f: rotor_averaging(f, v, radius, hub_height)[1][None, :].astype(complex),
                          taper_s)[:, 0]
        eff = eff + v * _profile_disc_mean(alpha, hub_height, radius)
        return cls(tt, u, eff, level="hub", source=source or "hub-height wind", x_ref=x_ref)

    @classmethod
    def from_hub_sheared(cls, t: np.ndarray, hub: np.ndarray, *, shear_exponent: float = 0.2,
                         hub_height: float = 90.0, radius: float = 63.0, n_radii: int = 5, n_azimuth: int = 24,
                         source: str = "", x_ref: float | None = 0.0) -> MeasuredWind:
        """A hub-height wind spread over the disc by the power-law profile: a field ``U_hub(t) (z/H)^alpha``.

        What a steady-wind run with shear (OpenFAST's InflowWind ``WindType = 1``, ``PLExp``) feeds its rotor: the
        blades meet the profile once per revolution (the mean tilt moment, and with the blades' flap lag a mean
        yaw moment) and the disc mean is the profile's. Built on a polar grid (``n_radii`` rings to ``radius``,
        ``n_azimuth`` azimuths) and read as :meth:`from_polar`; level ``"field"``.

        Parameters
        ----------
        t, hub : ndarray (n,)
            Time (s, regular) and hub-height wind (m/s, > 0 on average).
        shear_exponent : float
            Power-law exponent (-), >= 0.
        hub_height, radius : float
            Hub height and rotor radius (m).
        """
        tt, u, _ = _time_series("wind", t, hub)
        if float(np.mean(u)) <= 0:
            raise ValueError(f"wind: the mean hub wind must be > 0 m/s, got {float(np.mean(u)):g}")
        alpha = check_number("shear_exponent", shear_exponent, nonneg=True)
        h = check_number("hub_height", hub_height, positive=True)
        rad = check_number("radius", radius, positive=True)
        if rad >= h:
            raise ValueError(f"radius ({rad:g} m) must be below the hub height ({h:g} m)")
        radii = np.linspace(0.0, rad, int(n_radii))
        psi = np.arange(int(n_azimuth)) * 2.0 * np.pi / int(n_azimuth)
        profile = ((h + radii[:, None] * np.cos(psi)[None, :]) / h) ** alpha
        polar = (u[:, None, None] * profile[None, :, :]).astype(np.float32)
        return cls.from_polar(tt, polar, radii, psi, hub=u, radius=rad, n_azimuth=int(n_azimuth),
                              source=source or f"hub-height wind with power-law shear {alpha:g}", x_ref=x_ref)

    @classmethod
    def from_rotor_effective(cls, t: np.ndarray, rotor_effective: np.ndarray, hub: np.ndarray | None = None,
                             source: str = "", x_ref: float | None = None) -> MeasuredWind:
        """A rotor-effective wind series (m/s) given directly; ``hub`` (m/s) for the Wind1VelX channel; ``x_ref``
        where it was measured (default None: at the rotor, as an estimate from the rotor's own response is)."""
        eff = np.asarray(rotor_effective, dtype=float)
        return cls(np.asarray(t, float), eff if hub is None else np.asarray(hub, float), eff,
                   level="rotor_effective", source=source or "rotor-effective wind", x_ref=x_ref)

    @classmethod
    def from_polar(cls, t: np.ndarray, polar_u: np.ndarray, radii: np.ndarray, azimuth_rad: np.ndarray,
                   hub: np.ndarray | None = None, *, radius: float = 63.0, n_azimuth: int = 24,
                   source: str = "", x_ref: float | None = 0.0) -> MeasuredWind:
        """A streamwise field on a polar rotor grid (n_t, n_radii, n_azimuth), m/s -> disc mean, gradients and
        blade-effective winds; ``hub`` (m/s, default the grid's ring of radius 0)."""
        u = np.asarray(polar_u)
        mean, gy, gz = rotor_plane_fit(u, radii, azimuth_rad, radius=max(radius, float(np.max(radii))))
        if hub is None:
            r = np.asarray(radii, float)
            if r[0] != 0.0:
                raise ValueError("wind: give hub= when the polar grid has no ring of radius 0")
            hub = np.asarray(u[:, 0, 0], float)
        blade = blade_effective_wind(u, radii, azimuth_rad, n_azimuth)
        hub = np.asarray(hub, float)
        w_ip, _ = inplane_ring_weights(radii, max(float(np.mean(hub)), 0.1))
        inplane = blade_effective_wind(u, radii, azimuth_rad, n_azimuth, weights=w_ip)
        return cls(np.asarray(t, float), hub, mean, gy, gz, blade, level="field",
                   source=source or "polar wind field", x_ref=x_ref, blade_inplane=inplane)

    @classmethod
    def from_record(cls, record: Any, channel: str = "Wind1VelX", **kwargs: Any) -> MeasuredWind:
        """The hub wind channel of a :class:`surrogates.Record` (OpenFAST ``Wind1VelX``), level ``"hub"``.

        Its plane ``x_ref`` (unless given): 0 for an OpenFAST record (a fixed point at x = 0); None for a record
        of :func:`surrogates.simulate`, whose wind is synthesised at the rotor.
        """
        if channel not in getattr(record, "channels", ()):
            raise ValueError(f"wind: the record has no {channel!r} channel (hub-height wind, m/s)")
        if "x_ref" not in kwargs:
            kwargs["x_ref"] = record_wind_plane(getattr(record, "meta", None))
        return cls.from_hub(np.asarray(record.t), np.asarray(record[channel]),
                            source=f"record channel {channel}", **kwargs)

    @classmethod
    def from_inflow(cls, path: Any, level: str = "field") -> MeasuredWind:
        """An OpenFAST reference ``*.inflow.npz`` (``t``, ``hub_uvw``, ``disc_mean_u``, ``polar_u``, ...).

        ``level``: ``"field"`` (polar grid), ``"rotor_effective"`` (``disc_mean_u``) or ``"hub"``.
        """
        with np.load(path, allow_pickle=False) as z:
            missing = {"t", "hub_uvw"} - set(z.files)
            if missing:
                raise ValueError(f"wind: {path} is not an inflow file (missing {sorted(missing)})")
            t = np.asarray(z["t"], float)
            hub = np.asarray(z["hub_uvw"][:, 0], float)
            src = f"{path} ({level})"
            # the OpenFAST reference's wind passes the plane x = 0 (Wind1VelX's point) at its time axis
            if level == "hub":
                return cls.from_hub(t, hub, source=src, x_ref=0.0)
            if level == "rotor_effective":
                return cls.from_rotor_effective(t, np.asarray(z["disc_mean_u"], float), hub, source=src, x_ref=0.0)
            if level == "field":
                return cls.from_polar(t, z["polar_u"], z["polar_radii"], z["polar_azimuth_rad"], hub, source=src,
                                      x_ref=0.0)
        raise ValueError(f"wind: level must be 'hub', 'rotor_effective' or 'field', got {level!r}")

    def mean_speed(self) -> float:
        """Mean hub-height wind (m/s)."""
        return float(np.mean(self.hub))

    def window(self, t0: float | None = None, t1: float | None = None) -> MeasuredWind:
        """The wind between ``t0`` and ``t1`` (s, inclusive; None: from the start / to the end), e.g. to start a
        simulation at a reference run's time 0 when its inflow begins earlier.

        Raises
        ------
        ValueError
            If fewer than two samples fall in the window.
        """
        keep = np.ones(self.t.shape, dtype=bool)
        if t0 is not None:
            keep &= self.t >= float(t0) - 1e-9
        if t1 is not None:
            keep &= self.t <= float(t1) + 1e-9
        if int(keep.sum()) < 2:
            raise ValueError(f"wind: fewer than two samples in [{t0}, {t1}] s (the wind spans "
                             f"{self.t[0]:g}-{self.t[-1]:g} s)")
        cut = {name: (None if getattr(self, name) is None else getattr(self, name)[keep])
               for name in ("t", "hub", "rotor_effective", "shear_y", "shear_z", "blade", "blade_inplane")}
        return dataclasses.replace(self, **cut)


def record_wind_plane(meta: Mapping[str, Any] | None) -> float | None:
    """Where a record's ``Wind1VelX`` was measured (:attr:`MeasuredWind.x_ref`), from the record's ``meta``: None
    (at the rotor) for a record of :func:`surrogates.simulate`, whose wind is synthesised there; else 0, OpenFAST's
    fixed point at the platform's undisplaced axis."""
    return None if (meta or {}).get("source") == "surrogates.simulate" else 0.0


def advection_delay(sim: Simulator, wind: MeasuredWind | None = None, *, x_ref: float | None = 0.0,
                    mean_speed: float | None = None) -> float:
    """Time (s) the measured wind takes from its plane ``x_ref`` to the rotor (Taylor's frozen turbulence).

    The rotor apex's mean downwind position is taken at the simulator's static equilibrium (mean surge, mean
    pitch, the tower's mean bending, the overhang); the wind is advected at the load case's wind speed (a
    replay's linearisation point: the measured mean), so that every replay path of one simulator delays alike.
    The rotor's motion about that mean is left to the hub-relative wind the aerodynamics already use.

    Parameters
    ----------
    sim : Simulator
    wind : MeasuredWind, optional
        Gives ``x_ref`` (and the speed when the load case has none); otherwise pass ``x_ref``.
    x_ref : float or None
        Plane of the measurement (m downwind); None: at the rotor (delay 0).
    mean_speed : float, optional
        Advection speed (m/s); default the simulator's load case's wind speed, else ``wind``'s mean hub speed.
    """
    from .structure import _FLAP

    if wind is not None:
        x_ref = wind.x_ref
    if x_ref is None:
        return 0.0
    if mean_speed is None:
        mean_speed = sim.case.wind_speed if sim.case is not None and sim.case.wind_speed > 0 else (
            wind.mean_speed() if wind is not None else 0.0)
    st = sim.system.structure
    # the rotor apex (the blades' flap deflection downwind and their precone upwind nearly cancel at the thrust
    # centre: +1.8 and -1.8 m at 12 m/s)
    x_rotor = float(st.hub_position[0] + st.hub_translation[0, :_FLAP] @ sim.x_eq[:_FLAP])
    return (x_rotor - float(x_ref)) / max(float(mean_speed), 0.1)


def as_measured_waves(waves: Any) -> MeasuredWaves:
    """A :class:`MeasuredWaves` from itself, a record with ``Wave1Elev`` or a ``(t, elevation)`` pair."""
    if isinstance(waves, MeasuredWaves):
        return waves
    if hasattr(waves, "channels") and hasattr(waves, "t"):
        return MeasuredWaves.from_record(waves)
    if isinstance(waves, tuple | list) and len(waves) == 2:
        return MeasuredWaves(np.asarray(waves[0], float), np.asarray(waves[1], float), source="array")
    raise ValueError("waves must be a MeasuredWaves, a Record with a Wave1Elev channel or a (t, elevation) pair, "
                     f"got {type(waves).__name__}")


def as_measured_wind(wind: Any) -> MeasuredWind:
    """A :class:`MeasuredWind` from itself, a record with ``Wind1VelX`` (hub level) or a ``(t, hub)`` pair."""
    if isinstance(wind, MeasuredWind):
        return wind
    if hasattr(wind, "channels") and hasattr(wind, "t"):
        return MeasuredWind.from_record(wind)
    if isinstance(wind, tuple | list) and len(wind) == 2:
        return MeasuredWind.from_hub(np.asarray(wind[0], float), np.asarray(wind[1], float), source="array")
    raise ValueError("wind must be a MeasuredWind, a Record with a Wind1VelX channel or a (t, hub wind) pair, "
                     f"got {type(wind).__name__}")


# ------------------------------------------------------------------------------------------------ forcing
def replay_window(waves: MeasuredWaves | None, wind: MeasuredWind | None, duration: float | None,
                  transient: float, dt: float) -> tuple[float, float]:
    """Start time (s) of the simulation and the output duration (s) the replayed inputs allow.

    The simulation starts at the latest start of the given inputs; ``duration`` None takes everything they
    cover after ``transient``.

    Raises
    ------
    ValueError
        If the inputs do not overlap or cover less than ``transient + duration``.
    """
    spans = [(x.t[0], x.t[-1]) for x in (waves, wind) if x is not None]
    t0 = max(s[0] for s in spans)
    t1 = min(s[1] for s in spans)
    if t1 - t0 < MIN_RECORD_SECONDS:
        raise ValueError(f"the replayed inputs overlap over {max(t1 - t0, 0.0):g} s only (waves and wind time "
                         f"axes must share at least {MIN_RECORD_SECONDS:g} s)")
    avail = t1 - t0 - transient - 2 * dt  # one sample for the hold and rounding
    if duration is None:
        if avail < 2 * dt:
            raise ValueError(f"the replayed inputs cover {t1 - t0:g} s, not more than the transient ({transient:g} s)")
        return t0, math.floor(avail / dt) * dt
    if duration > avail + 1e-9:
        raise ValueError(f"the replayed inputs cover {t1 - t0:g} s from t = {t0:g} s: too short for transient "
                         f"{transient:g} s + duration {duration:g} s (at most duration={max(avail, 0):.6g})")
    return t0, duration


def measured_azimuth(azimuth: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(t, psi)`` of a measured rotor azimuth: a record with an ``Azimuth`` channel or a ``(t, deg)`` pair.

    Returns the time (s) and the azimuth unwrapped to a continuous angle (rad), OpenFAST's convention (blade 1 up
    = 0, increasing clockwise looking downwind).

    Raises
    ------
    ValueError
        No ``Azimuth`` channel, mismatched or non-finite arrays, a time axis not increasing.
    """
    if hasattr(azimuth, "channels") and hasattr(azimuth, "t"):
        if "Azimuth" not in azimuth.channels:
            raise ValueError("the record has no Azimuth channel to replay")
        t, deg = np.asarray(azimuth.t, float), np.asarray(azimuth["Azimuth"], float)
    else:
        try:
            t, deg = (np.asarray(a, dtype=float) for a in azimuth)
        except (TypeError, ValueError):
            raise ValueError("azimuth must be a record with an Azimuth channel or a (t, deg) pair") from None
    if t.ndim != 1 or t.shape != deg.shape or t.size < 2:
        raise ValueError(f"azimuth needs matching 1-D time and angle arrays of >= 2 samples, got {t.shape}, "
                         f"{deg.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(deg))):
        raise ValueError("azimuth: non-finite time or angle")
    if np.any(np.diff(t) <= 0):
        raise ValueError("azimuth: time must increase")
    return t, np.unwrap(np.deg2rad(deg))


def with_measured_azimuth(blade: np.ndarray, t: np.ndarray, t_az: np.ndarray, psi_az: np.ndarray) -> np.ndarray:
    """The stepper's blade-wind array with the measured azimuth (rad, wrapped) as an extra last column at the
    internal steps' times ``t`` (NaN outside the measurement: the stepper then integrates its own); a forcing
    without a turbulent field gets NaN blade winds (the stepper then computes no rotationally sampled loads)."""
    from .simulate import N_BLADE_COLUMNS

    psi = np.interp(t, t_az, psi_az, left=np.nan, right=np.nan) % (2.0 * np.pi)
    field = blade if blade.shape[0] == t.size else np.full((t.size, N_BLADE_COLUMNS), np.nan)
    return np.ascontiguousarray(np.concatenate([field[:, :N_BLADE_COLUMNS], psi[:, None]], axis=1),
                                dtype=np.float32)


def stepper_blade_winds(blade: np.ndarray, inplane: np.ndarray | None = None) -> np.ndarray:
    """The stepper's blade winds from measured ones: the thrust and torque's blade wind, then the in-plane
    force's (``blade`` stands in when ``inplane`` is None), each resampled periodically to
    ``N_BLADE_AZIMUTH`` uniform azimuths; shape ``(n, N_BLADE_COLUMNS)`` float32 (m/s)."""
    from .simulate import N_BLADE_AZIMUTH

    def resample(b: np.ndarray) -> np.ndarray:
        if b.shape[1] == N_BLADE_AZIMUTH:
            return np.asarray(b, dtype=np.float32)
        return blade_effective_wind(b[:, None, :], np.array([1.0]), np.arange(b.shape[1]) * 2 * np.pi
                                    / b.shape[1], N_BLADE_AZIMUTH)

    return np.concatenate([resample(blade), resample(blade if inplane is None else inplane)], axis=1)


def delayed_blade_winds(t: np.ndarray, delay: np.ndarray, t_src: np.ndarray, blade: np.ndarray) -> np.ndarray:
    """Blade-wind columns read at ``t - delay[j]`` from series sampled at ``t_src`` (linear, held at the ends):
    each azimuth of the tilted disc meets the field with its own delay (:meth:`Simulator.blade_sampling_delay`).
    Returns ``(t.size, n_columns)`` float32 (m/s)."""
    out = np.empty((t.size, blade.shape[1]), dtype=np.float32)
    for j in range(blade.shape[1]):
        out[:, j] = np.interp(t - delay[j], t_src, blade[:, j])
    return out


def replay_forcing(sim: Simulator, n_steps: int, t_start: float, waves: MeasuredWaves | None,
                   wind: MeasuredWind | None, seed_sequence: np.random.SeedSequence,
                   ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """:meth:`Simulator.forcing` with measured inputs in place of the random draws.

    Same outputs ``(u_ex, vel, psi0, blade)`` over ``n_steps + 1`` internal steps from ``t_start`` (s). An input
    given as None keeps its random draw (seeded as in :meth:`Simulator.forcing`).
    """
    from .model import INPUT_BLOCKS
    from .simulate import N_BLADE_COLUMNS, N_EX

    n = n_steps + 1
    lc = sim.case
    if waves is None or wind is None:
        u_ex, vel, psi0, blade = sim.forcing(n_steps, seed_sequence)
    else:
        u_ex = np.zeros((n, N_EX))
        u_ex[:, 0] = 1.0
        vel = np.zeros((n, sim.strip_z.size, 2))
        blade = np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
        _, _, psi_ss = seed_sequence.spawn(3)  # the rotor azimuth is drawn as in Simulator.forcing
        psi0 = float(np.random.default_rng(psi_ss).uniform(0.0, 2.0 * np.pi))
    t = t_start + np.arange(n) * sim.dt_int
    if waves is not None:
        direction = lc.wave_dir_deg if lc is not None else 0.0
        w = waves.loads(t, direction, n_strips=sim.strip_z.size)
        vel = np.ascontiguousarray(w.velocity)
        u_ex[:, INPUT_BLOCKS["wave"]] = w.excitation + sim.drag.excitation(vel)
        u_ex[:, INPUT_BLOCKS["elev"].start] = w.elevation
    if wind is not None:
        if lc is None or lc.wind_speed <= 0:
            raise ValueError("wind replay needs an operating load case (wind_speed > 0, e.g. the measured mean)")
        tw = t - advection_delay(sim, wind)  # the wind the rotor meets now passed the measurement plane at tw
        u_ex[:, INPUT_BLOCKS["wind"].start] = np.interp(tw, wind.t, wind.rotor_effective) - lc.wind_speed
        u_ex[:, INPUT_BLOCKS["hub_wind"].start] = np.interp(tw, wind.t, wind.hub)
        i_sh = INPUT_BLOCKS["shear"].start
        u_ex[:, i_sh] = np.interp(tw, wind.t, wind.shear_y) if wind.shear_y is not None else sim.mean_shear[0]
        u_ex[:, i_sh + 1] = np.interp(tw, wind.t, wind.shear_z) if wind.shear_z is not None else sim.mean_shear[1]
        if wind.blade is not None:
            delay = np.tile(sim.blade_sampling_delay(), 2)  # at the load case's wind speed (> 0: checked above)
            blade = delayed_blade_winds(tw, delay, wind.t, stepper_blade_winds(wind.blade, wind.blade_inplane))
        else:
            blade = np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
    return np.ascontiguousarray(u_ex), vel, psi0, np.ascontiguousarray(blade)


def replay_meta(waves: MeasuredWaves | None, wind: MeasuredWind | None, t_start: float,
                wind_delay_s: float | None = None) -> dict[str, Mapping[str, Any] | float | None]:
    """JSON-able description of the replayed inputs for a record's ``meta``."""
    return {
        "t_start": float(t_start),
        "waves": None if waves is None else {"source": waves.source, "dt": waves.dt, "f_min_hz": waves.f_min_hz,
                                             "f_max_hz": waves.f_max_hz, "taper_s": waves.taper_s,
                                             "direction_deg": waves.direction_deg},
        "wind": None if wind is None else {"source": wind.source, "level": wind.level,
                                           "mean_hub_speed": wind.mean_speed(), "x_ref": wind.x_ref,
                                           "advection_delay_s": wind_delay_s},
    }
