"""`Record`: multichannel time series of one simulation, measurement campaign or file import.

A record holds time stamps ``t`` (s, shape ``(n_samples,)``), data ``y`` (float64, time-major, shape
``(n_samples, n_channels)``), the channel names and units (OpenFAST conventions, see
:mod:`surrogates.channels`) and a JSON-serialisable ``meta`` dictionary (load case, seed, model effects, ...).
``y`` may hold NaN: a dropped sample or a lost sensor is legal data. A batch of seeds is a ``list[Record]``.

File format
-----------
:meth:`Record.save` writes one compressed NumPy archive (``.npz``, :func:`numpy.savez_compressed`) with three
members:

``t``
    float64 array ``(n_samples,)``, the time stamps (s).
``y``
    float64 array ``(n_samples, n_channels)``, the data.
``header``
    0-d unicode array holding a JSON object::

        {"format": "fowt-env.record", "version": 1,
         "channels": [...], "units": [...], "meta": {...}}

No member is an object array, so :meth:`Record.load` reads the file with ``numpy.load(path,
allow_pickle=False)``: there is no pickle anywhere, and loading a file cannot execute code. The arrays are
stored as raw IEEE-754 bytes, so a round trip is bit-identical (NaN payloads included). Any tool that reads
``.npz`` and JSON (e.g. ``numpy`` alone, or a zip reader plus an ``.npy`` parser) can read the format.

Examples
--------
>>> import numpy as np
>>> from surrogates.record import Record
>>> t = np.arange(5) * 0.0125
>>> rec = Record(t, np.zeros((5, 2)), ["PtfmPitch", "TwHt1ALxt"], ["deg", "m/s^2"], meta={"seed": 1})
>>> rec.fs, rec.n_channels
(80.0, 2)
>>> rec.select("TwHt1ALxt").channels
['TwHt1ALxt']
"""

from __future__ import annotations

import contextlib
import copy
import errno
import json
import math
import os
import uuid
import zipfile
import zlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from surrogates.channels import channel_index, channel_units, tower_channels

__all__ = ["Record", "FORMAT_NAME", "FORMAT_VERSION"]

FORMAT_NAME = "fowt-env.record"
"""Value of the ``"format"`` key of a saved record's JSON header."""

FORMAT_VERSION = 1
"""Version of the file format written by :meth:`Record.save`; :meth:`Record.load` reads versions <= this."""

_MEMBERS = {"t", "y", "header"}


def _read_only(a: NDArray[np.float64]) -> NDArray[np.float64]:
    view = a.view()
    view.flags.writeable = False
    return view


def _jsonable(value: Any, where: str) -> Any:
    """Plain-JSON copy of ``value`` (dicts with str keys, lists, str, finite numbers, bool, None)."""
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        out = float(value)
        if not math.isfinite(out):
            raise ValueError(f"meta{where} must be finite to be valid JSON, got {out!r} (use None instead)")
        return out
    if isinstance(value, dict):
        out_dict = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise ValueError(f"meta{where} keys must be strings, got {key!r} ({type(key).__name__})")
            out_dict[key] = _jsonable(item, f"{where}[{key!r}]")
        return out_dict
    if isinstance(value, list | tuple):
        return [_jsonable(item, f"{where}[{i}]") for i, item in enumerate(value)]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist(), where)
    hint = " (a LoadCase? store load_case.to_dict())" if hasattr(value, "to_dict") else ""
    raise ValueError(
        f"meta{where} must be JSON-serialisable (dict, list, str, int, float, bool, None), "
        f"got {type(value).__name__}{hint}"
    )


def _name_list(values: Any, argname: str) -> list[str]:
    if isinstance(values, str) or not isinstance(values, Sequence | np.ndarray):
        raise ValueError(f"{argname} must be a sequence of strings, got {type(values).__name__}")
    out = list(values)
    bad = [v for v in out if not isinstance(v, str)]
    if bad:
        raise ValueError(f"{argname} must contain only strings, got {bad[:3]!r}")
    return out


class Record:
    """Multichannel time series: time stamps, time-major data, channel names, units and metadata.

    Parameters
    ----------
    t : array_like, shape (n_samples,)
        Time stamps (s): finite, strictly increasing, at least two samples. Uniform spacing is not required;
        :attr:`dt` is the median spacing.
    y : array_like, shape (n_samples, n_channels)
        Data, converted to float64. NaN marks a missing value (legal); +-inf is rejected.
    channels : sequence of str, length n_channels
        Unique channel names (OpenFAST conventions, see :mod:`surrogates.channels`).
    units : sequence of str or None, length n_channels
        Unit string of each channel (e.g. ``"m/s^2"``, ``"kN-m"``). ``None`` looks them up in
        :data:`surrogates.channels.UNITS` (all channels must then be known there).
    meta : dict, optional
        JSON-serialisable metadata with string keys (load case as ``LoadCase.to_dict()``, seed, dt, model
        effects, ...). NumPy scalars and arrays are converted to Python numbers and lists; tuples to lists;
        non-finite floats are rejected (strict JSON). A normalised deep copy is stored.

    Raises
    ------
    ValueError
        Naming the argument, for wrong shapes, non-finite or non-increasing `t`, infinite `y`, duplicated
        channels, a units/channels length mismatch or non-serialisable `meta`.

    Notes
    -----
    Arrays are taken without copying when they already are float64 and are exposed read-only (``rec.y`` is a
    read-only view); copy them to modify, then build a new record (see :meth:`replace`). :attr:`channels`,
    :attr:`units` and :attr:`meta` return copies, so a record cannot be changed after construction.

    Examples
    --------
    >>> import numpy as np
    >>> from surrogates.channels import tower_channels
    >>> t = np.arange(800) / 80.0
    >>> y = np.random.default_rng(0).normal(size=(800, 36))
    >>> rec = Record(t, y, tower_channels(), units=None, meta={"load_case": "OLC7", "seed": 3})
    >>> rec.planar("FA").n_channels
    18
    >>> rec["TwHt9ALxt"].shape
    (800,)
    >>> rec.slice_time(1.0, 2.0).n_samples
    80
    """

    __hash__ = None  # type: ignore[assignment]  # mutable-looking container compared by value

    def __init__(
        self,
        t: ArrayLike,
        y: ArrayLike,
        channels: Sequence[str],
        units: Sequence[str] | None,
        meta: dict[str, Any] | None = None,
    ) -> None:
        t_arr = self._check_t(t)
        y_arr = self._check_y(y, t_arr.shape[0])
        names = _name_list(channels, "channels")
        if len(names) != y_arr.shape[1]:
            raise ValueError(f"channels has {len(names)} names but y has {y_arr.shape[1]} columns")
        if len(set(names)) != len(names):
            dup = sorted({n for n in names if names.count(n) > 1})
            raise ValueError(f"channels must be unique; duplicated: {dup}")
        if units is None:
            unit_list = channel_units(names)
        else:
            unit_list = _name_list(units, "units")
            if len(unit_list) != len(names):
                raise ValueError(f"units has {len(unit_list)} entries but there are {len(names)} channels")
        if meta is None:
            meta = {}
        if not isinstance(meta, dict):
            raise ValueError(f"meta must be a dict or None, got {type(meta).__name__}")
        self._t = _read_only(t_arr)
        self._y = _read_only(y_arr)
        self._channels = tuple(names)
        self._units = tuple(unit_list)
        self._meta: dict[str, Any] = _jsonable(meta, "")

    @staticmethod
    def _check_t(t: ArrayLike) -> NDArray[np.float64]:
        try:
            t_arr = np.asarray(t, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"t must be a 1-D array of real time stamps (s): {exc}") from None
        if t_arr.ndim != 1:
            raise ValueError(f"t must be 1-D (n_samples,), got shape {t_arr.shape}")
        if t_arr.shape[0] < 2:
            raise ValueError(f"t must hold at least 2 samples, got {t_arr.shape[0]}")
        if not np.all(np.isfinite(t_arr)):
            raise ValueError(f"t must be finite; {int(np.sum(~np.isfinite(t_arr)))} non-finite value(s)")
        steps = np.diff(t_arr)
        if not np.all(steps > 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise ValueError(f"t must be strictly increasing; t[{k}] = {t_arr[k]!r} >= t[{k + 1}] = {t_arr[k + 1]!r}")
        return t_arr

    @staticmethod
    def _check_y(y: ArrayLike, n: int) -> NDArray[np.float64]:
        if np.iscomplexobj(y):
            raise ValueError("y must be real, got a complex array")
        try:
            y_arr = np.asarray(y, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"y must be a 2-D array of real numbers: {exc}") from None
        if y_arr.ndim != 2:
            hint = " (use y[:, None] for a single channel)" if y_arr.ndim == 1 else ""
            raise ValueError(f"y must be 2-D (n_samples, n_channels), got shape {y_arr.shape}{hint}")
        if y_arr.shape[0] != n:
            raise ValueError(f"y must have one row per time stamp: y has {y_arr.shape[0]} rows, t has {n} samples")
        if np.isinf(y_arr).any():
            raise ValueError(f"y must not hold +-inf (NaN marks missing data); {int(np.isinf(y_arr).sum())} found")
        return y_arr

    # ------------------------------------------------------------------ attributes
    @property
    def t(self) -> NDArray[np.float64]:
        """Time stamps (s), shape (n_samples,), read-only."""
        return self._t

    @property
    def y(self) -> NDArray[np.float64]:
        """Data, shape (n_samples, n_channels), float64, read-only."""
        return self._y

    @property
    def channels(self) -> list[str]:
        """Channel names (a new list)."""
        return list(self._channels)

    @property
    def units(self) -> list[str]:
        """Unit strings, one per channel (a new list)."""
        return list(self._units)

    @property
    def meta(self) -> dict[str, Any]:
        """Metadata (a deep copy)."""
        return copy.deepcopy(self._meta)

    @property
    def dt(self) -> float:
        """Sampling interval (s): the median spacing of :attr:`t`."""
        return float(np.median(np.diff(self._t)))

    @property
    def fs(self) -> float:
        """Sampling frequency (Hz), ``1 / dt``."""
        return 1.0 / self.dt

    @property
    def duration(self) -> float:
        """Time spanned by the record, ``t[-1] - t[0]`` (s)."""
        return float(self._t[-1] - self._t[0])

    @property
    def n_samples(self) -> int:
        """Number of time stamps."""
        return int(self._t.shape[0])

    @property
    def n_channels(self) -> int:
        """Number of channels."""
        return int(self._y.shape[1])

    def __len__(self) -> int:
        return self.n_samples

    def __contains__(self, name: object) -> bool:
        return name in self._channels

    def __repr__(self) -> str:
        names = list(self._channels)
        shown = ", ".join(names[:3]) + (f", ..., {names[-1]}" if len(names) > 3 else "")
        return (
            f"Record(n_samples={self.n_samples}, n_channels={self.n_channels}, dt={self.dt:.6g} s, "
            f"t=[{self._t[0]:.6g}, {self._t[-1]:.6g}] s, channels=[{shown}])"
        )

    def __eq__(self, other: object) -> bool:
        """Same channels, units, meta and arrays (NaN equal to NaN)."""
        if not isinstance(other, Record):
            return NotImplemented
        return (
            self._channels == other._channels
            and self._units == other._units
            and self._meta == other._meta
            and np.array_equal(self._t, other._t)
            and self._y.shape == other._y.shape
            and np.array_equal(self._y, other._y, equal_nan=True)
        )

    # ------------------------------------------------------------------ views
    def __getitem__(self, name: str) -> NDArray[np.float64]:
        """Column of one channel, shape (n_samples,), read-only.

        Raises
        ------
        UnknownChannelError
            (both a ValueError and a KeyError) if `name` is not a channel.
        """
        if not isinstance(name, str):
            raise TypeError(f"Record indices are channel names (str), got {type(name).__name__}; use .y")
        return self._y[:, int(channel_index(self._channels, name)[0])]

    def select(self, names: str | Sequence[str]) -> Record:
        """Record with only the given channels, in the given order.

        Parameters
        ----------
        names : str or sequence of str
            Channel names; must be unique and present.

        Returns
        -------
        Record
            Same `t` and `meta`; `y` columns and units follow `names`.

        Raises
        ------
        ValueError
            On unknown names (with a close-match suggestion) or repeated names.
        """
        idx = channel_index(self._channels, names)
        return Record(
            self._t,
            self._y[:, idx],
            [self._channels[i] for i in idx],
            [self._units[i] for i in idx],
            self._meta,
        )

    def planar(self, plane: str) -> Record:
        """The seed paper's 18-channel planar state of one bending plane.

        Parameters
        ----------
        plane : {"FA", "SS"}
            Fore-aft or side-to-side; the channels are :func:`surrogates.channels.tower_channels(plane)
            <surrogates.channels.tower_channels>`: accelerations at gauges 1-9, then moments at gauges 1-9.

        Returns
        -------
        Record

        Raises
        ------
        ValueError
            If `plane` is not "FA" or "SS", or the record lacks some of those channels.
        """
        if plane is None:
            raise ValueError("plane must be 'FA' or 'SS', got None")
        return self.select(tower_channels(plane))

    def slice_time(self, t0: float | None = None, t1: float | None = None) -> Record:
        """Samples with ``t0 <= t < t1`` (time stamps are kept, not shifted).

        Parameters
        ----------
        t0, t1 : float or None
            Window start (inclusive) and end (exclusive) (s); ``None`` leaves that side open. Half-open
            windows let consecutive slices tile a record without overlap.

        Returns
        -------
        Record

        Raises
        ------
        ValueError
            If a bound is not finite, ``t0 >= t1``, or the window holds fewer than two samples.
        """
        lo = -np.inf if t0 is None else float(t0)
        hi = np.inf if t1 is None else float(t1)
        if (t0 is not None and not math.isfinite(lo)) or (t1 is not None and not math.isfinite(hi)):
            raise ValueError(f"t0 and t1 must be finite or None, got t0={t0!r}, t1={t1!r}")
        if lo >= hi:
            raise ValueError(f"t0 must be < t1, got t0={t0!r}, t1={t1!r}")
        keep = (self._t >= lo) & (self._t < hi)
        if int(keep.sum()) < 2:
            raise ValueError(
                f"window [{t0!r}, {t1!r}) holds {int(keep.sum())} sample(s); a Record needs at least 2 "
                f"(record spans [{self._t[0]!r}, {self._t[-1]!r}] s)"
            )
        return Record(self._t[keep], self._y[keep], self._channels, self._units, self._meta)

    def replace(
        self,
        *,
        t: ArrayLike | None = None,
        y: ArrayLike | None = None,
        channels: Sequence[str] | None = None,
        units: Sequence[str] | None = None,
        meta: dict[str, Any] | None = None,
    ) -> Record:
        """A new record with some parts replaced (and validated again); others are shared.

        Examples
        --------
        >>> import numpy as np
        >>> rec = Record([0.0, 1.0], [[1.0], [2.0]], ["Wave1Elev"], ["m"])
        >>> rec.replace(meta={"note": "demo"}).meta
        {'note': 'demo'}
        """
        return Record(
            self._t if t is None else t,
            self._y if y is None else y,
            self._channels if channels is None else channels,
            self._units if units is None else units,
            self._meta if meta is None else meta,
        )

    # ------------------------------------------------------------------ files
    def _header(self) -> str:
        return json.dumps(
            {
                "format": FORMAT_NAME,
                "version": FORMAT_VERSION,
                "channels": list(self._channels),
                "units": list(self._units),
                "meta": self._meta,
            },
            ensure_ascii=False,
            allow_nan=False,
        )

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the record to one ``.npz`` file (format in the module docstring).

        The file is written exactly at `path` (no suffix is appended; ``.npz`` is the recommended one), via a
        temporary file in the same directory that replaces `path` only once complete.

        Parameters
        ----------
        path : str or path-like
            Destination file; its directory must exist.

        Returns
        -------
        pathlib.Path
            The path written.
        """
        dest = Path(path)
        header = np.array(self._header(), dtype=np.str_)
        if dest.is_dir():
            raise IsADirectoryError(errno.EISDIR, "is a directory; give a file name", str(dest))
        if not dest.parent.is_dir():
            raise FileNotFoundError(errno.ENOENT, f"its directory {str(dest.parent)!r} does not exist", str(dest))
        tmp = dest.with_name(f".{dest.name}.{uuid.uuid4().hex}.tmp")
        try:
            with open(tmp, "xb") as fh:
                np.savez_compressed(fh, t=self._t, y=self._y, header=header)
            os.replace(tmp, dest)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            if isinstance(exc, OSError) and exc.errno is not None:  # name the destination, not the hidden file
                raise type(exc)(exc.errno, exc.strerror, str(dest)) from None
            raise
        return dest

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Record:
        """Read a record written by :meth:`save`, with ``numpy.load(path, allow_pickle=False)``.

        Parameters
        ----------
        path : str or path-like
            A ``.npz`` file written by :meth:`save`.

        Returns
        -------
        Record
            Bit-identical arrays, same channels, units and meta.

        Raises
        ------
        FileNotFoundError
            If `path` does not exist (``IsADirectoryError`` if it is a directory); one line naming it.
        ValueError
            If the file is not a record archive (wrong members, object arrays, a bad or foreign header, a newer
            format version, or corrupt compressed data); one line naming it.
        """
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(errno.ENOENT, "no such file", str(path))
        if path.is_dir():
            raise IsADirectoryError(errno.EISDIR, "is a directory, not a record file", str(path))
        unreadable = (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error)
        # Open the file ourselves so that it is closed on every path (np.load leaks it on a corrupt zip).
        with open(path, "rb") as fh:
            try:
                loaded = np.load(fh, allow_pickle=False)
            except unreadable as exc:
                raise ValueError(f"{path} is not a Record file (.npz written by Record.save): "
                                 f"{' '.join(str(exc).split())}") from None
            if not isinstance(loaded, np.lib.npyio.NpzFile):
                raise ValueError(f"{path} is not a Record file: it holds a single array, not an .npz archive")
            with loaded:
                members = set(loaded.files)
                if members != _MEMBERS:
                    raise ValueError(
                        f"{path} is not a Record file: members {sorted(members)}, expected {sorted(_MEMBERS)}"
                    )
                try:
                    t, y, header_arr = loaded["t"], loaded["y"], loaded["header"]
                except unreadable as exc:
                    what = f"corrupt compressed data ({exc})" if isinstance(exc, zlib.error) else str(exc)
                    raise ValueError(f"{path} is not a readable Record file: {' '.join(what.split())}") from None
        if header_arr.ndim != 0 or header_arr.dtype.kind != "U":
            raise ValueError(f"{path} is not a Record file: 'header' is not a 0-d unicode array")
        try:
            header = json.loads(str(header_arr[()]))
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path} is not a Record file: header is not JSON ({exc})") from None
        if not isinstance(header, dict) or header.get("format") != FORMAT_NAME:
            raise ValueError(f"{path} is not a Record file: header format is not {FORMAT_NAME!r}")
        version = header.get("version")
        if not isinstance(version, int) or isinstance(version, bool) or not 1 <= version <= FORMAT_VERSION:
            raise ValueError(f"{path} has Record format version {version!r}; this fowt-env reads 1-{FORMAT_VERSION}")
        for key in ("channels", "units", "meta"):
            if key not in header:
                raise ValueError(f"{path} is not a Record file: header lacks {key!r}")
        if t.dtype != np.float64 or y.dtype != np.float64:
            raise ValueError(f"{path} is not a Record file: t and y must be float64, got {t.dtype}, {y.dtype}")
        return cls(t, y, header["channels"], header["units"], header["meta"])
