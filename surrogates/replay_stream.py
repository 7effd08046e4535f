"""Replayed forcing chunk by chunk: measured inputs read and transformed a window at a time (flat memory).

:func:`surrogates.replay.replay_forcing` turns a whole measured record into the simulator's forcing with one FFT
over the record. A replay that runs for a day beside its turbine cannot hold the record, let alone its FFT, so
:class:`ReplayForcing` produces the same forcing for a window of internal time steps at a time, reading only the
measured samples that window needs from a :class:`MeasuredSeries` (an in-memory array, or a file reader such as
:class:`fowt_env.replay_stream.NpzSeries` that reads a record chunk by chunk). The
:class:`surrogates.StreamingSimulator` asks for it one forcing chunk (600 s) at a time.

Overlapping chunks with tapered edges
-------------------------------------
The wave kinematics (elevation -> excitation and particle velocities along the spar) and the hub -> rotor-
effective wind filter are FFT filters, i.e. convolutions whose kernels decay within seconds (the wave loads) to
about a minute (the wind filter, ~ L_c / V; the 1/t tails of the 2 Hz band edge longer still). For a window
``[t_a, t_b]`` the measured series is read over ``[t_a - margin_s, t_b + margin_s]`` (clipped to the record),
the *record's* mean is removed (found once by the caller's scan, not the segment's: the elevation passes the
local mean through), the segment is mirror-extended over ``taper_s`` and faded at both ends exactly as the
whole-record transform does (:func:`surrogates.replay._extend`), zero-padded, filtered, and only
``[t_a, t_b]`` is kept. At the record's own ends the segment's treatment is the whole record's; at an interior
seam the unknown neighbour is stood in for by the real samples of the margin, so the difference from the
whole-record transform is the kernels' tails beyond ``margin_s`` (and the brick-wall band edge on a different FFT
grid). A transfer function whose value at f = 0 differs from its limit (the strip velocities: 0 at DC,
``sqrt(g / h)`` just above on finite depth) leaves a constant over the whole transform that depends on its FFT
length; :func:`whole_record_dc` computes the whole record's from its ends, and each window carries that one
instead of its own (without it the deepest strips were off by 13-29 % of their std). Measured
(``benchmarks/replay_env.py --seams``: JONSWAP Hs 5 m, Tp 10 s and Kaimal 12 m/s sampled at 20 Hz, 2 h, 600 s
windows, margins 120 s for the waves and 480 s for the hub wind): the largest deviation over the record, as a
fraction of each series' std, is 2.8e-7 for the wave loads (excitation and the drag's), 1.1e-8 for the
rotor-effective wind, and 1.7e-4 for the elevation and 1.1e-4 for the strip velocities, whose 2 Hz band edge rings
longest (a brick wall's 1/t tails: the near-surface strips see it most). :data:`SEAM_TOLERANCE` states the bound.

The pointwise wind levels (rotor-effective series, polar field: disc mean, gradients and blade winds per time
sample) need no margin and are exact chunk by chunk.

Examples
--------
>>> import numpy as np, surrogates
>>> from surrogates.replay_stream import ArraySeries, ReplayForcing, StreamedWaves, StreamedWind
>>> t = np.arange(0.0, 400.0, 0.05)
>>> data = np.column_stack([np.sin(2 * np.pi * 0.1 * t), 11.0 + np.sin(2 * np.pi * 0.01 * t)])
>>> series = ArraySeries(0.0, 0.05, data)
>>> sim = surrogates.Simulator(surrogates.FOWTModel(), 7)
>>> forcing = ReplayForcing(sim, StreamedWaves(series, column=0), StreamedWind(series, "hub", hub_column=1))
>>> u_ex, vel, blade = forcing(0, 800)
>>> u_ex.shape[0], vel.shape[1:]
(801, (24, 2))
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft

from .aero import inplane_ring_weights
from .model import INPUT_BLOCKS
from .oc3 import WATER_DEPTH
from .replay import (
    _PAD_SECONDS,
    DEFAULT_TAPER_S,
    MIN_RECORD_SECONDS,
    _profile_disc_mean,
    advection_delay,
    blade_effective_wind,
    delayed_blade_winds,
    stepper_blade_winds,
)
from .simulate import N_BLADE_AZIMUTH, N_BLADE_COLUMNS, N_EX, Simulator
from .validation import check_number
from .waves import SparGeometry, _loads_from_transfer_series, _wave_transfer_rows
from .wind import rotor_averaging, rotor_plane_fit

__all__ = ["DEFAULT_MARGIN_S", "DEFAULT_WIND_MARGIN_S", "SEAM_TOLERANCE", "ArraySeries", "MeasuredSeries",
           "ReplayForcing", "StreamedWaves", "StreamedWind", "whole_record_dc"]

DEFAULT_MARGIN_S = 120.0
"""Measured samples read beyond each side of a window before the wave FFT (s)."""
DEFAULT_WIND_MARGIN_S = 480.0
"""The same for the hub -> rotor-effective wind filter, whose kernel decays over ~ L_c / V (s)."""
SEAM_TOLERANCE = 3e-4
"""Bound on the chunked transform's deviation from the whole-record one with the default margins, as a fraction of
each forcing series' standard deviation (elevation and strip velocities; the wave loads and the rotor-effective
wind are three or more decades below it, see the module docstring). The tests hold it."""


@runtime_checkable
class MeasuredSeries(Protocol):
    """Measured samples on a regular time grid ``t0 + i dt``, read a block of rows at a time.

    Attributes
    ----------
    t0 : float
        Time of the first sample (s).
    dt : float
        Sample time (s).
    n_samples : int
        Number of samples.
    """

    t0: float
    dt: float
    n_samples: int

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Rows ``i0 <= i < i1`` as float64, shape ``(i1 - i0, n_columns)``."""
        ...


class ArraySeries:
    """A :class:`MeasuredSeries` over an array in memory (or a ``numpy.memmap``).

    Parameters
    ----------
    t0 : float
        Time of the first row (s).
    dt : float
        Sample time (s), > 0.
    data : array_like (n,) or (n, n_columns)
        Samples, time-major.
    """

    def __init__(self, t0: float, dt: float, data: np.ndarray) -> None:
        self.t0 = check_number("t0", t0)
        self.dt = check_number("dt", dt, positive=True)
        a = np.asarray(data)
        self._data = a[:, None] if a.ndim == 1 else a.reshape(a.shape[0], -1)
        self.n_samples = int(self._data.shape[0])

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Rows ``i0 <= i < i1`` as float64 ``(i1 - i0, n_columns)``."""
        return np.asarray(self._data[i0:i1], dtype=float)


@dataclass(frozen=True)
class StreamedWaves:
    """A measured wave elevation column of a :class:`MeasuredSeries` (see :class:`surrogates.replay.MeasuredWaves`).

    Parameters
    ----------
    series : MeasuredSeries
    column : int
        Column of the elevation (m) at the spar axis.
    mean : float or None
        The whole record's mean elevation (m), removed before the transform (a linear sea has none); None: found
        by one pass over the series.
    direction_deg : float or None
        Propagation direction (deg); None: the load case's.
    f_min_hz, f_max_hz : float
        Band replayed (Hz); default 0 and the lower of 2 Hz and the Nyquist frequency.
    taper_s : float
        Faded mirror extension at a segment's ends (s).
    margin_s : float
        Samples read beyond each side of a window (s).
    ends : (ndarray, ndarray), optional
        The column's first and last ``round(taper_s / dt) + 1`` samples (for :func:`whole_record_dc`); None: read
        from the series.
    """

    series: MeasuredSeries
    column: int = 0
    mean: float | None = None
    direction_deg: float | None = None
    f_min_hz: float = 0.0
    f_max_hz: float | None = None
    taper_s: float = DEFAULT_TAPER_S
    margin_s: float = DEFAULT_MARGIN_S
    ends: tuple[np.ndarray, np.ndarray] | None = None


@dataclass(frozen=True)
class StreamedWind:
    """Measured wind columns of a :class:`MeasuredSeries` (levels as :class:`surrogates.replay.MeasuredWind`).

    Parameters
    ----------
    series : MeasuredSeries
    level : {"hub", "rotor_effective", "field", "given"}
        ``"hub"``: ``hub_column`` through the rotor-averaging filter (chunked with ``margin_s``);
        ``"rotor_effective"``: ``effective_column`` (and ``hub_column`` for the ``Wind1VelX`` channel);
        ``"field"``: ``hub_column`` and the polar field in ``field_columns`` (``len(radii) * len(azimuth_rad)``
        columns, ring by ring); ``"given"``: everything precomputed in ``hub_column``, ``effective_column``,
        ``shear_columns`` (2, or None) and ``field_columns`` (the blade winds at uniform azimuths, or None),
        ``inplane_columns`` (the in-plane force's blade winds, same azimuths; None: the blade winds stand in).
    hub_column, effective_column : int
    field_columns, inplane_columns : slice, optional
    shear_columns : slice, optional
    radii, azimuth_rad : ndarray, optional
        The polar grid (m, rad) of a ``"field"``.
    mean : float or None
        The whole record's mean hub wind (m/s): level ``"hub"`` filters the departures from it with ``G(f)`` at
        this speed. None: found by one pass over the series (level ``"hub"`` only).
    shear_exponent : float
        Power-law profile of the disc mean for level ``"hub"`` (-).
    radius, hub_height : float
        Rotor radius and hub height (m).
    taper_s, margin_s, ends
        As :class:`StreamedWaves` (s; the hub column's ends).
    x_ref : float or None
        Plane where the wind was measured (m downwind; as :class:`surrogates.replay.MeasuredWind`): default 0, a
        fixed point at the platform's undisplaced axis (OpenFAST's ``Wind1VelX``); None: at the rotor.
    """

    series: MeasuredSeries
    level: str = "hub"
    hub_column: int = 0
    effective_column: int = 0
    field_columns: slice | None = None
    shear_columns: slice | None = None
    inplane_columns: slice | None = None
    radii: np.ndarray | None = None
    azimuth_rad: np.ndarray | None = None
    mean: float | None = None
    shear_exponent: float = 0.2
    radius: float = 63.0
    hub_height: float = 90.0
    taper_s: float = DEFAULT_TAPER_S
    margin_s: float = DEFAULT_WIND_MARGIN_S
    ends: tuple[np.ndarray, np.ndarray] | None = None
    x_ref: float | None = 0.0

    def __post_init__(self) -> None:
        if self.level not in ("hub", "rotor_effective", "field", "given"):
            raise ValueError(f"wind: level must be 'hub', 'rotor_effective', 'field' or 'given', got {self.level!r}")
        if self.level == "field" and (self.field_columns is None or self.radii is None or self.azimuth_rad is None):
            raise ValueError("wind: level 'field' needs field_columns, radii and azimuth_rad")


_F_LIMIT_HZ = 1e-9  # where a transfer function's limit at f -> 0+ is read


def _n_fft(n: int, m: int, dt: float) -> int:
    """FFT length of :func:`surrogates.replay._fft_filter` for ``n`` samples extended by ``m`` at each end."""
    return next_fast_len(n + 2 * m + max(n // 4, int(math.ceil(_PAD_SECONDS / dt))), real=True)


def _taper_samples(n: int, dt: float, taper_s: float) -> int:
    return min(int(round(taper_s / dt)), n - 1)


def _extend_about(x: np.ndarray, mean: float, m: int) -> np.ndarray:
    """``x - mean`` with its faded even mirror image over ``m`` samples at both ends (as
    :func:`surrogates.replay._extend`, about a given mean)."""
    xm = x - mean
    if m <= 0:
        return xm
    n = x.size
    ramp = 0.5 * (1.0 - np.cos(np.pi * (np.arange(m) + 0.5) / m))
    return np.concatenate([xm[1:m + 1][::-1] * ramp, xm, xm[n - m - 1:n - 1][::-1] * ramp[::-1]])


def whole_record_dc(head: np.ndarray, tail: np.ndarray, mean: float, n: int, dt: float,
                    taper_s: float = DEFAULT_TAPER_S) -> float:
    """The zero-frequency bin of the whole record's extended series over its FFT length (the series' unit).

    A transfer function whose value at f = 0 differs from its limit at f -> 0+ (the strip velocities: 0 at DC,
    ``sqrt(g / h)`` in the limit, on finite depth) leaves a constant ``(H(0) - H(0+)) * dc`` over the whole
    transform. The chunked transform reproduces it from this number, computed from the record's first and last
    ``taper_s / dt + 1`` samples (``head``, ``tail``), its mean and length alone.
    """
    m = _taper_samples(n, dt, taper_s)
    if m <= 0:
        return 0.0
    ramp = 0.5 * (1.0 - np.cos(np.pi * (np.arange(m) + 0.5) / m))
    h = np.asarray(head, dtype=float)[1:m + 1] - mean
    t = np.asarray(tail, dtype=float)[-m - 1:-1] - mean
    return float((h[::-1] @ ramp + t[::-1] @ ramp[::-1]) / _n_fft(n, m, dt))


def _column_pass(series: MeasuredSeries, column: int, m: int, block: int = 1 << 16
                 ) -> tuple[float, np.ndarray, np.ndarray]:
    """Mean of one column over the whole series, and its first and last ``m + 1`` samples, in blocks of rows."""
    n = series.n_samples
    total = 0.0
    head = np.empty(0)
    tail = np.empty(0)
    for i0 in range(0, n, block):
        col = series.read(i0, min(n, i0 + block))[:, column]
        total += float(np.sum(col))
        if i0 == 0:
            head = col[: m + 1].copy()
        tail = np.concatenate([tail, col])[-(m + 1):]
    return total / n, head, tail


def _segment_filter(x: np.ndarray, mean: float, dt: float, taper_s: float, transfer, up: int,
                    band: tuple[float, float] | None, cache: dict, dc_ref: float, n_min: int = 0) -> np.ndarray:
    """:func:`surrogates.replay._fft_filter` on one segment, about the record's ``mean`` (not the segment's).

    Returns ``(n * up, n_out)`` on the grid ``dt / up`` from the segment's first sample. ``transfer(f)`` is
    evaluated once per FFT length (``cache``). ``dc_ref`` (:func:`whole_record_dc`) replaces the segment's
    zero-frequency artefact by the whole record's. The FFT is at least as long as for ``n_min`` samples, so that
    the windows of one chunk size, clipped or not, share one FFT length (and one evaluation of ``transfer``)."""
    n = x.size
    m = _taper_samples(n, dt, taper_s)
    ext = _extend_about(x, mean, max(m, 0))
    m = max(m, 0)
    n_fft = _n_fft(max(n, n_min), m, dt)
    key = (n_fft, up)
    if key not in cache:
        f = np.fft.rfftfreq(n_fft, dt)
        keep = f < 0.5 / dt
        if band is not None:
            keep &= (f >= band[0]) & (f <= band[1])
        idx = np.flatnonzero(keep)
        rows = np.atleast_2d(transfer(f[idx]))
        h0 = rows[:, 0].real if idx.size and idx[0] == 0 else np.zeros(rows.shape[0])
        jump = h0 - np.atleast_2d(transfer(np.array([_F_LIMIT_HZ])))[:, 0].real  # H(0) - H(0+)
        if len(cache) >= 4:
            cache.clear()
        cache[key] = (idx, rows, jump)
    idx, rows, jump = cache[key]
    spec = rfft(ext, n=n_fft)
    n_used = int(idx[-1]) + 1 if idx.size else 1
    full = np.zeros((rows.shape[0], n_used), dtype=complex)
    full[:, idx] = rows * spec[idx]
    out = irfft(full, n=n_fft * up, axis=-1) * up
    out = out[:, m * up: (m + n) * up].T
    return np.ascontiguousarray(out + jump * (dc_ref - float(spec[0].real) / n_fft))


class ReplayForcing:
    """The simulator's replayed forcing over any window of internal steps, read and transformed chunk by chunk.

    Produces what :func:`surrogates.replay.replay_forcing` produces for the whole record (``u_ex``, strip
    velocities, blade winds) on the internal grid ``t_start + k dt_int``, for ``k0 <= k <= k0 + n_steps``; the
    :class:`surrogates.StreamingSimulator` calls it as its ``forcing``. Windows past the end of the inputs are
    padded with the last available sample; :attr:`steps_available` says how far the inputs reach.

    Parameters
    ----------
    sim : Simulator
        Its load case must be an operating one (wind speed > 0, the linearisation point; use the measured mean).
    waves : StreamedWaves
    wind : StreamedWind
    t_start : float
        Time (s, on the inputs' own axis) of internal step 0; default the later of the two series' starts.

    Raises
    ------
    ValueError
        If the inputs do not overlap over at least :data:`surrogates.replay.MIN_RECORD_SECONDS` after ``t_start``
        or the load case is not an operating one.
    """

    def __init__(self, sim: Simulator, waves: StreamedWaves, wind: StreamedWind, t_start: float | None = None) -> None:
        lc = sim.case
        if lc is None or lc.wind_speed <= 0:
            raise ValueError("wind replay needs an operating load case (wind_speed > 0, e.g. the measured mean)")
        self.sim = sim
        self.waves = waves
        self.wind = wind
        self._cache_waves: dict = {}
        self._cache_wind: dict = {}
        w = waves.series
        v = wind.series
        self.t_begin = max(w.t0, v.t0)
        self.t_end = min(w.t0 + (w.n_samples - 1) * w.dt, v.t0 + (v.n_samples - 1) * v.dt)
        if self.t_end - self.t_begin < MIN_RECORD_SECONDS:
            raise ValueError(f"the replayed inputs overlap over {max(self.t_end - self.t_begin, 0.0):g} s only (waves "
                             f"and wind time axes must share at least {MIN_RECORD_SECONDS:g} s)")
        self.f_max_hz = min(2.0, 0.5 / w.dt) if waves.f_max_hz is None else check_number(
            "f_max_hz", waves.f_max_hz, positive=True)
        self.wave_mean, self.wave_dc = self._reference(w, waves.column, waves.mean, waves.taper_s, waves.ends)
        self.wind_mean, self.wind_dc = lc.wind_speed, 0.0
        if wind.level == "hub":
            self.wind_mean, self.wind_dc = self._reference(v, wind.hub_column, wind.mean, wind.taper_s, wind.ends)
            if self.wind_mean <= 0:
                raise ValueError(f"wind: the mean hub wind must be > 0 m/s, got {self.wind_mean:g}")
        # Taylor advection from the wind's plane to the rotor (as surrogates.replay.replay_forcing)
        self.wind_delay = advection_delay(sim, x_ref=wind.x_ref)
        # and from the rotor centre to each azimuth of the tilted disc (Simulator.blade_sampling_delay)
        self.blade_delay = np.tile(sim.blade_sampling_delay(), 2)  # thrust/torque, then in-plane blade winds
        self.inplane_weights = None
        if wind.level == "field" and wind.radii is not None:  # the in-plane force's ring weights at the mean hub
            hub_mean = wind.mean if wind.mean is not None else _column_pass(v, wind.hub_column, 0)[0]
            self.inplane_weights = inplane_ring_weights(wind.radii, max(float(hub_mean), 0.1))[0]
        geo = SparGeometry()
        z, _, _ = geo.strips(sim.strip_z.size)
        self._transfer_z = z
        self._geo = geo
        self.start(self.t_begin if t_start is None else t_start)

    @staticmethod
    def _reference(series: MeasuredSeries, column: int, mean: float | None, taper_s: float,
                   ends: tuple[np.ndarray, np.ndarray] | None) -> tuple[float, float]:
        """The record's mean and :func:`whole_record_dc` of one filtered column (one pass if not given)."""
        n = series.n_samples
        m = max(_taper_samples(n, series.dt, taper_s), 0)
        if mean is None or ends is None:
            mu, head, tail = _column_pass(series, column, m)
            mean = mu if mean is None else mean
            ends = (head, tail) if ends is None else ends
        mean = check_number("mean", mean)
        return mean, whole_record_dc(ends[0], ends[1], mean, n, series.dt, taper_s)

    def start(self, t_start: float) -> None:
        """Set internal step 0 at ``t_start`` (s, the inputs' axis); check that the inputs reach on from it."""
        t0 = check_number("t_start", t_start)
        if t0 < self.t_begin - 1e-9 or self.t_end - t0 < MIN_RECORD_SECONDS:
            raise ValueError(f"replay start {t0:g} s: the inputs cover {self.t_begin:g}-{self.t_end:g} s; a replay "
                             f"needs at least {MIN_RECORD_SECONDS:g} s of them from its start")
        self.t_start = t0
        # the last internal step whose time lies inside both series (the hold sample included)
        self.steps_available = int(math.floor((self.t_end - t0) / self.sim.dt_int + 1e-9))

    # ----------------------------------------------------------------------------------------- windows
    @staticmethod
    def _rows(series: MeasuredSeries, t_a: float, t_b: float, margin_s: float) -> tuple[int, int]:
        """Row range of ``series`` covering ``[t_a - margin, t_b + margin]`` (clipped to the series)."""
        m = int(math.ceil(margin_s / series.dt))
        i_a = int(math.floor((t_a - series.t0) / series.dt + 1e-9)) - m
        i_b = int(math.ceil((t_b - series.t0) / series.dt - 1e-9)) + 1 + m
        return max(0, i_a), min(series.n_samples, i_b)

    @staticmethod
    def _window_rows(series: MeasuredSeries, n_steps: int, dt_int: float, margin_s: float) -> int:
        """Rows of an unclipped window of ``n_steps`` internal steps (the FFT length of every window)."""
        return int(math.ceil(n_steps * dt_int / series.dt)) + 3 + 2 * int(math.ceil(margin_s / series.dt))

    def _wave_series(self, t: np.ndarray, block: np.ndarray, s0: int, n_min: int) -> np.ndarray:
        """Elevation, the three along-wave loads and the strip velocities at ``t`` from rows ``s0...`` of the
        elevation (``(len(t), 4 + n_strips)``)."""
        wv = self.waves
        dt = wv.series.dt
        up = max(1, int(math.ceil(dt / self.sim.dt_int - 1e-9)))
        z, geo = self._transfer_z, self._geo

        def transfer(f: np.ndarray) -> np.ndarray:
            return _wave_transfer_rows(f, WATER_DEPTH, geo, z)

        fine = _segment_filter(block, self.wave_mean, dt, wv.taper_s, transfer, up, (wv.f_min_hz, self.f_max_hz),
                               self._cache_waves, self.wave_dc, n_min)
        t_fine = wv.series.t0 + np.arange(s0 * up, s0 * up + fine.shape[0]) * (dt / up)
        out = np.empty((t.size, fine.shape[1]))
        for j in range(fine.shape[1]):
            out[:, j] = np.interp(t, t_fine, fine[:, j])
        return out

    def _wind_series(self, t: np.ndarray, block: np.ndarray, s0: int, n_min: int) -> tuple[np.ndarray, ...]:
        """Hub wind, rotor-effective wind, shear (y, z, or None) and blade winds (or None) at ``t``."""
        wd = self.wind
        dt = wd.series.dt
        t_rows = wd.series.t0 + np.arange(s0, s0 + block.shape[0]) * dt
        hub = block[:, wd.hub_column]
        shear_y = shear_z = blade = inplane = None
        if wd.level == "hub":
            v = self.wind_mean

            def transfer(f: np.ndarray) -> np.ndarray:
                return rotor_averaging(f, v, wd.radius, wd.hub_height)[1][None, :].astype(complex)

            eff = _segment_filter(hub, v, dt, wd.taper_s, transfer, 1, None, self._cache_wind, self.wind_dc,
                                  n_min)[:, 0]
            eff = eff + v * _profile_disc_mean(wd.shear_exponent, wd.hub_height, wd.radius)
        elif wd.level == "rotor_effective":
            eff = block[:, wd.effective_column]
        elif wd.level == "field":
            assert wd.field_columns is not None and wd.radii is not None and wd.azimuth_rad is not None
            polar = block[:, wd.field_columns].reshape(block.shape[0], len(wd.radii), len(wd.azimuth_rad))
            eff, shear_y, shear_z = rotor_plane_fit(polar, wd.radii, wd.azimuth_rad,
                                                    radius=max(wd.radius, float(np.max(wd.radii))))
            blade = blade_effective_wind(polar, wd.radii, wd.azimuth_rad, N_BLADE_AZIMUTH)
            inplane = blade_effective_wind(polar, wd.radii, wd.azimuth_rad, N_BLADE_AZIMUTH,
                                           weights=self.inplane_weights)
        else:
            eff = block[:, wd.effective_column]
            if wd.shear_columns is not None:
                shear_y, shear_z = block[:, wd.shear_columns].T
            if wd.field_columns is not None:
                blade = block[:, wd.field_columns].astype(np.float32)
                if wd.inplane_columns is not None:
                    inplane = block[:, wd.inplane_columns].astype(np.float32)
        inter = [np.interp(t, t_rows, hub), np.interp(t, t_rows, eff)]
        inter += [None, None] if shear_y is None else [np.interp(t, t_rows, shear_y), np.interp(t, t_rows, shear_z)]
        if blade is not None:
            inter.append(delayed_blade_winds(t, self.blade_delay, t_rows, stepper_blade_winds(blade, inplane)))
        else:
            inter.append(None)
        return tuple(inter)

    def __call__(self, k0: int, n_steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Forcing at internal steps ``k0 ... k0 + n_steps`` (``n_steps + 1`` samples).

        Returns
        -------
        u_ex : ndarray (n_steps + 1, N_EX)
        vel : ndarray (n_steps + 1, n_strips, 2)
            Wave particle velocities at the drag strips (m/s).
        blade : ndarray (n_steps + 1, N_BLADE_COLUMNS) float32, or (0, N_BLADE_COLUMNS) without a field
            Blade-effective winds (m/s): thrust and torque's, then the in-plane force's.
        """
        sim, lc = self.sim, self.sim.case
        assert lc is not None
        n = n_steps + 1
        k_last = min(k0 + n_steps, self.steps_available)
        n_in = max(0, k_last - k0 + 1)
        if n_in == 0:
            raise ValueError(f"internal step {k0} lies beyond the replayed inputs ({self.steps_available} steps)")
        t = self.t_start + np.arange(k0, k0 + n_in) * sim.dt_int
        # one read per distinct series for both uses (a record often carries waves and wind)
        wv, wd = self.waves, self.wind
        ra = self._rows(wv.series, float(t[0]), float(t[-1]), wv.margin_s)
        # pointwise levels need no margin, but the blade winds are read up to the tilted disc's sampling delays
        margin_wind = wd.margin_s if wd.level == "hub" else float(np.max(np.abs(self.blade_delay))) + wd.series.dt
        tw = t - self.wind_delay  # the wind the rotor meets now passed the measurement plane at tw
        rb = self._rows(wd.series, float(tw[0]), float(tw[-1]), margin_wind)
        if wv.series is wd.series:
            lo, hi = min(ra[0], rb[0]), max(ra[1], rb[1])
            both = wv.series.read(lo, hi)
            block_w, block_v = both[ra[0] - lo: ra[1] - lo], both[rb[0] - lo: rb[1] - lo]
        else:
            block_w, block_v = wv.series.read(*ra), wd.series.read(*rb)
        series = self._wave_series(t, np.ascontiguousarray(block_w[:, wv.column]), ra[0],
                                   self._window_rows(wv.series, n_steps, sim.dt_int, wv.margin_s))
        beta = np.deg2rad(wv.direction_deg if wv.direction_deg is not None else lc.wave_dir_deg)
        u_ex = np.zeros((n, N_EX))
        u_ex[:, 0] = 1.0
        excitation, vel_in = _loads_from_transfer_series(series, beta)
        vel = np.empty((n, sim.strip_z.size, 2))
        vel[:n_in] = vel_in
        u_ex[:n_in, INPUT_BLOCKS["wave"]] = excitation + sim.drag.excitation(vel[:n_in])
        u_ex[:n_in, INPUT_BLOCKS["elev"].start] = series[:, 0]
        hub, eff, shy, shz, blade_in = self._wind_series(
            tw, block_v, rb[0], self._window_rows(wd.series, n_steps, sim.dt_int, margin_wind))
        u_ex[:n_in, INPUT_BLOCKS["wind"].start] = eff - lc.wind_speed
        u_ex[:n_in, INPUT_BLOCKS["hub_wind"].start] = hub
        i_sh = INPUT_BLOCKS["shear"].start
        u_ex[:n_in, i_sh] = shy if shy is not None else sim.mean_shear[0]
        u_ex[:n_in, i_sh + 1] = shz if shz is not None else sim.mean_shear[1]
        if blade_in is not None:
            blade = np.empty((n, N_BLADE_COLUMNS), dtype=np.float32)
            blade[:n_in] = blade_in
        else:
            blade = np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
        if n_in < n:  # beyond the inputs: hold the last sample (never stepped into: see steps_available)
            u_ex[n_in:] = u_ex[n_in - 1]
            vel[n_in:] = vel[n_in - 1]
            if blade.shape[0]:
                blade[n_in:] = blade[n_in - 1]
        return np.ascontiguousarray(u_ex), vel, np.ascontiguousarray(blade)
