"""Measured inputs for replayed episodes (``SparEnv(replay=...)``), read from files chunk by chunk.

:class:`ReplaySource` gathers what an episode that replays measured conditions needs: the wave elevation
(``Wave1Elev``, m) and the wind (the record's ``Wind1VelX`` as a hub-height series, or a richer wind beside it),
the load case (a ``<run>.case.json`` beside the record, else estimated as :func:`fowt_env.replay.record_case`
does), and the inputs' time span. :meth:`ReplaySource.forcing` gives the simulator a
:class:`surrogates.replay_stream.ReplayForcing` that turns the inputs into forcing a window at a time.

Flat memory. A record given as a ``.npz`` file (:meth:`surrogates.Record.save`; compressed or not) is never
loaded whole: :class:`NpzSeries` reads the rows of its ``y`` member (and an ``*.inflow.npz`` beside it: ``hub_uvw``
and the polar field ``polar_u``) forward in blocks through the zip stream and keeps only the window the current
forcing chunk needs. At construction one pass over the file checks the time axis (finite, increasing, regular to
1e-3 of its step), the two channels (finite) and computes the mean wind, the sea state (4 std and the Welch peak
period of the elevation, as :func:`surrogates.replay.sea_state`) and the record's mean elevation and end
samples (the chunked wave transform's references). Other record formats (``.outb``, ``.out``, ``.csv``,
``.parquet``) and in-memory :class:`surrogates.Record` objects are read whole by their readers; only the two
channels are kept. A TurbSim ``.bts`` wind is read whole too (:func:`fowt_env.turbsim.measured_wind_from_bts`).

Each :meth:`ReplaySource.forcing` window reads forward; a new episode (``reset``) reopens the zip stream and
decompresses up to its start, so a ``replay_start`` deep into a long compressed file costs a sequential read
of the file up to it.

Examples
--------
>>> import numpy as np, surrogates
>>> t = np.arange(0.0, 300.0, 0.05)
>>> rec = surrogates.Record(t, np.column_stack([np.sin(2 * np.pi * 0.1 * t), 11.0 + 0 * t]),
...                         ["Wave1Elev", "Wind1VelX"], ["m", "m/s"])
>>> src = ReplaySource(rec)
>>> src.t_begin, round(src.t_end, 9), round(src.case.wind_speed, 1)
(0.0, 299.95, 11.0)
"""

from __future__ import annotations

import json
import math
import os
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

import numpy as np
from scipy.signal import get_window

from surrogates.replay import MIN_RECORD_SECONDS, MeasuredWind, record_wind_plane
from surrogates.replay_stream import ArraySeries, ReplayForcing, StreamedWaves, StreamedWind

__all__ = ["NpzSeries", "ReplaySource"]

_BLOCK_ROWS = 1 << 16  # rows per read of the scan
_STEP_TOLERANCE = 1e-3  # as surrogates.replay: relative deviation of a step accepted as a regular grid
_WELCH_S = 200.0  # surrogates.replay.sea_state's Welch segment (s)


# ------------------------------------------------------------------------------------------------ readers
class _Rows:
    """Rows of one ``.npy`` array (an ``.npz`` member), read forward through the zip stream.

    Reading rows before the current position reopens the member (a compressed member cannot seek back)."""

    def __init__(self, path: Path, member: str) -> None:
        self.path, self.member = path, member
        self._fh: IO[bytes] | None = None
        self._zip: zipfile.ZipFile | None = None
        self._open()
        assert self._fh is not None
        self._fh.close()
        self._fh = None

    def _open(self) -> None:
        self.close()
        self._zip = zipfile.ZipFile(self.path)
        name = self.member if self.member.endswith(".npy") else self.member + ".npy"
        if name not in self._zip.namelist():
            raise ValueError(f"{self.path}: no member {self.member!r} (members: "
                             f"{sorted(n[:-4] for n in self._zip.namelist())})")
        fh = self._zip.open(name)
        version = np.lib.format.read_magic(fh)
        shape, fortran, dtype = (np.lib.format.read_array_header_1_0(fh) if version == (1, 0)
                                 else np.lib.format.read_array_header_2_0(fh))
        if dtype.hasobject or dtype.kind not in "fiu" or (fortran and len(shape) > 1) or not shape:
            raise ValueError(f"{self.path}: member {self.member!r} is not a C-ordered numeric array "
                             f"(dtype {dtype}, shape {shape})")
        self.shape, self.dtype = tuple(int(s) for s in shape), dtype
        self.row_bytes = int(np.prod(self.shape[1:], dtype=np.int64)) * dtype.itemsize
        self._fh, self._pos = fh, 0

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Rows ``i0 <= i < i1`` in the file's dtype, shape ``(i1 - i0, *shape[1:])``."""
        if self._fh is None or i0 < self._pos:
            self._open()
        assert self._fh is not None
        skip = (i0 - self._pos) * self.row_bytes
        while skip > 0:  # forward: decompress and drop, in bounded pieces
            got = len(self._fh.read(min(skip, 1 << 24)))
            if got == 0:
                raise ValueError(f"{self.path}: member {self.member!r} ends early")
            skip -= got
        want = (i1 - i0) * self.row_bytes
        buf = self._fh.read(want)
        if len(buf) != want:
            raise ValueError(f"{self.path}: member {self.member!r} ends early (truncated file?)")
        self._pos = i1
        return np.frombuffer(buf, dtype=self.dtype).reshape((i1 - i0,) + self.shape[1:])

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if self._zip is not None:
            self._zip.close()
            self._zip = None


class NpzSeries:
    """A :class:`surrogates.replay_stream.MeasuredSeries` over columns of ``.npz`` members, read in windows.

    Parameters
    ----------
    path : path-like
        The ``.npz`` file.
    members : list of (str, list of int or None)
        Members (rows along their first axis, all of the same length) and the columns (of each row flattened)
        to take; None takes every column.
    t0, dt : float
        The regular time axis (s), checked by the caller's scan.

    Notes
    -----
    Reads are expected to move forward (each window starts at or after the previous one's start); the rows of
    the current window are kept so that overlapping windows read each byte of the file once.
    """

    def __init__(self, path: str | os.PathLike[str], members: list[tuple[str, list[int] | None]], t0: float,
                 dt: float) -> None:
        self.path = Path(path)
        self._readers = [(_Rows(self.path, name), cols) for name, cols in members]
        lengths = {r.shape[0] for r, _ in self._readers}
        if len(lengths) != 1:
            raise ValueError(f"{self.path}: members {[m for m, _ in members]} differ in length {sorted(lengths)}")
        self.n_samples = lengths.pop()
        self.t0, self.dt = float(t0), float(dt)
        self._b0, self._buf = 0, np.empty((0, 0))

    def _raw(self, i0: int, i1: int) -> np.ndarray:
        parts = []
        for reader, cols in self._readers:
            rows = reader.read(i0, i1).reshape(i1 - i0, -1)
            parts.append(np.asarray(rows if cols is None else rows[:, cols], dtype=float))
        return np.hstack(parts)

    def read(self, i0: int, i1: int) -> np.ndarray:
        """Rows ``i0 <= i < i1`` as float64 ``(i1 - i0, n_columns)``."""
        i0, i1 = max(0, int(i0)), min(self.n_samples, int(i1))
        b1 = self._b0 + self._buf.shape[0]
        if not (self._buf.size and self._b0 <= i0 <= b1):
            self._b0, self._buf = i0, self._raw(i0, i1)
        elif i1 > b1:
            self._buf = np.vstack([self._buf[i0 - self._b0:], self._raw(b1, i1)])
            self._b0 = i0
        else:
            self._buf, self._b0 = self._buf[i0 - self._b0:], i0
        return self._buf[: i1 - i0].copy()

    def restart(self) -> None:
        """Drop the kept window (a new episode starts from its own start)."""
        self._b0, self._buf = 0, np.empty((0, 0))

    def close(self) -> None:
        for reader, _ in self._readers:
            reader.close()


# ------------------------------------------------------------------------------------------------ the scan
class _Scan:
    """One pass over a record's time axis and channels: checks and the statistics a replay needs."""

    def __init__(self, name: str, dt_hint: float, m_wave: int, m_wind: int) -> None:
        self.name = name
        self.n = 0
        self.t0 = self.t_last = math.nan
        self.step = dt_hint
        self.sums = np.zeros(2)
        self.sq = 0.0
        self.m = (m_wave, m_wind)
        self.heads: list[np.ndarray] = [np.empty(0), np.empty(0)]
        self.tails: list[np.ndarray] = [np.empty(0), np.empty(0)]
        self._seg: np.ndarray = np.empty(0)
        self._psd: np.ndarray | None = None
        self._n_seg = 0

    def block(self, t: np.ndarray, x: np.ndarray) -> None:
        if not np.all(np.isfinite(t)):
            raise ValueError(f"{self.name}: the time axis holds NaN or inf")
        if self.n == 0:
            self.t0 = float(t[0])
            steps0 = np.diff(t)
            if steps0.size:
                self.step = float(np.median(steps0))
        full_t = t if self.n == 0 else np.concatenate([[self.t_last], t])
        steps = np.diff(full_t)
        if self.step <= 0 or np.any(steps <= 0):
            raise ValueError(f"{self.name}: the time axis must be strictly increasing")
        dev = np.abs(steps - self.step)
        if np.any(dev > _STEP_TOLERANCE * self.step):
            i = int(np.argmax(dev))
            raise ValueError(f"{self.name}: the time axis is not regular (step {steps[i]:g} s at t = {full_t[i]:g} s, "
                             f"expected {self.step:g} s); resample it onto a regular grid first")
        bad = ~np.isfinite(x).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            col = ("Wave1Elev", "Wind1VelX")[int(np.flatnonzero(~np.isfinite(x[i]))[0])]
            raise ValueError(f"{self.name}: {col} has a non-finite sample (NaN/inf) at t = {t[i]:g} s; fill or cut "
                             "the gaps before replaying (replay needs a gap-free series)")
        self.t_last = float(t[-1])
        self.sums += x.sum(axis=0)
        self.sq += float(x[:, 0] @ x[:, 0])
        for j in range(2):
            if self.n < self.m[j] + 1:
                self.heads[j] = np.concatenate([self.heads[j], x[: self.m[j] + 1 - self.n, j]])
            self.tails[j] = np.concatenate([self.tails[j], x[:, j]])[-(self.m[j] + 1):]
        self.n += t.size
        self._welch(x[:, 0])

    @property
    def mean_step(self) -> float:
        """The grid's step (s) from its first and last time stamps (so that the grid ends where the record does)."""
        return (self.t_last - self.t0) / (self.n - 1)

    def _welch(self, x: np.ndarray) -> None:
        """Welch periodogram of the elevation as scipy.signal.welch (Hann, 50 %, constant detrend), streamed."""
        nper = int(round(_WELCH_S / self.step))
        self._seg = np.concatenate([self._seg, x])
        win = get_window("hann", nper)
        step = nper - nper // 2
        while self._seg.size >= nper:
            s = self._seg[:nper]
            p = np.abs(np.fft.rfft((s - s.mean()) * win)) ** 2
            self._psd = p if self._psd is None else self._psd + p
            self._n_seg += 1
            self._seg = self._seg[step:]

    def sea_state(self, elevation_head: np.ndarray | None = None) -> tuple[float, float]:
        """Hs = 4 std (m) and Tp (s) of the Welch peak above 0.02 Hz."""
        mean = self.sums[0] / self.n
        hs = 4.0 * math.sqrt(max(self.sq / self.n - mean * mean, 0.0))
        nper = int(round(_WELCH_S / self.step))
        if self._psd is None:  # shorter than one segment: scipy's welch uses the whole series
            return hs, math.nan
        f = np.fft.rfftfreq(nper, self.step)
        sel = f >= 0.02
        return hs, 1.0 / float(f[sel][np.argmax(self._psd[sel])])


def _npz_members(path: Path) -> set[str]:
    try:
        with zipfile.ZipFile(path) as z:
            return {n[:-4] for n in z.namelist() if n.endswith(".npy")}
    except (OSError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{path}: not a readable .npz file ({exc})") from None


def _sidecar(path: Path, suffix: str) -> Path | None:
    from .replay import _sidecar as find

    return find(path, suffix)


# ------------------------------------------------------------------------------------------ ReplaySource
class ReplaySource:
    """The measured inputs of replayed episodes: waves, wind, load case and time span.

    Parameters
    ----------
    record : path or surrogates.Record
        A record with ``Wave1Elev`` (m, at the spar axis) and ``Wind1VelX`` (m/s, hub height). A ``.npz``
        record file is streamed (see the module docstring); other formats are read whole.
    wind : None, "record", path or surrogates.replay.MeasuredWind
        None: an ``<run>.inflow.npz`` beside the record file if there is one (the polar rotor field, streamed),
        else the record's ``Wind1VelX`` (hub level, through the rotor-averaging filter). ``"record"``: always
        ``Wind1VelX``. A path: an ``*.inflow.npz`` (streamed) or a TurbSim ``.bts`` (read whole). A
        ``MeasuredWind`` (in memory) as it is.
    case : mapping or surrogates.LoadCase, optional
        The conditions (``case.json`` keys, with the mean ``Wind1VelX`` as the wind speed, as
        :func:`fowt_env.replay.record_case`) or the load case itself. Default: the ``<run>.case.json`` beside
        the record file, else estimated from the record (mean hub wind, Hs = 4 std and Tp of ``Wave1Elev``).

    Attributes
    ----------
    case : surrogates.LoadCase
    t_begin, t_end : float
        Span (s, the inputs' own time axis) that both waves and wind cover.
    waves : surrogates.replay_stream.StreamedWaves
    wind : surrogates.replay_stream.StreamedWind

    Raises
    ------
    ValueError
        A record without ``Wave1Elev`` or ``Wind1VelX``, shorter than
        :data:`surrogates.replay.MIN_RECORD_SECONDS`, with NaN/inf samples, or an irregular time axis (each named
        with the time where it happens); a wind file that is not an inflow file; a mean wind <= 0.
    """

    def __init__(self, record: Any, *, wind: Any = None, case: Mapping[str, Any] | Any = None) -> None:
        import surrogates

        self.path: Path | None = None
        if isinstance(record, str | os.PathLike):
            self.path = Path(record)
            if not self.path.is_file():
                raise ValueError(f"replay: {self.path} is not a file")
        elif not isinstance(record, surrogates.Record):
            raise ValueError(f"replay must be a record file path, a surrogates.Record or a ReplaySource, got "
                             f"{type(record).__name__}")
        if case is None and self.path is not None:
            cj = _sidecar(self.path, ".case.json")
            case = json.loads(cj.read_text(encoding="utf-8")) if cj else None
        streamed = self.path is not None and self.path.suffix.lower() == ".npz"
        self._series: list[NpzSeries] = []
        if streamed:
            assert self.path is not None
            series, scan = self._scan_npz(self.path)
        else:
            rec = record if self.path is None else _load(self.path)
            series, scan = self._scan_memory(rec)
        name = str(self.path) if self.path is not None else "record"
        elev_mean, wind_mean = (float(v) for v in scan.sums / scan.n)
        self.waves = StreamedWaves(series, column=0, mean=elev_mean, ends=(scan.heads[0], scan.tails[0]))
        # the record's Wind1VelX: at a fixed point at x = 0 (OpenFAST), or at the rotor (a surrogate's own record)
        x_ref = record_wind_plane(self._meta)
        self.wind = StreamedWind(series, "hub", hub_column=1, mean=wind_mean, ends=(scan.heads[1], scan.tails[1]),
                                 x_ref=x_ref)
        if wind is None and self.path is not None:
            wind = _sidecar(self.path, ".inflow.npz")
        if wind is not None and not (isinstance(wind, str) and wind == "record"):
            self.wind = self._wind(wind)
        if wind_mean <= 0:
            raise ValueError(f"replay: {name}: the mean Wind1VelX is {wind_mean:g} m/s; a replay needs an operating "
                             "rotor (mean wind > 0)")
        self.case = self._case(case, scan, wind_mean, name)
        w, v = self.waves.series, self.wind.series
        self.t_begin = max(w.t0, v.t0)
        self.t_end = min(w.t0 + (w.n_samples - 1) * w.dt, v.t0 + (v.n_samples - 1) * v.dt)
        if self.t_end - self.t_begin < MIN_RECORD_SECONDS:
            raise ValueError(f"replay: {name}: the waves and wind cover {max(self.t_end - self.t_begin, 0):g} s "
                             f"together, shorter than {MIN_RECORD_SECONDS:g} s")

    # ---------------------------------------------------------------------------------------- inputs
    @staticmethod
    def _margins(dt: float) -> tuple[int, int]:
        from surrogates.replay import DEFAULT_TAPER_S

        m = max(int(round(DEFAULT_TAPER_S / dt)), 0)
        return m, m

    def _scan_npz(self, path: Path) -> tuple[NpzSeries, _Scan]:
        members = _npz_members(path)
        if not {"t", "y", "header"} <= members:
            raise ValueError(f"replay: {path} is not a record file (.npz written by Record.save: members t, y, header; "
                             f"found {sorted(members)})")
        with zipfile.ZipFile(path) as z, z.open("header.npy") as fh:
            header = json.loads(str(np.lib.format.read_array(fh, allow_pickle=False)[()]))
        channels = list(header.get("channels", []))
        self._meta = header.get("meta")
        missing = [c for c in ("Wave1Elev", "Wind1VelX") if c not in channels]
        if missing:
            raise ValueError(f"replay: {path} has no {' and no '.join(missing)} channel (a replay needs the measured "
                             "wave elevation Wave1Elev, m, and hub wind Wind1VelX, m/s)")
        cols = [channels.index("Wave1Elev"), channels.index("Wind1VelX")]
        t_rows = _Rows(path, "t")
        y_rows = _Rows(path, "y")
        n = t_rows.shape[0]
        if y_rows.shape[0] != n or len(y_rows.shape) != 2:
            raise ValueError(f"replay: {path}: y of shape {y_rows.shape} does not match t of {n} samples")
        if n < 3:
            raise ValueError(f"replay: {path}: {n} samples, too short to replay")
        t01 = np.asarray(t_rows.read(0, 2), dtype=float)
        m = self._margins(float(t01[1] - t01[0]) if t01[1] > t01[0] else 1.0)
        scan = _Scan(f"replay: {path}", float(t01[1] - t01[0]), *m)
        for i0 in range(0, n, _BLOCK_ROWS):
            i1 = min(n, i0 + _BLOCK_ROWS)
            scan.block(np.asarray(t_rows.read(i0, i1), dtype=float), np.asarray(y_rows.read(i0, i1)[:, cols], float))
        t_rows.close()
        y_rows.close()
        self._check_span(scan, str(path))
        series = NpzSeries(path, [("y", cols)], scan.t0, scan.mean_step)
        self._series.append(series)
        return series, scan

    def _scan_memory(self, rec: Any) -> tuple[ArraySeries, _Scan]:
        self._meta = getattr(rec, "meta", None)
        missing = [c for c in ("Wave1Elev", "Wind1VelX") if c not in rec.channels]
        if missing:
            raise ValueError(f"replay: the record has no {' and no '.join(missing)} channel (a replay needs the "
                             "measured wave elevation Wave1Elev, m, and hub wind Wind1VelX, m/s)")
        t = np.asarray(rec.t, dtype=float)
        x = np.column_stack([np.asarray(rec["Wave1Elev"], float), np.asarray(rec["Wind1VelX"], float)])
        if t.size < 3:
            raise ValueError(f"replay: the record has {t.size} samples, too short to replay")
        m = self._margins(float(t[1] - t[0]) if t[1] > t[0] else 1.0)
        scan = _Scan("replay", float(t[1] - t[0]), *m)
        for i0 in range(0, t.size, _BLOCK_ROWS):
            scan.block(t[i0:i0 + _BLOCK_ROWS], x[i0:i0 + _BLOCK_ROWS])
        self._check_span(scan, "the record")
        return ArraySeries(scan.t0, scan.mean_step, x), scan

    @staticmethod
    def _check_span(scan: _Scan, name: str) -> None:
        span = (scan.n - 1) * scan.step
        if span < MIN_RECORD_SECONDS:
            raise ValueError(f"replay: {name} covers {span:g} s, shorter than {MIN_RECORD_SECONDS:g} s")

    def _wind(self, wind: Any) -> StreamedWind:
        if isinstance(wind, MeasuredWind):
            return _given_wind(wind)
        if not isinstance(wind, str | os.PathLike):
            raise ValueError(f"replay_wind must be None, 'record', a path (.inflow.npz or .bts) or a MeasuredWind, "
                             f"got {type(wind).__name__}")
        p = Path(wind)
        if not p.is_file():
            raise ValueError(f"replay_wind: {p} is not a file")
        if p.suffix.lower() == ".bts":
            from .turbsim import measured_wind_from_bts

            return _given_wind(measured_wind_from_bts(p))  # type: ignore[arg-type]
        members = _npz_members(p)
        need = {"t", "hub_uvw", "polar_u", "polar_radii", "polar_azimuth_rad"}
        if not need <= members:
            raise ValueError(f"replay_wind: {p} is not an inflow file (missing {sorted(need - members)})")
        with np.load(p, allow_pickle=False) as z:
            radii = np.asarray(z["polar_radii"], float)
            az = np.asarray(z["polar_azimuth_rad"], float)
        t_rows = _Rows(p, "t")
        n = t_rows.shape[0]
        if n < 3:
            raise ValueError(f"replay_wind: {p}: {n} samples, too short to replay")
        t01 = np.asarray(t_rows.read(0, 2), float)
        step = float(t01[1] - t01[0])
        t_last, t_first = math.nan, float(t01[0])
        for i0 in range(0, n, _BLOCK_ROWS):  # the inflow file's own axis: finite, increasing, regular
            t = np.asarray(t_rows.read(i0, min(n, i0 + _BLOCK_ROWS)), float)
            full = np.concatenate([[t_last], t]) if i0 else t
            d = np.diff(full)
            if not np.all(np.isfinite(full)) or np.any(d <= 0) or np.any(np.abs(d - step) > _STEP_TOLERANCE * step):
                raise ValueError(f"replay_wind: {p}: the time axis is not finite, increasing and regular")
            t_last = float(t[-1])
        t_rows.close()
        series = NpzSeries(p, [("hub_uvw", [0]), ("polar_u", None)], t_first, (t_last - t_first) / (n - 1))
        self._series.append(series)
        cols = slice(1, 1 + radii.size * az.size)
        return StreamedWind(series, "field", hub_column=0, field_columns=cols, radii=radii, azimuth_rad=az)

    def _case(self, case: Any, scan: _Scan, wind_mean: float, name: str) -> Any:
        import surrogates

        from .validation import surrogate_case

        if isinstance(case, surrogates.LoadCase):
            return case
        if case is not None and not isinstance(case, Mapping):
            raise ValueError(f"replay case must be a mapping (case.json keys) or a surrogates.LoadCase, got "
                             f"{type(case).__name__}")
        c: dict[str, Any] = dict(case or {})
        c.pop("initial", None)
        c["wind_speed"] = wind_mean
        if not c.get("hs"):
            c["hs"], c["tp"] = scan.sea_state()
            if not math.isfinite(c["tp"]):
                from surrogates.replay import sea_state

                c["tp"] = sea_state(*self._short_elevation())[1]
        c.setdefault("name", "replay")
        lc = surrogate_case(c)
        if lc is None or lc.wind_speed <= 0:
            raise ValueError(f"replay: {name}: the conditions are not an operating case (wind speed > 0)")
        return lc

    def _short_elevation(self) -> tuple[np.ndarray, np.ndarray]:
        s = self.waves.series
        x = s.read(0, s.n_samples)[:, self.waves.column]
        return s.t0 + np.arange(s.n_samples) * s.dt, x

    # ----------------------------------------------------------------------------------------- forcing
    def forcing(self, sim: Any, t_start: float | None = None) -> ReplayForcing:
        """The simulator's replayed forcing from ``t_start`` (s on the inputs' axis; default their start)."""
        for s in self._series:
            s.restart()
        return ReplayForcing(sim, self.waves, self.wind, self.t_begin if t_start is None else t_start)

    def restart(self) -> None:
        """Forget the kept windows of the file readers (before an episode starts again)."""
        for s in self._series:
            s.restart()

    def close(self) -> None:
        """Close the files."""
        for s in self._series:
            s.close()


def _load(path: Path) -> Any:
    from .io import load_record

    return load_record(path, unknown_channels="keep")


def _given_wind(wind: MeasuredWind) -> StreamedWind:
    """An in-memory MeasuredWind as columns hub, effective, [shear_y, shear_z], [blade...] (level "given")."""
    cols = [wind.hub, wind.rotor_effective]
    shear = blade = None
    if wind.shear_y is not None and wind.shear_z is not None:
        shear = slice(2, 4)
        cols += [wind.shear_y, wind.shear_z]
    data = np.column_stack(cols)
    inplane = None
    if wind.blade is not None:
        blade = slice(data.shape[1], data.shape[1] + wind.blade.shape[1])
        data = np.hstack([data, np.asarray(wind.blade, float)])
        if wind.blade_inplane is not None:
            inplane = slice(data.shape[1], data.shape[1] + wind.blade_inplane.shape[1])
            data = np.hstack([data, np.asarray(wind.blade_inplane, float)])
    dt = float(np.median(np.diff(wind.t)))
    return StreamedWind(ArraySeries(float(wind.t[0]), dt, data), "given", hub_column=0, effective_column=1,
                        shear_columns=shear, field_columns=blade, inplane_columns=inplane, x_ref=wind.x_ref)
