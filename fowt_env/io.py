"""Record files in and out: OpenFAST ``.out``/``.outb``, CSV and Parquet field data, ``.npz`` records.

One entry point per direction, dispatching on the file extension:

=============  ===============================================  ==============================================
extension      read with                                        write with
=============  ===============================================  ==============================================
``.npz``       :meth:`surrogates.Record.load`                   :meth:`surrogates.Record.save` (lossless)
``.out``       :func:`read_openfast` (OpenFAST text)            :func:`write_openfast` (``precision`` digits)
``.outb``      :func:`read_openfast` (OpenFAST binary)          :func:`write_openfast` (int16 or float64)
``.csv``       :func:`read_table` (stdlib ``csv`` + NumPy)      :func:`write_table` (lossless decimal text)
``.parquet``   :func:`read_table` (needs ``pyarrow``)           :func:`write_table` (lossless, keeps ``meta``)
=============  ===============================================  ==============================================

:func:`load_record` and :func:`save_record` are those two dispatchers; every ``fowt-env`` command that reads a
record goes through :func:`load_record`. Every error they raise is a :class:`RecordFileError` (a
:class:`ValueError`) whose message is a single line naming the file and what is wrong with it.

Time axis
---------
Estimators assume uniform sampling, so every reader returns a record on a uniform grid ``t0 + k dt`` (s). The step
is inferred from the data (the median of the differences, then a least-squares fit), never from how wide the
stamps are printed. A file's time stamps must follow the grid to within their own resolution (half a unit of the
last printed digit of each stamp, the int32 quantisation step of a binary ``FileFmtID`` 1 file) or 0.1 % of ``dt``,
whichever is larger; quantised stamps are then replaced by the grid, stamps that already are a uniform grid to
float64 rounding are kept as they are (lossless). Decreasing or repeated stamps, a gap (a step of more than 1.5
``dt``: the message says how many samples are missing) or a jitter beyond that tolerance raise an error naming the
first offending sample: resample such data first (missing samples as NaN rows). ``.npz`` records are held to the
same rule.

Files
-----
Only regular files are read: a device (a link to ``/dev/zero``), a FIFO or a socket is refused before anything is
read, and so is a file larger than the available memory divided by 8 (a reader's worst case per byte).

Missing values
--------------
NaN marks a missing value, as everywhere in fowt-env. Tables: empty cells and ``NA``, ``N/A``, ``NaN``,
``null``, ``None`` (any case) read as NaN, as do Parquet nulls. OpenFAST text: ``NaN`` reads as NaN, and so do
Fortran overflow fields (``*****``), counted in ``meta["overflow_values"]``. An OpenFAST int16 binary channel whose
scale factor is not finite (OpenFAST writes that for a channel holding NaN) reads as all NaN; the int16 formats
cannot store NaN, so :func:`write_openfast` refuses them for records with NaN (use ``file_format_id=3`` or text).

Units are labels only: nothing here converts values (field data in g stays in g; say so with ``units``).

Examples
--------
>>> import numpy as np, tempfile, pathlib
>>> from surrogates.record import Record
>>> rec = Record(np.arange(4) * 0.0125, [[1.0], [2.0], [3.0], [4.0]], ["TwHt9ALxt"], ["m/s^2"])
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> back = load_record(save_record(rec, folder / "run.out"))
>>> back.channels, back.units, back.dt
(['TwHt9ALxt'], ['m/s^2'], 0.0125)
"""

from __future__ import annotations

import contextlib
import csv
import datetime
import difflib
import json
import math
import os
import re
import stat
import uuid
import warnings
import zipfile
import zlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from surrogates.channels import UNITS
from surrogates.record import Record

__all__ = [
    "FILE_FMT_WITH_TIME",
    "FILE_FMT_WITHOUT_TIME",
    "FILE_FMT_NO_COMPRESS_WITHOUT_TIME",
    "FILE_FMT_CHANLEN_IN",
    "READ_EXTENSIONS",
    "RecordFileError",
    "MissingDependencyError",
    "read_openfast",
    "write_openfast",
    "read_table",
    "write_table",
    "rename_channels",
    "load_channel_map",
    "load_record",
    "save_record",
]

FILE_FMT_WITH_TIME = 1
"""OpenFAST binary ``FileFmtID``: int16-packed channels plus an int32-packed time column (any time stamps)."""
FILE_FMT_WITHOUT_TIME = 2
"""OpenFAST binary ``FileFmtID``: int16-packed channels, uniform time (first time and step), 10-character names."""
FILE_FMT_NO_COMPRESS_WITHOUT_TIME = 3
"""OpenFAST binary ``FileFmtID``: float64 channels (lossless), uniform time, 10-character names."""
FILE_FMT_CHANLEN_IN = 4
"""OpenFAST binary ``FileFmtID``: as 2 with the name length stored in the file (OpenFAST's default)."""

_FILE_FMT_IDS = (FILE_FMT_WITH_TIME, FILE_FMT_WITHOUT_TIME, FILE_FMT_NO_COMPRESS_WITHOUT_TIME, FILE_FMT_CHANLEN_IN)

READ_EXTENSIONS: tuple[str, ...] = (".npz", ".out", ".outb", ".csv", ".parquet")
"""File extensions :func:`load_record` and :func:`save_record` understand (case-insensitive)."""

UnknownPolicy = Literal["warn", "keep", "drop", "error"]

_INSTALL_IO = "pip install 'fowt-env[io]'"
_NA_TOKENS = frozenset({"", "na", "n/a", "nan", "-nan", "+nan", "null", "none"})
_INT16_MIN, _INT16_MAX, _INT16_RNG = -32768.0, 32767.0, 65535.0
_INT32_MIN, _INT32_RNG = -2147483648.0, 4294967295.0
_SQRT_EPS32 = float(np.sqrt(np.finfo(np.float32).eps))


# ---------------------------------------------------------------------------------------------------------- errors
def _one_line(text: str) -> str:
    return re.sub(r"\s*\n\s*", "; ", str(text).strip())


class RecordFileError(ValueError):
    """A record file cannot be read or written (missing, unknown extension, unreadable or corrupt content).

    A :class:`ValueError`, so the ``fowt-env`` command line reports it as a one-line error.

    Parameters
    ----------
    path : str or path-like
        The file concerned.
    problem : str
        What is wrong; newlines are folded so the message is one line.

    Attributes
    ----------
    filename : str
        The file concerned.
    problem : str
        What is wrong with it.
    """

    def __init__(self, path: str | os.PathLike[str], problem: str) -> None:
        self.filename = str(path)
        self.problem = _one_line(problem)
        super().__init__(f"{self.filename}: {self.problem}")


class MissingDependencyError(RecordFileError, ImportError):
    """An optional package needed for a file format (``pyarrow`` for Parquet) is not installed.

    Both a :class:`RecordFileError` (a :class:`ValueError`) and an :class:`ImportError`; the message says what to
    install.
    """


def _require_pyarrow(path: Path) -> Any:
    try:
        import pyarrow
        import pyarrow.parquet  # noqa: F401  (registers the submodule)
    except ImportError:
        raise MissingDependencyError(path, f"Parquet files need the 'pyarrow' package: {_INSTALL_IO}") from None
    return pyarrow


# ---------------------------------------------------------------------------------------------------------- helpers
def _atomic_write(dest: Path, write: Callable[[Path], None]) -> Path:
    """Run ``write(tmp)`` on a temporary file beside `dest`, then move it onto `dest`."""
    tmp = dest.with_name(f".{dest.name}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        os.replace(tmp, dest)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return dest


def _package_version() -> str:
    try:
        from importlib.metadata import version

        return version("fowt-env")
    except Exception:  # pragma: no cover - not installed as a distribution
        return "unknown"


_MEMORY_FACTOR = 8
"""Bytes of memory a reader may need per byte of file (text lines, parsed floats, the record): a file larger than
the available memory divided by this is refused before it is read."""


def _available_memory() -> int | None:
    """Bytes of memory available to this process (``MemAvailable``), or None where that is unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


_FILE_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
               (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def _open_regular(p: Path) -> tuple[int, int]:
    """Open `p` for reading without blocking and check it is a regular file of a size this machine can read.

    Returns the file descriptor (the caller closes it) and the file size in bytes. Raises RecordFileError for a
    missing file, a directory, a device, a FIFO or socket (never read: ``/dev/zero`` and a pipe have no end), or a
    file larger than the available memory allows.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(p, flags)
    except FileNotFoundError:
        raise RecordFileError(p, "no such file") from None
    except IsADirectoryError:
        raise RecordFileError(p, "is a directory, not a record file") from None
    except OSError as exc:
        raise RecordFileError(p, f"cannot open: {exc.strerror or exc}") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = next((name for test, name in _FILE_KINDS if test(info.st_mode)), "not a regular file")
            raise RecordFileError(p, f"is {kind}, not a regular file; fowt-env reads records from regular files "
                                     "only")
        size = int(info.st_size)
        available = _available_memory()
        if available is not None and size * _MEMORY_FACTOR > available:
            raise RecordFileError(p, f"is {size / 2**30:.3g} GiB, too large to read here ({available / 2**30:.3g} "
                                     f"GiB of memory available, reading needs up to {_MEMORY_FACTOR}x the file size);"
                                     " split the file")
    except BaseException:
        os.close(fd)
        raise
    return fd, size


def _read_regular(p: Path) -> bytes:
    """The bytes of the regular file `p` (see :func:`_open_regular`), read at most to the size checked."""
    fd, size = _open_regular(p)
    try:
        with os.fdopen(fd, "rb", closefd=True) as fh:
            data = fh.read(size + 1)
    except OSError as exc:
        raise RecordFileError(p, f"cannot read: {exc.strerror or exc}") from None
    if len(data) > size:
        raise RecordFileError(p, "grew while being read; read a finished file")
    return data


def _check_regular(p: Path) -> None:
    """:func:`_open_regular`'s checks, for readers that open the file themselves (NumPy, pyarrow)."""
    fd, _ = _open_regular(p)
    os.close(fd)


def _grid(t0: float, dt: float, n: int) -> NDArray[np.float64]:
    return t0 + dt * np.arange(n, dtype=np.float64)


def _float_noise(t_abs: float, dt: float) -> float:
    """Float64 rounding (s) of time stamps computed as ``t0 + k*dt``: a few ulps of the largest."""
    return 8.0 * float(np.finfo(np.float64).eps) * max(t_abs, dt)


def _uniform_grid(t_raw: NDArray[np.float64], resolution: float | NDArray[np.float64], what: str, *,
                  rel_tol: float = 1e-3) -> tuple[float, float]:
    """``(t0, dt)`` of the uniform grid that the time stamps `t_raw` (s) follow to within their resolution.

    `resolution` is one unit of the last printed digit of each stamp (an array, one per stamp) or of all of them
    (a float; 0 for stamps stored exactly). The step is inferred from the data, not from how the stamps are
    printed: the median of the differences screens every difference (a gap, a jitter or a step back is refused,
    naming its sample), then a least-squares fit of ``t0 + k dt`` is snapped to the shortest decimals that
    reproduce every stamp within half its resolution. Each stamp must lie within ``max(resolution / 2,
    rel_tol * dt)`` of the grid. A resolution coarser than 0.3 ``dt`` (a first stamp printed as ``0``) is capped
    there: such a stamp cannot tell a grid apart, the others can.
    """
    t_raw = np.asarray(t_raw, dtype=np.float64)
    n = int(t_raw.size)
    if n < 2:
        raise ValueError(f"{what} holds {n} time step(s); a record needs at least 2")
    bad = ~np.isfinite(t_raw)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"{what}: time stamp {k} is missing or not finite ({float(t_raw[k])!r})")
    steps = np.diff(t_raw)
    back = np.nonzero(~(steps > 0.0))[0]
    if back.size:
        k = int(back[0])
        raise ValueError(f"{what}: time is not increasing at sample {k + 1} "
                         f"({float(t_raw[k])!r} s, then {float(t_raw[k + 1])!r} s)")
    t_abs = float(np.max(np.abs(t_raw)))
    dt_med = float(np.median(steps))
    noise = _float_noise(t_abs, dt_med)
    res = np.broadcast_to(np.asarray(resolution, dtype=np.float64), (n,))
    half = 0.5 * res
    half = np.minimum(half, 0.3 * dt_med) + noise
    # every step against the median step: names the first gap, jitter or drift
    step_tol = rel_tol * dt_med + half[:-1] + half[1:]
    off = np.abs(steps - dt_med) > step_tol
    if off.any():
        k = int(np.argmax(off))
        step = float(steps[k])
        if step > 1.5 * dt_med:
            raise ValueError(
                f"{what}: time has a gap at sample {k + 1}: {float(t_raw[k + 1])!r} s comes {step:.6g} s after "
                f"{float(t_raw[k])!r} s, about {round(step / dt_med) - 1} missing sample(s) at the median step "
                f"{dt_med:.6g} s; resample to a uniform grid first (missing samples as NaN rows)")
        raise ValueError(
            f"{what}: time step is not uniform: sample {k + 1} at {float(t_raw[k + 1])!r} s comes {step:.6g} s after "
            f"the previous one, the median step is {dt_med:.6g} s (tolerance {float(step_tol[k]):.3g} s); resample "
            "to a uniform grid first (missing samples as NaN rows)")
    # least-squares grid, centred for precision, then the shortest decimals the stamps cannot tell apart from it
    k_idx = np.arange(n, dtype=np.float64)
    kc = k_idx - 0.5 * (n - 1)
    t_mean = float(np.mean(t_raw))
    dt = float(np.dot(kc, t_raw - t_mean) / np.dot(kc, kc))

    def fits(step: float, within: NDArray[np.float64]) -> tuple[bool, float]:
        start = float(np.median(t_raw - step * k_idx))
        return bool(np.all(np.abs(t_raw - (start + step * k_idx)) <= within)), start

    exact, t0 = fits(dt, np.full(n, noise))
    # stamps stored exactly (shortest decimals, binary floats) only snap off float rounding: "0.0", "0.0125",
    # "0.025" are not 0.012 s steps printed to 1 ms. Printed (quantised) stamps snap within their resolution to
    # a step of at most two more decimals than printed and within 3 standard errors of the fitted step: 1 ms
    # stamps of 60 Hz data are not 0.016667 s steps, 0.1 ms stamps of 160 Hz data are 0.00625 s steps.
    # Snapping allows only the rounding of ``t0 + k dt`` itself (2 ulps), not the screening margin `noise`
    # (8 ulps): with that margin two stamps 1234.0 and 1234.00152439024390 (656 Hz) snapped to a step of
    # 0.00152439024 s, 2.6e-9 relative off the true one.
    fine = 2.0 * float(np.finfo(np.float64).eps) * max(t_abs, dt_med)
    snap = np.full(n, fine) if exact else np.minimum(0.5 * res, 0.3 * dt_med) + fine
    ok = exact or fits(dt, half)[0]
    if exact:
        max_digits, max_shift = 16, 2.0 * fine / (n - 1)
    else:
        printed = res[res > 0.0]
        max_digits = 16 if printed.size == 0 else int(round(-math.log10(float(np.median(printed))))) + 2
        resid = t_raw - (t0 + dt * k_idx)
        max_shift = (3.0 * math.sqrt(float(np.dot(resid, resid)) / (n - 2) / float(np.dot(kc, kc)))
                     if n > 2 else math.inf)
    for digits in range(1, min(max_digits, 16) + 1):
        cand = round(dt, digits)
        if cand > 0.0 and abs(cand - dt) <= max_shift and abs(cand - dt) * (n - 1) <= 2.0 * float(snap.max()):
            good, start = fits(cand, snap)
            if good:
                dt, t0, ok = cand, start, True
                break
    if ok:
        for digits in range(0, 13):
            cand0 = round(t0, digits)
            if np.all(np.abs(t_raw - (cand0 + dt * k_idx)) <= snap):
                t0 = cand0
                break
    tol = np.maximum(half, rel_tol * dt + noise)
    dev = np.abs(t_raw - (t0 + dt * k_idx))
    if np.any(dev > tol):
        k = int(np.argmax(dev > tol))
        raise ValueError(
            f"{what}: time step is not uniform: sample {k} at {float(t_raw[k])!r} s is {dev[k]:.3g} s off the grid "
            f"{t0!r} + k*{dt!r} s (tolerance {float(tol[k]):.3g} s); resample to a uniform grid first (missing "
            "samples as NaN rows)"
        )
    return t0, dt


def _time_axis(t_raw: NDArray[np.float64], resolution: float | NDArray[np.float64], what: str) -> NDArray[np.float64]:
    """The uniform time axis (s) of stamps `t_raw`: the stamps themselves if they already are a uniform grid to
    float64 rounding (lossless), else the grid ``t0 + k dt`` of :func:`_uniform_grid` they follow."""
    t_raw = np.asarray(t_raw, dtype=np.float64)
    t0, dt = _uniform_grid(t_raw, resolution, what)
    grid = _grid(t0, dt, t_raw.size)
    noise = _float_noise(float(np.max(np.abs(t_raw))), dt)
    return t_raw.copy() if float(np.max(np.abs(t_raw - grid))) <= noise else grid


def _token_resolution(token: str) -> float:
    """Resolution (s) of a printed number: one unit of its last digit."""
    token = token.strip()
    m = re.fullmatch(r"[+-]?(\d*)\.?(\d*)(?:[eEdD]([+-]?\d+))?", token)
    if not m:
        return 0.0
    decimals = len(m.group(2))
    exponent = int(m.group(3)) if m.group(3) else 0
    return 10.0 ** (exponent - decimals)


def _token_resolutions(tokens: NDArray[np.str_]) -> NDArray[np.float64]:
    """:func:`_token_resolution` of each printed number (vectorised for plain decimals)."""
    cells = np.char.strip(np.asarray(tokens, dtype=str))
    out = np.empty(cells.shape, dtype=np.float64)
    if cells.size == 0:
        return out
    lower = np.char.lower(cells)
    has_exp = (np.char.find(lower, "e") >= 0) | (np.char.find(lower, "d") >= 0)
    dot = np.char.find(cells, ".")
    decimals = np.where(dot >= 0, np.char.str_len(cells) - dot - 1, 0)
    out[:] = 10.0 ** (-decimals.astype(np.float64))
    for i in np.nonzero(has_exp)[0]:
        out[i] = _token_resolution(str(cells[i]))
    return out


def _check_uniform_for_writing(record: Record) -> tuple[float, float]:
    try:
        return _uniform_grid(record.t, 0.0, "the record", rel_tol=1e-6)
    except ValueError as exc:
        raise ValueError(f"{exc}; this format stores a first time and a step only: use "
                         f"file_format_id={FILE_FMT_WITH_TIME} or a text .out file") from None


# ---------------------------------------------------------------------------------------------------------- OpenFAST
def read_openfast(path: str | os.PathLike[str]) -> Record:
    """Read an OpenFAST output file, text (``.out``) or binary (``.outb``), into a record.

    The format is recognised from the content, not the extension. Text: any header lines, then a line of
    channel names starting with ``Time``, a line of units in parentheses (``(s)  (m/s^2) ...``), then one
    whitespace-, tab- or comma-separated row of numbers per time step, as OpenFAST writes it. Binary: OpenFAST's
    ``FileFmtID`` 1 (int16 channels, int32 time), 2 (int16, uniform time), 3 (float64, uniform time) and
    4 (as 2 with the name length stored), little- or big-endian, laid out as OpenFAST's ``WrBinFAST`` writes them.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    Record
        ``t`` (s) is the file's ``Time`` column on a uniform grid (see the module notes), ``channels`` and
        ``units`` (parentheses removed, e.g. ``"kN-m"``) the file's other columns, in file order. ``meta`` holds
        ``source_file``, ``format`` (``"openfast-text"`` or ``"openfast-binary"``), ``file_format_id`` (binary)
        and ``description`` (the file's description text).

    Raises
    ------
    RecordFileError
        (a ValueError, one line) if the file is missing, truncated, not an OpenFAST output file, holds fewer than
        two time steps, duplicated channel names or non-uniform or decreasing time.

    Notes
    -----
    Precision: text values carry the digits printed (OpenFAST's default ``ES10.3E2`` keeps 4 significant
    digits); int16 binary values are quantised to steps of ``1 / ColScl`` (about ``(max - min) / 65535`` of the
    channel), int32-packed time to ``1 / TimeScl``.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> rec = Record(np.arange(3) * 0.05, [[1.0, 0.5], [2.0, 0.25], [3.0, 0.0]], ["PtfmPitch", "X"], ["deg", "-"])
    >>> path = write_openfast(rec, pathlib.Path(tempfile.mkdtemp()) / "run.outb")
    >>> back = read_openfast(path)
    >>> back.channels, back.units, back.meta["file_format_id"]
    (['PtfmPitch', 'X'], ['deg', '-'], 4)
    >>> bool(np.allclose(back.y, rec.y, atol=1e-4))
    True
    """
    p = Path(path)
    data = _read_regular(p)
    try:
        order = _binary_byte_order(data)
        if order is not None:
            t, y, names, units, meta = _parse_openfast_binary(data, order)
        else:
            t, y, names, units, meta = _parse_openfast_text(data)
        meta = {"source_file": str(p), **meta}
        return Record(t, y, names, units, meta)
    except RecordFileError:
        raise
    except (ValueError, IndexError, KeyError, OverflowError, MemoryError) as exc:
        raise RecordFileError(p, str(exc)) from None


def _binary_byte_order(data: bytes) -> str | None:
    if len(data) < 2:
        return None
    if int(np.frombuffer(data, dtype="<i2", count=1)[0]) in _FILE_FMT_IDS:
        return "<"
    if int(np.frombuffer(data, dtype=">i2", count=1)[0]) in _FILE_FMT_IDS:
        return ">"
    return None


class _Cursor:
    """Sequential reader of a binary buffer with size checks."""

    def __init__(self, data: bytes, order: str) -> None:
        self.data, self.order, self.pos = data, order, 0

    def take(self, kind: str, count: int, what: str) -> NDArray[Any]:
        dtype = np.dtype(kind).newbyteorder(self.order)
        end = self.pos + dtype.itemsize * count
        if count < 0 or end > len(self.data):
            raise ValueError(f"not a complete OpenFAST binary file: truncated while reading {what} "
                             f"(needs {end} bytes, the file has {len(self.data)})")
        out = np.frombuffer(self.data, dtype=dtype, count=count, offset=self.pos)
        self.pos = end
        return out

    def scalar(self, kind: str, what: str) -> Any:
        return self.take(kind, 1, what)[0].item()


def _parse_openfast_binary(data: bytes, order: str):
    cur = _Cursor(data, order)
    file_id = cur.scalar("i2", "FileFmtID")
    len_name = cur.scalar("i2", "the name length") if file_id == FILE_FMT_CHANLEN_IN else 10
    if not 1 <= len_name <= 4096:
        raise ValueError(f"corrupt OpenFAST binary file: channel-name length {len_name}")
    n_chan = cur.scalar("i4", "the number of channels")
    n_t = cur.scalar("i4", "the number of time steps")
    if n_chan < 0 or n_t < 0:
        raise ValueError(f"corrupt OpenFAST binary file: {n_chan} channels, {n_t} time steps")
    a, b = cur.scalar("f8", "the time scaling"), cur.scalar("f8", "the time scaling")
    packed = file_id != FILE_FMT_NO_COMPRESS_WITHOUT_TIME
    # check the total size before allocating anything large
    head = cur.pos + (8 * n_chan if packed else 0)
    if head + 4 <= len(data):
        len_desc = int(np.frombuffer(data, dtype=np.dtype("i4").newbyteorder(order), count=1, offset=head)[0])
    else:
        len_desc = 0
    expected = (head + 4 + max(len_desc, 0) + 2 * (n_chan + 1) * len_name
                + (4 * n_t if file_id == FILE_FMT_WITH_TIME else 0) + (2 if packed else 8) * n_chan * n_t)
    if len_desc < 0 or expected != len(data):
        problem = "truncated" if expected > len(data) else "has unexpected trailing bytes"
        raise ValueError(f"not a valid OpenFAST binary file (FileFmtID {file_id}, {n_chan} channels, {n_t} time "
                         f"steps): {problem} ({len(data)} bytes, expected {expected})")
    if packed:
        col_scl = cur.take("f4", n_chan, "the channel scales").astype(np.float64)
        col_off = cur.take("f4", n_chan, "the channel offsets").astype(np.float64)
    len_desc = cur.scalar("i4", "the description length")
    desc = cur.take("u1", len_desc, "the description").tobytes().decode("latin-1").strip()
    raw_names = cur.take("u1", (n_chan + 1) * len_name, "the channel names").tobytes().decode("latin-1")
    raw_units = cur.take("u1", (n_chan + 1) * len_name, "the channel units").tobytes().decode("latin-1")
    names = [raw_names[i:i + len_name].strip() for i in range(0, len(raw_names), len_name)]
    units = [_strip_parens(raw_units[i:i + len_name]) for i in range(0, len(raw_units), len_name)]
    if file_id == FILE_FMT_WITH_TIME:
        time_scl, time_off = a, b
        if not (math.isfinite(time_scl) and time_scl > 0 and math.isfinite(time_off)):
            raise ValueError(f"corrupt OpenFAST binary file: time scale {time_scl!r}, offset {time_off!r}")
        packed_time = cur.take("i4", n_t, "the time column").astype(np.float64)
        t0, dt = _uniform_grid((packed_time - time_off) / time_scl, 1.0 / time_scl, "the time column")
    else:
        t0, dt = a, b
        if not (math.isfinite(t0) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"corrupt OpenFAST binary file: first time {t0!r} s, time step {dt!r} s")
        if n_t < 2:
            raise ValueError(f"holds {n_t} time step(s); a record needs at least 2")
    if packed:
        raw = cur.take("i2", n_chan * n_t, "the channel data").reshape(n_t, n_chan).astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = (raw - col_off) / col_scl
        unusable = ~(np.isfinite(col_scl) & (col_scl != 0.0) & np.isfinite(col_off))
        y[:, unusable] = np.nan
    else:
        y = cur.take("f8", n_chan * n_t, "the channel data").reshape(n_t, n_chan).astype(np.float64)
    meta = {"format": "openfast-binary", "file_format_id": int(file_id), "description": desc}
    return _grid(t0, dt, n_t), y, names[1:], units[1:], meta


def _strip_parens(unit: str) -> str:
    unit = unit.strip()
    if len(unit) >= 2 and unit[0] in "([" and unit[-1] in ")]":
        unit = unit[1:-1].strip()
    return unit


_UNIT_TOKEN = re.compile(r"[(\[]([^()\[\]]*)[)\]]")
_FORTRAN_EXP = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+))([+-]\d{3,})$")


def _parse_openfast_text(data: bytes):
    text = data.decode("utf-8", errors="replace")
    if "\x00" in text[:4096]:
        raise ValueError("not an OpenFAST output file: binary content that is not an OpenFAST FileFmtID 1-4 file")
    lines = text.splitlines()
    header_at = None
    for i, line in enumerate(lines[:200]):
        tokens = line.replace(",", " ").split()
        if not tokens or tokens[0].lower() != "time":
            continue
        following = lines[i + 1] if i + 1 < len(lines) else ""
        units_follow = len(_UNIT_TOKEN.findall(following)) == len(tokens)
        numbers_follow = len(following.replace(",", " ").split()) == len(tokens) and bool(
            re.match(r"\s*[+-]?(\d|\.\d)", following))
        if units_follow or numbers_follow:  # a description line that happens to start with "Time" is neither
            header_at = i
            break
    if header_at is None:
        raise ValueError("not an OpenFAST output file: no line of channel names starting with 'Time' in its first "
                         "200 lines")
    name_line = lines[header_at]
    delimiter = "," if "," in name_line else None
    names = [n.strip() for n in name_line.split(",")] if delimiter else name_line.split()
    units: list[str] | None = None
    start = header_at + 1
    if start < len(lines):
        found = _UNIT_TOKEN.findall(lines[start])
        if found and len(found) == len(names):
            units = [u.strip() for u in found]
            start += 1
    if units is None:
        units = [UNITS.get(n, "") for n in names]
    description = " ".join(ln.strip() for ln in lines[:header_at] if ln.strip())
    body = lines[start:]
    while body and not body[-1].strip():
        body.pop()
    if not body:
        raise ValueError("holds no data rows after its header")
    overflow = 0
    try:
        table = np.loadtxt(body, dtype=np.float64, delimiter=delimiter, ndmin=2, comments=None)
    except ValueError:
        table, overflow = _parse_rows_slowly(body, len(names), delimiter, start)
    if table.shape[1] != len(names):
        raise ValueError(f"has {len(names)} channel names (with Time) but {table.shape[1]} columns of numbers")
    time_tokens = np.array([line.split(delimiter, 1)[0] if delimiter else (line.split(None, 1) or [""])[0]
                            for line in body], dtype=str)
    t = _time_axis(table[:, 0], _token_resolutions(time_tokens), "the Time column")
    meta: dict[str, Any] = {"format": "openfast-text", "description": description}
    if overflow:
        meta["overflow_values"] = overflow
    return t, table[:, 1:], names[1:], units[1:], meta


def _parse_rows_slowly(body: list[str], n_cols: int, delimiter: str | None, first_line: int):
    """Row-by-row parse: Fortran exponents without 'E' (``1.234-100``), ``*****`` overflow fields as NaN."""
    out = np.empty((len(body), n_cols), dtype=np.float64)
    overflow = 0
    for r, line in enumerate(body):
        tokens = [tok.strip() for tok in line.split(delimiter)] if delimiter else line.split()
        if len(tokens) != n_cols:
            raise ValueError(f"line {first_line + r + 1} has {len(tokens)} values, expected {n_cols}")
        for c, tok in enumerate(tokens):
            try:
                out[r, c] = float(tok)
                continue
            except ValueError:
                pass
            m = _FORTRAN_EXP.match(tok)
            if m:
                out[r, c] = float(f"{m.group(1)}E{m.group(2)}")
            elif tok and set(tok) == {"*"}:
                out[r, c] = np.nan
                overflow += 1
            else:
                raise ValueError(f"line {first_line + r + 1}, column {c + 1}: {tok!r} is not a number") from None
    return out, overflow


def write_openfast(
    record: Record,
    path: str | os.PathLike[str],
    *,
    binary: bool | None = None,
    file_format_id: int = FILE_FMT_CHANLEN_IN,
    precision: int = 6,
    description: str | None = None,
) -> Path:
    """Write a record as an OpenFAST output file, text (``.out``) or binary (``.outb``).

    The layouts are OpenFAST's own, so OpenFAST post-processing tools (pCrunch, MLife, openfast_toolbox,
    ``openfast_io.FAST_output_reader``, MATLAB ``ReadFASTbinary``) read the files. Text: a blank line, a
    "Predictions were generated on ..." line, a " linked with ..." line, a blank line, a description line, a
    blank line, tab-separated channel names (``Time`` first), units in parentheses, then one tab-separated row
    per time step. Binary: OpenFAST ``WrBinFAST``'s layout, little-endian.

    Parameters
    ----------
    record : Record
        The record; its time (s) becomes the ``Time`` column.
    path : str or path-like
        Destination; written via a temporary file that replaces it once complete.
    binary : bool or None
        Binary or text; ``None`` (default) decides from the extension (``.outb`` binary, anything else text).
    file_format_id : {1, 2, 3, 4}
        Binary only: :data:`FILE_FMT_CHANLEN_IN` (4, default, OpenFAST's own choice: int16 channels, uniform
        time, names of any length), :data:`FILE_FMT_NO_COMPRESS_WITHOUT_TIME` (3: float64 channels, lossless,
        names and units of at most 10 and 8 characters), :data:`FILE_FMT_WITHOUT_TIME` (2: as 4 with at most 10/8
        characters), :data:`FILE_FMT_WITH_TIME` (1: int16 channels plus an int32-packed time column, the only
        one for non-uniform time; 10/8 characters).
    precision : int
        Text only: digits after the decimal point of the mantissa (``%.{precision}E``); each value is within
        ``0.5e-precision`` of its magnitude. Default 6 (float32-like); OpenFAST's default ``ES10.3E2`` is 3.
    description : str, optional
        Free text for the description line (text) or string (binary); ASCII.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ValueError
        For names or units that the format cannot hold (whitespace, non-ASCII, too long for ``FileFmtID`` 1-3),
        NaN in an int16 format (int16 has no NaN: use 3 or text), non-uniform time outside format 1, or a bad
        option.

    Notes
    -----
    int16 packing (formats 1, 2, 4) follows OpenFAST: per channel ``packed = round(ColScl * y + ColOff)`` with
    float32 ``ColScl`` and ``ColOff`` stored in the file, and readers compute ``(packed - ColOff) / ColScl``.
    Unlike OpenFAST, which maps the minimum to -32768 exactly, the offset here centres the range so that the
    float32 rounding of ``ColOff`` can never push an extreme value out of the int16 range: every value reads
    back within half a step, ``|error| <= 0.5 / ColScl``, with ``ColScl`` at least ``(65535 - margin) / (max -
    min)`` (margin 0 unless the channel's mean is large compared with its range). A constant channel uses
    OpenFAST's scale ``65535 / sqrt(eps_float32)`` (relative to ``max(1, |value|)``). Format 1 packs time into
    the full int32 range (OpenFAST uses only 17 bits of it), i.e. to within ``duration / 2**33``.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> rec = Record(np.arange(3) * 0.0125, [[1.5], [2.5], [-0.125]], ["TwHt1MLyt"], ["kN-m"])
    >>> path = write_openfast(rec, pathlib.Path(tempfile.mkdtemp()) / "run.out")
    >>> path.read_text().splitlines()[6:9]
    ['Time\\tTwHt1MLyt', '(s)\\t(kN-m)', '    0.0000\\t 1.500000E+00']
    """
    if not isinstance(record, Record):
        raise ValueError(f"record must be a surrogates.Record, got {type(record).__name__}")
    dest = Path(path)
    if binary is None:
        binary = dest.suffix.lower() == ".outb"
    names = ["Time", *record.channels]
    units = ["s", *record.units]
    if "Time" in record.channels:
        raise ValueError("the record has a channel named 'Time', which OpenFAST files reserve for the time axis")
    for name in names:
        if not name or not name.isascii() or any(ch.isspace() for ch in name):
            raise ValueError(f"channel name {name!r} cannot be written to an OpenFAST file: it must be non-empty "
                             "ASCII without whitespace")
    for unit in units:
        if not unit.isascii() or any(ch.isspace() for ch in unit):
            raise ValueError(f"unit {unit!r} cannot be written to an OpenFAST file: it must be ASCII without "
                             "whitespace")
    desc = (description or "").strip()
    if not desc.isascii() or "\n" in desc:
        raise ValueError("description must be one line of ASCII text")
    if binary:
        if file_format_id not in _FILE_FMT_IDS:
            raise ValueError(f"file_format_id must be one of {_FILE_FMT_IDS}, got {file_format_id!r}")
        payload = _openfast_binary_bytes(record, names, units, desc, int(file_format_id))
        return _atomic_write(dest, lambda tmp: tmp.write_bytes(payload))
    if isinstance(precision, bool) or not isinstance(precision, int | np.integer) or not 1 <= precision <= 16:
        raise ValueError(f"precision must be an integer in 1..16, got {precision!r}")
    return _atomic_write(dest, lambda tmp: _write_openfast_text(record, tmp, names, units, desc, int(precision)))


def _header_lines(record: Record, desc: str) -> tuple[str, str, str]:
    now = datetime.datetime.now()
    first = (f"Predictions were generated on {now:%d-%b-%Y} at {now:%H:%M:%S} using fowt-env "
             f"{_package_version()} (NREL 5 MW on OC3 Hywind surrogate and tools)")
    source = record.meta.get("source")
    linked = f"linked with surrogates.Record; source: {source}" if isinstance(source, str) else \
        "linked with surrogates.Record"
    return first, linked, f"Description from fowt-env: {desc}" if desc else "Description from fowt-env:"


def _write_openfast_text(record: Record, tmp: Path, names: list[str], units: list[str], desc: str,
                         precision: int) -> None:
    t = record.t
    dt = record.dt
    decimals = 15
    # enough digits that every stamp reads back to within an ulp or two of the float written, which a reader
    # takes as exact (a margin of 8 ulps let 2816.002525252525 s print as 2816.00252525253 and read 5e-12 s off)
    one_ulp = float(np.finfo(np.float64).eps) * max(float(np.max(np.abs(t))), dt)
    for d in range(4, 16):
        if float(np.max(np.abs(t - np.round(t, d)))) <= one_ulp:
            decimals = d
            break
    width = max(10, decimals + 6)
    first, linked, description = _header_lines(record, desc)
    with open(tmp, "x", encoding="ascii", newline="\n") as fh:
        fh.write(f"\n{first}\n {linked}\n\n{description}\n\n")
        fh.write("\t".join(names) + "\n")
        fh.write("\t".join(f"({u})" for u in units) + "\n")
        fmt = [f"%{width}.{decimals}f"] + [f"%{precision + 7}.{precision}E"] * record.n_channels
        np.savetxt(fh, np.column_stack([t, record.y]), fmt=fmt, delimiter="\t")


def _int16_scaling(column: NDArray[np.float64], name: str) -> tuple[np.float32, np.float32]:
    """float32 (ColScl, ColOff) such that every value packs within half a step, without clipping."""
    lo, hi = float(column.min()), float(column.max())
    rng = hi - lo
    eff = rng if rng > 0.0 else _SQRT_EPS32 * max(1.0, abs(lo))
    margin = 0.0
    for _ in range(64):
        with np.errstate(over="ignore"):
            scl = np.float32((_INT16_RNG - margin) / eff)
            off = np.float32(-0.5 - float(scl) * 0.5 * (lo + hi))
        if not (np.isfinite(scl) and scl > 0 and np.isfinite(off)):
            break
        p_lo, p_hi = float(scl) * lo + float(off), float(scl) * hi + float(off)
        excess = max(_INT16_MIN - 0.5 - p_lo, p_hi - (_INT16_MAX + 0.5))
        if excess <= 0.0:
            return scl, off
        margin += 2.0 * excess + 1.0
    raise ValueError(f"channel {name!r} (range [{lo!r}, {hi!r}]) cannot be packed into int16; "
                     f"use file_format_id={FILE_FMT_NO_COMPRESS_WITHOUT_TIME}")


def _openfast_binary_bytes(record: Record, names: list[str], units: list[str], desc: str, file_id: int) -> bytes:
    y = record.y
    packed = file_id != FILE_FMT_NO_COMPRESS_WITHOUT_TIME
    if packed and np.isnan(y).any():
        bad = [record.channels[i] for i in np.nonzero(np.isnan(y).any(axis=0))[0][:3]]
        raise ValueError(f"channel(s) {bad} hold NaN, which int16-packed OpenFAST files cannot store; use "
                         f"file_format_id={FILE_FMT_NO_COMPRESS_WITHOUT_TIME} or a text .out file")
    paren_units = [f"({u})" for u in units]
    if file_id == FILE_FMT_CHANLEN_IN:
        len_name = max(1, *(len(s) for s in names), *(len(s) for s in paren_units))
    else:
        len_name = 10
        too_long = [s for s in names + paren_units if len(s) > len_name]
        if too_long:
            raise ValueError(f"FileFmtID {file_id} holds names and '(unit)' strings of at most 10 characters; "
                             f"{too_long[:3]} are longer: use file_format_id={FILE_FMT_CHANLEN_IN}")
    parts: list[bytes] = [np.int16(file_id).astype("<i2").tobytes()]
    if file_id == FILE_FMT_CHANLEN_IN:
        parts.append(np.int16(len_name).astype("<i2").tobytes())
    parts.append(np.array([record.n_channels, record.n_samples], dtype="<i4").tobytes())
    if file_id == FILE_FMT_WITH_TIME:
        t_min, t_max = float(record.t[0]), float(record.t[-1])
        time_scl = _INT32_RNG / (t_max - t_min)
        time_off = _INT32_MIN - time_scl * t_min
        packed_time = np.clip(np.rint(time_scl * record.t + time_off), _INT32_MIN, -_INT32_MIN - 1)
        parts.append(np.array([time_scl, time_off], dtype="<f8").tobytes())
    else:
        t0, dt = _check_uniform_for_writing(record)
        parts.append(np.array([t0, dt], dtype="<f8").tobytes())
    if packed:
        scales = [_int16_scaling(y[:, c], record.channels[c]) for c in range(record.n_channels)]
        col_scl = np.array([s for s, _ in scales], dtype=np.float32)
        col_off = np.array([o for _, o in scales], dtype=np.float32)
        parts.append(col_scl.astype("<f4").tobytes())
        parts.append(col_off.astype("<f4").tobytes())
    desc_bytes = (desc or f"Generated by fowt-env {_package_version()}").encode("ascii")
    parts.append(np.int32(len(desc_bytes)).astype("<i4").tobytes())
    parts.append(desc_bytes)
    parts.append("".join(s.ljust(len_name) for s in names).encode("ascii"))
    parts.append("".join(s.ljust(len_name) for s in paren_units).encode("ascii"))
    if file_id == FILE_FMT_WITH_TIME:
        parts.append(packed_time.astype("<i4").tobytes())
    if packed:
        values = np.rint(col_scl.astype(np.float64) * y + col_off.astype(np.float64))
        parts.append(np.clip(values, _INT16_MIN, _INT16_MAX).astype("<i2").tobytes())
    else:
        parts.append(np.ascontiguousarray(y, dtype="<f8").tobytes())
    return b"".join(parts)


# ---------------------------------------------------------------------------------------------------------- tables
_HEADER_UNIT = re.compile(r"^(.*?)\s*_?[\[(]\s*([^\[\]()]*?)\s*[\])]$")


def _split_header(raw: str) -> tuple[str, str | None]:
    """``"TwHt9ALxt [m/s^2]"``, ``"TwHt9ALxt (m/s^2)"`` or ``"TwHt9ALxt_[m/s^2]"`` -> name and unit."""
    raw = raw.strip()
    m = _HEADER_UNIT.match(raw)
    if m and m.group(1).strip():
        return m.group(1).strip(), m.group(2)
    return raw, None


@dataclass
class _Column:
    raw: str
    name: str
    unit: str | None
    values: NDArray[Any]  # float64, datetime64, or str (CSV cells, converted late)


def _float_column(col: _Column, what: str) -> NDArray[np.float64]:
    v = col.values
    if v.dtype.kind == "f":
        return v.astype(np.float64, copy=False)
    if v.dtype.kind in "iub":
        return v.astype(np.float64)
    if v.dtype.kind == "U":
        cells = np.char.strip(v)
        na = np.isin(np.char.lower(cells), list(_NA_TOKENS))
        cells = np.where(na, "nan", cells)
        try:
            return cells.astype(np.float64)
        except ValueError:
            for r, cell in enumerate(cells.tolist()):
                try:
                    float(cell)
                except ValueError:
                    raise ValueError(f"{what} {col.raw!r} is not numeric: row {r + 1} holds {cell!r}") from None
    raise ValueError(f"{what} {col.raw!r} is not numeric (type {v.dtype})")


def _time_seconds(col: _Column) -> tuple[NDArray[np.float64], float | NDArray[np.float64], str | None]:
    """Seconds, their resolution (s; one per printed stamp, or one for all) and the ISO start time (datetime
    columns only)."""
    v = col.values
    if v.dtype.kind == "M":
        ns = v.astype("datetime64[ns]")
        if np.isnat(ns).any():
            raise ValueError(f"time column {col.raw!r}: time stamp {int(np.argmax(np.isnat(ns)))} is missing")
        rel = (ns - ns[0]).astype(np.int64).astype(np.float64) * 1e-9
        return rel, 1e-9, str(ns[0])
    if v.dtype.kind == "U":
        cells = np.char.strip(v)
        missing = np.isin(np.char.lower(cells), list(_NA_TOKENS))
        if missing.any():
            raise ValueError(f"time column {col.raw!r}: time stamp {int(np.argmax(missing))} is missing")
        try:
            seconds = cells.astype(np.float64)
        except ValueError:
            seconds = None
        if seconds is not None:
            return seconds, _token_resolutions(cells), None
        try:
            with warnings.catch_warnings():  # numpy warns on UTC offsets (+01:00), which it applies
                warnings.simplefilter("ignore")
                stamps = np.array([c[:-1] if c.endswith("Z") else c for c in cells.tolist()],
                                  dtype="datetime64[ns]")
        except ValueError:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                bad = next((c for c in cells.tolist() if not _parses_as_time(c)), cells[0])
            raise ValueError(f"time column {col.raw!r} holds {bad!r}, neither seconds nor an ISO 8601 date-time; "
                             "pass time_column=None and dt=... if the file has no time column") from None
        return _time_seconds(_Column(col.raw, col.name, col.unit, stamps))
    return _float_column(col, "time column"), 0.0, None


def _parses_as_time(cell: str) -> bool:
    try:
        float(cell)
        return True
    except ValueError:
        pass
    try:
        np.datetime64(cell[:-1] if cell.endswith("Z") else cell)
        return True
    except ValueError:
        return False


def _read_csv_columns(path: Path) -> list[_Column]:
    text = _read_regular(path).decode("utf-8-sig")
    lines = [ln for ln in text.splitlines() if not ln.lstrip().startswith("#")]
    while lines and not lines[0].strip():
        lines.pop(0)
    if not lines:
        raise ValueError("is empty (no header row)")
    head = lines[0]
    delimiter = "," if "," in head else ";" if ";" in head else "\t" if "\t" in head else ","
    rows = [r for r in csv.reader(lines, delimiter=delimiter) if any(cell.strip() for cell in r)]
    if not rows:  # e.g. a lone delimiter: no cell holds anything
        raise ValueError("has no header row (no non-empty cells)")
    header = [h.strip() for h in rows[0]]
    body = rows[1:]
    file_units: list[str | None] = [None] * len(header)
    if body and all(re.fullmatch(r"[(\[].*[)\]]", c.strip()) for c in body[0] if c.strip()) and \
            any(c.strip() for c in body[0]):
        file_units = [_strip_parens(c) if c.strip() else None for c in body[0]]
        body = body[1:]
    if len(body) < 2:
        raise ValueError(f"holds {len(body)} data row(s); a record needs at least 2")
    for r, row in enumerate(body):
        if len(row) != len(header):
            raise ValueError(f"data row {r + 1} has {len(row)} cells but the header has {len(header)} columns")
    cells = np.array(body, dtype=str).reshape(len(body), len(header))
    out = []
    for j, raw in enumerate(header):
        name, unit = _split_header(raw)
        out.append(_Column(raw, name, file_units[j] if file_units[j] is not None else unit, cells[:, j]))
    return out


def _read_parquet_columns(path: Path) -> tuple[list[_Column], dict[str, Any] | None]:
    pa = _require_pyarrow(path)
    _check_regular(path)
    try:
        table = pa.parquet.read_table(path)
    except (pa.lib.ArrowException, OSError) as exc:
        raise ValueError(f"not a readable Parquet file: {exc}") from None
    embedded = None
    schema_meta = table.schema.metadata or {}
    if b"fowt-env.record" in schema_meta:
        try:
            embedded = json.loads(schema_meta[b"fowt-env.record"].decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError):
            embedded = None
    out = []
    for i, field in enumerate(table.schema):
        col = table.column(i)
        unit = None
        if field.metadata and b"unit" in field.metadata:
            unit = field.metadata[b"unit"].decode("utf-8", errors="replace")
        name, header_unit = _split_header(field.name)
        if unit is None:
            unit = header_unit
        typ = field.type
        if pa.types.is_timestamp(typ) or pa.types.is_date(typ):
            values = col.cast(pa.timestamp("ns")).to_numpy(zero_copy_only=False)
        elif pa.types.is_integer(typ) or pa.types.is_floating(typ) or pa.types.is_boolean(typ) or \
                pa.types.is_decimal(typ):
            values = col.cast(pa.float64()).to_numpy(zero_copy_only=False)
        elif pa.types.is_string(typ) or pa.types.is_large_string(typ):
            values = np.array(["" if v is None else v for v in col.to_pylist()], dtype=str)
        else:
            values = np.array(col.to_pylist(), dtype=object)
        out.append(_Column(field.name, name, unit, values))
    if table.num_rows < 2:
        raise ValueError(f"holds {table.num_rows} row(s); a record needs at least 2")
    return out, embedded


def _validate_channel_map(channel_map: Any) -> dict[str, str]:
    if channel_map is None:
        return {}
    if not isinstance(channel_map, Mapping):
        raise ValueError(f"channel_map must be a mapping of file column names to channel names, got "
                         f"{type(channel_map).__name__}")
    out = {}
    for key, value in channel_map.items():
        if not isinstance(key, str) or not isinstance(value, str) or not value.strip():
            raise ValueError(f"channel_map entries must map strings to non-empty strings, got {key!r}: {value!r}")
        out[key] = value.strip()
    return out


def _unknown_keys_message(unknown: list[str], available: list[str]) -> str:
    parts = []
    for name in unknown:
        match = difflib.get_close_matches(name, available, n=1, cutoff=0.6)
        parts.append(f"{name!r}" + (f" (did you mean {match[0]!r}?)" if match else ""))
    shown = ", ".join(repr(n) for n in available[:8]) + (", ..." if len(available) > 8 else "")
    return f"channel_map names column(s) the file does not have: {', '.join(parts)}; columns: [{shown}]"


def read_table(
    path: str | os.PathLike[str],
    *,
    channel_map: Mapping[str, str] | None = None,
    time_column: str | None = "Time",
    dt: float | None = None,
    units: Mapping[str, str] | Sequence[str] | None = None,
    unknown_channels: UnknownPolicy = "warn",
) -> Record:
    """Read field data or exported results from a CSV or Parquet table into a record.

    One column per channel, one row per time step. Column headers may carry units, as ``name [unit]``,
    ``name (unit)`` or ``name_[unit]``; a CSV may instead have a second header row of units in parentheses or
    brackets (OpenFAST style), and Parquet columns a ``unit`` field metadata entry (as :func:`write_table` writes).
    CSV: comma-, semicolon- or tab-separated (from the header row), UTF-8, lines starting with ``#`` ignored;
    read with the standard library and NumPy, no pandas needed. Parquet needs ``pyarrow``
    (``pip install 'fowt-env[io]'``).

    Parameters
    ----------
    path : str or path-like
        A ``.csv`` or ``.parquet`` file (decided by the extension).
    channel_map : mapping of str to str, optional
        Renames file columns to fowt-env's OpenFAST channel names, e.g. ``{"acc_top_x": "TwHt9ALxt"}``. Keys are
        column names as in the file (with or without their unit suffix); every key must exist. Columns not in
        the map keep their names.
    time_column : str or None
        The column holding time (default ``"Time"``, matched exactly, then case-insensitively): seconds, or ISO
        8601 date-times (converted to seconds from the first one, UTC offsets applied; ``meta["start_time"]``
        keeps the first one, in UTC if offsets were given). ``None``:
        the file has no time column and `dt` gives the sampling.
    dt : float, optional
        Sampling interval (s). Used when the file has no time column (then ``t = k dt`` from 0); when it has one,
        `dt` must agree with it within 0.1 %.
    units : mapping or sequence of str, optional
        Unit strings of the resulting channels, by final (mapped) name or in order; they override units from the
        file. Otherwise: the file's units, else fowt-env's unit for a known channel name, else ``""`` (unknown).
    unknown_channels : {"warn", "keep", "drop", "error"}
        What to do with columns whose final name is not one of fowt-env's channels
        (:data:`surrogates.channels.ALL_CHANNELS`): keep them and warn (default), keep them silently, drop them,
        or refuse the file. Kept ones are listed in ``meta["unknown_channels"]``. Dropped columns need not be
        numeric.

    Returns
    -------
    Record
        Channels in file order (time column removed); float64 data with NaN for missing values (see the module
        notes); ``meta`` with ``source_file``, ``format``, and ``channel_map``, ``unknown_channels`` and
        ``start_time`` where they apply. A Parquet file written by :func:`write_table` gives back its record's
        own ``meta``.

    Raises
    ------
    RecordFileError
        (a ValueError, one line) naming the file and the problem: missing file, unreadable content, duplicated
        or non-numeric columns, channel_map keys the file lacks, unknown channels with ``"error"``, no time column
        and no `dt`, non-uniform or decreasing time, fewer than two rows.
    MissingDependencyError
        For Parquet without ``pyarrow`` installed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "field.csv"
    >>> _ = path.write_text("Time,acc_top_x [m/s^2],status\\n0.0,0.1,ok\\n0.5,,ok\\n1.0,-0.2,ok\\n")
    >>> rec = read_table(path, channel_map={"acc_top_x": "TwHt9ALxt"}, unknown_channels="drop")
    >>> rec.channels, rec.units, rec.dt
    (['TwHt9ALxt'], ['m/s^2'], 0.5)
    >>> rec["TwHt9ALxt"].tolist()
    [0.1, nan, -0.2]
    """
    p = Path(path)
    try:
        return _read_table(p, channel_map, time_column, dt, units, unknown_channels)
    except RecordFileError:
        raise
    except FileNotFoundError:
        raise RecordFileError(p, "no such file") from None
    except IsADirectoryError:
        raise RecordFileError(p, "is a directory, not a table") from None
    except UnicodeDecodeError as exc:
        raise RecordFileError(p, f"is not UTF-8 text (byte {exc.start}): not a CSV file") from None
    except OSError as exc:
        raise RecordFileError(p, f"cannot read: {exc.strerror or exc}") from None
    except (ValueError, csv.Error, IndexError, KeyError, MemoryError) as exc:
        raise RecordFileError(p, str(exc)) from None


def _read_table(p: Path, channel_map: Any, time_column: str | None, dt: float | None, units: Any,
                unknown_channels: str) -> Record:
    if unknown_channels not in ("warn", "keep", "drop", "error"):
        raise ValueError(f"unknown_channels must be 'warn', 'keep', 'drop' or 'error', got {unknown_channels!r}")
    if dt is not None and not (isinstance(dt, int | float | np.floating | np.integer) and math.isfinite(dt)
                               and dt > 0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
    mapping = _validate_channel_map(channel_map)
    ext = p.suffix.lower()
    embedded = None
    if ext == ".parquet":
        columns, embedded = _read_parquet_columns(p)
        fmt = "parquet"
    elif ext == ".csv":
        columns = _read_csv_columns(p)
        fmt = "csv"
    else:
        raise ValueError(f"read_table reads .csv and .parquet files, not {ext or 'files without an extension'!r}")

    # time column
    time_col = None
    if time_column is not None:
        exact = [c for c in columns if time_column in (c.name, c.raw)]
        loose = [c for c in columns if time_column.lower() in (c.name.lower(), c.raw.lower())]
        found = exact or loose
        if len(found) > 1:
            raise ValueError(f"several columns match time_column {time_column!r}: {[c.raw for c in found]}")
        if found:
            time_col = found[0]
            columns = [c for c in columns if c is not time_col]
        elif dt is None:
            raise ValueError(f"no time column {time_column!r} among [{', '.join(c.raw for c in columns[:8])}"
                             f"{', ...' if len(columns) > 8 else ''}]; pass time_column=<name>, or dt=<seconds> "
                             "if the file has none")
    elif dt is None:
        raise ValueError("time_column=None needs dt (the sampling interval, s)")

    # channel map
    if mapping:
        by_name = {c.name: c for c in columns} | {c.raw: c for c in columns}
        missing = [k for k in mapping if k not in by_name and not (time_col and k in (time_col.name, time_col.raw))]
        if missing:
            raise ValueError(_unknown_keys_message(missing, [c.name for c in columns]))
        for key, new in mapping.items():
            if key in by_name:
                by_name[key].name = new
    names = [c.name for c in columns]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"duplicated column name(s) {dup}" + (" after channel_map" if mapping else ""))

    unknown = [c.name for c in columns if c.name not in UNITS]
    if unknown:
        shown = ", ".join(repr(n) for n in unknown[:6]) + (", ..." if len(unknown) > 6 else "")
        if unknown_channels == "error":
            raise ValueError(f"{len(unknown)} column(s) are not fowt-env channel names: {shown} (map them with "
                             "channel_map, or pass unknown_channels='keep' or 'drop')")
        if unknown_channels == "drop":
            columns = [c for c in columns if c.name in UNITS]
            unknown = []
        elif unknown_channels == "warn":
            warnings.warn(f"{p}: {len(unknown)} column(s) are not fowt-env channel names and are kept as they are: "
                          f"{shown} (map them with channel_map)", UserWarning, stacklevel=3)
    if not columns:
        raise ValueError("no data columns left" + (" after dropping unknown channels" if unknown_channels == "drop"
                                                   else ""))

    y = np.column_stack([_float_column(c, "column") for c in columns])
    n = y.shape[0]
    start_time = None
    if time_col is not None:
        seconds, resolution, start_time = _time_seconds(time_col)
        t = _time_axis(seconds, resolution, f"time column {time_col.raw!r}")
        step = float(t[1] - t[0]) if n == 2 else float((t[-1] - t[0]) / (n - 1))
        if dt is not None and abs(step - float(dt)) > 1e-3 * float(dt):
            raise ValueError(f"dt={dt!r} s disagrees with the time column's step {step!r} s")
    else:
        t = _grid(0.0, float(dt), n)  # type: ignore[arg-type]

    final_names = [c.name for c in columns]
    unit_list = [c.unit if c.unit is not None else UNITS.get(c.name, "") for c in columns]
    if units is not None:
        if isinstance(units, Mapping):
            extra = [k for k in units if k not in final_names]
            if extra:
                raise ValueError(f"units names channel(s) the record does not have: {extra[:5]}")
            unit_list = [str(units.get(name, u)) for name, u in zip(final_names, unit_list, strict=True)]
        elif isinstance(units, str) or not isinstance(units, Sequence):
            raise ValueError(f"units must be a mapping or a sequence of strings, got {type(units).__name__}")
        else:
            if len(units) != len(final_names):
                raise ValueError(f"units has {len(units)} entries but there are {len(final_names)} channels")
            unit_list = [str(u) for u in units]

    if embedded is not None and isinstance(embedded.get("meta"), dict) and not mapping:
        meta: dict[str, Any] = embedded["meta"]
    else:
        meta = {"source_file": str(p), "format": fmt}
        if mapping:
            meta["channel_map"] = mapping
        if unknown:
            meta["unknown_channels"] = unknown
        if start_time is not None:
            meta["start_time"] = start_time
    return Record(t, y, final_names, unit_list, meta)


def write_table(record: Record, path: str | os.PathLike[str]) -> Path:
    """Write a record as a CSV or Parquet table (by extension), one column per channel after ``Time``.

    CSV: a header row ``Time [s],TwHt1ALxt [m/s^2],...`` (no brackets for an empty unit), then one row per time
    step with every value in its shortest exact decimal form (``nan`` for missing), so a round trip through
    :func:`read_table` is bit-identical except ``meta``, which CSV cannot hold. Parquet (needs ``pyarrow``):
    float64 columns named as the channels, each with its unit in the field metadata (key ``unit``), and the
    record's JSON header (channels, units, meta) in the schema metadata (key ``fowt-env.record``); the round
    trip keeps everything.

    Parameters
    ----------
    record : Record
        The record.
    path : str or path-like
        ``.csv`` or ``.parquet`` destination; written via a temporary file that replaces it once complete.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ValueError
        For another extension, or a channel named ``Time``.
    MissingDependencyError
        For Parquet without ``pyarrow``.
    """
    if not isinstance(record, Record):
        raise ValueError(f"record must be a surrogates.Record, got {type(record).__name__}")
    dest = Path(path)
    if "Time" in record.channels:
        raise ValueError("the record has a channel named 'Time', which tables reserve for the time axis")
    ext = dest.suffix.lower()
    if ext == ".csv":
        headers = ["Time [s]"] + [f"{n} [{u}]" if u else n for n, u in zip(record.channels, record.units,
                                                                            strict=True)]

        def write_csv(tmp: Path) -> None:
            cells = np.column_stack([record.t, record.y]).astype(str)
            with open(tmp, "x", encoding="utf-8", newline="") as fh:
                writer = csv.writer(fh, lineterminator="\n")
                writer.writerow(headers)
                writer.writerows(cells.tolist())

        return _atomic_write(dest, write_csv)
    if ext == ".parquet":
        pa = _require_pyarrow(dest)
        fields = [pa.field("Time", pa.float64(), metadata={"unit": "s"})]
        arrays = [pa.array(record.t)]
        for j, (name, unit) in enumerate(zip(record.channels, record.units, strict=True)):
            fields.append(pa.field(name, pa.float64(), metadata={"unit": unit}))
            arrays.append(pa.array(record.y[:, j]))
        header = json.dumps({"channels": record.channels, "units": record.units, "meta": record.meta},
                            ensure_ascii=False, allow_nan=False)
        schema = pa.schema(fields, metadata={"fowt-env.record": header})
        table = pa.Table.from_arrays(arrays, schema=schema)
        return _atomic_write(dest, lambda tmp: pa.parquet.write_table(table, tmp))
    raise ValueError(f"write_table writes .csv and .parquet files, not {ext or 'files without an extension'!r}")


# ---------------------------------------------------------------------------------------------------------- records
def rename_channels(record: Record, channel_map: Mapping[str, str]) -> Record:
    """The record with channels renamed by `channel_map` (old name -> new name); others unchanged.

    A renamed channel keeps its unit, unless that is empty and the new name is a known fowt-env channel, which
    then gets its unit from :data:`surrogates.channels.UNITS`.

    Raises
    ------
    ValueError
        If a key is not a channel of the record (with a close-match suggestion) or the new names collide.

    Examples
    --------
    >>> import numpy as np
    >>> rec = Record([0.0, 1.0], [[1.0], [2.0]], ["acc_top_x"], [""])
    >>> renamed = rename_channels(rec, {"acc_top_x": "TwHt9ALxt"})
    >>> renamed.channels, renamed.units
    (['TwHt9ALxt'], ['m/s^2'])
    """
    mapping = _validate_channel_map(channel_map)
    channels = record.channels
    missing = [k for k in mapping if k not in channels]
    if missing:
        raise ValueError(_unknown_keys_message(missing, channels).replace("the file does not have", "the record "
                                                                          "does not have"))
    new = [mapping.get(c, c) for c in channels]
    units = [UNITS.get(n, u) if (c in mapping and not u) else u for c, n, u in zip(channels, new, record.units,
                                                                                     strict=True)]
    dup = sorted({n for n in new if new.count(n) > 1})
    if dup:
        raise ValueError(f"channel_map makes channel names collide: {dup}")
    return record.replace(channels=new, units=units)


def load_channel_map(path: str | os.PathLike[str]) -> dict[str, str]:
    """Read a channel map, a JSON object of file column names to channel names (``{"acc_top_x": "TwHt9ALxt"}``).

    Raises
    ------
    RecordFileError
        (one line) if the file is missing, not JSON, or not an object of strings to strings.
    """
    p = Path(path)
    try:
        raw = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RecordFileError(p, "no such file (channel map)") from None
    except OSError as exc:
        raise RecordFileError(p, f"cannot read the channel map: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RecordFileError(p, f"channel map is not valid JSON: {exc}") from None
    try:
        return _validate_channel_map(raw)
    except ValueError as exc:
        raise RecordFileError(p, f"not a channel map: {exc}") from None


def _check_readable(p: Path) -> str:
    if not os.path.lexists(p):
        raise RecordFileError(p, "no such file")
    if not p.exists():
        raise RecordFileError(p, "is a broken symbolic link (no such file)")
    if p.is_dir():
        raise RecordFileError(p, "is a directory, not a record file")
    ext = p.suffix.lower()
    if ext not in READ_EXTENSIONS:
        raise RecordFileError(p, f"unknown file extension {ext or '(none)'!r}; fowt-env reads "
                                 f"{', '.join(READ_EXTENSIONS)}")
    _check_regular(p)
    return ext


def load_record(
    path: str | os.PathLike[str],
    *,
    channel_map: Mapping[str, str] | None = None,
    unknown_channels: UnknownPolicy = "warn",
    **options: Any,
) -> Record:
    """Read a record from any supported file, by extension (case-insensitive).

    ``.npz`` -> :meth:`surrogates.Record.load`, ``.out``/``.outb`` -> :func:`read_openfast`,
    ``.csv``/``.parquet`` -> :func:`read_table`.

    Parameters
    ----------
    path : str or path-like
        The file.
    channel_map : mapping of str to str, optional
        Renames channels (file column names -> fowt-env channel names) for every format; for tables it is
        :func:`read_table`'s argument, for the others :func:`rename_channels` is applied after reading.
    unknown_channels : {"warn", "keep", "drop", "error"}
        Tables only: see :func:`read_table`.
    **options
        Further :func:`read_table` arguments (``time_column``, ``dt``, ``units``); tables only.

    Returns
    -------
    Record

    Raises
    ------
    RecordFileError
        (a ValueError with a one-line message naming the file) for a missing file, a directory, an unknown
        extension, unreadable or corrupt content, or channel_map keys the file lacks.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> try:
    ...     load_record(pathlib.Path(tempfile.mkdtemp()) / "missing.outb")
    ... except ValueError as exc:
    ...     print(str(exc).split(": ")[-1])
    no such file
    """
    p = Path(path)
    ext = _check_readable(p)
    if ext in (".csv", ".parquet"):
        return read_table(p, channel_map=channel_map, unknown_channels=unknown_channels, **options)
    if options:
        raise RecordFileError(p, f"option(s) {sorted(options)} apply to .csv and .parquet files only")
    if ext == ".npz":
        try:
            record = Record.load(p)
        except (ValueError, OSError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as exc:
            message = str(exc) if not isinstance(exc, zlib.error) else f"corrupt compressed data ({exc})"
            message = message[len(str(p)):].lstrip(": ") if message.startswith(str(p)) else message
            raise RecordFileError(p, message or type(exc).__name__) from None
        try:  # Record allows any increasing t; every reader here promises a uniform grid
            _uniform_grid(record.t, 0.0, "the time axis t")
        except ValueError as exc:
            raise RecordFileError(p, str(exc)) from None
    else:
        record = read_openfast(p)
    if channel_map:
        try:
            record = rename_channels(record, channel_map)
        except ValueError as exc:
            raise RecordFileError(p, str(exc)) from None
    return record


def save_record(record: Record, path: str | os.PathLike[str], **options: Any) -> Path:
    """Write a record to any supported file, by extension (case-insensitive).

    ``.npz`` -> :meth:`surrogates.Record.save` (lossless, keeps ``meta``), ``.out``/``.outb`` ->
    :func:`write_openfast` (``options``: ``file_format_id``, ``precision``, ``description``),
    ``.csv``/``.parquet`` -> :func:`write_table`.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    RecordFileError
        (one line) for an unknown extension, a missing directory, or what the writer refuses.
    """
    p = Path(path)
    if not isinstance(record, Record):
        raise RecordFileError(p, f"can only save a surrogates.Record, got {type(record).__name__}")
    ext = p.suffix.lower()
    if ext not in READ_EXTENSIONS:
        raise RecordFileError(p, f"unknown file extension {ext or '(none)'!r}; fowt-env writes "
                                 f"{', '.join(READ_EXTENSIONS)}")
    if not p.parent.is_dir():
        raise RecordFileError(p, f"directory {str(p.parent)!r} does not exist")
    if options and ext not in (".out", ".outb"):
        raise RecordFileError(p, f"option(s) {sorted(options)} apply to .out and .outb files only")
    try:
        if ext == ".npz":
            return record.save(p)
        if ext in (".out", ".outb"):
            return write_openfast(record, p, **options)
        return write_table(record, p)
    except RecordFileError:
        raise
    except (ValueError, OSError) as exc:
        raise RecordFileError(p, getattr(exc, "strerror", None) or str(exc)) from None
