"""Input checks shared by the estimators: clear ``ValueError`` messages that name the argument.

Every public estimator validates its arguments here, so that bad input fails early with a message saying which
argument, which channels and which samples are wrong — never with a deep ``LinAlgError`` or a silent NaN.
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral, Real

import numpy as np

__all__ = [
    "MAX_ABS",
    "NotFittedError",
    "apply_masks",
    "as_2d_float",
    "as_records",
    "as_sample",
    "check_fitted",
    "check_int",
    "check_no_constant_channels",
    "check_number",
    "constant_channels",
    "constant_channels_across",
    "describe_nonfinite",
    "is_record_list",
    "split_at_nonfinite",
]

_MAX_LISTED = 5

MAX_ABS = 1e150
"""Largest magnitude the estimators fit on: squares and sums of squares of larger values overflow float64 (a
variance of 1e300-sized data is inf, a z-score 0), so training and identification data beyond it get a clear
error naming the channel instead of a silent wrong result (all-zero preprocessing, a NaN rank). Streaming
``update``/``reconstruct`` accept any finite value: their fault screen rejects wild samples."""


class NotFittedError(ValueError, AttributeError):
    """An estimator was used before :meth:`fit` (a ``ValueError`` and an ``AttributeError``, as in scikit-learn)."""


def _list_indices(idx: np.ndarray, limit: int = _MAX_LISTED) -> str:
    idx = np.asarray(idx).ravel()
    shown = ", ".join(str(int(i)) for i in idx[:limit])
    return f"[{shown}, ...] ({idx.size} in all)" if idx.size > limit else f"[{shown}]"


def describe_nonfinite(Y: np.ndarray, *, include_nan: bool = True) -> str:
    """Say which channels and (first few) samples of a 2-D array hold NaN or ±inf.

    Parameters
    ----------
    Y : ndarray (n_samples, n_channels)
    include_nan : bool
        Report NaN too (otherwise only ±inf).

    Returns
    -------
    str
        Empty if all checked values are fine, else e.g. ``"channel 3: NaN at samples [10, 11] ..."``.
    """
    bad = np.isinf(Y) | (np.isnan(Y) if include_nan else False)
    if not bad.any():
        return ""
    channels = np.flatnonzero(bad.any(axis=0))
    parts = []
    for c in channels[:_MAX_LISTED]:
        rows = np.flatnonzero(bad[:, c])
        kinds = sorted({"NaN" if np.isnan(v) else "inf" for v in Y[rows[:_MAX_LISTED], c]})
        parts.append(f"channel {int(c)}: {'/'.join(kinds)} at samples {_list_indices(rows)}")
    more = f"; and {channels.size - _MAX_LISTED} more channels" if channels.size > _MAX_LISTED else ""
    return "; ".join(parts) + more


def as_2d_float(
    Y: object,
    name: str = "Y",
    *,
    allow_nan: bool = False,
    min_samples: int = 1,
    n_channels: int | None = None,
    max_abs: float | None = None,
) -> np.ndarray:
    """Return ``Y`` as a C-contiguous float64 array of shape ``(n_samples, n_channels)`` after checking it.

    Parameters
    ----------
    Y : array_like (n_samples, n_channels)
        Time-major data.
    name : str
        Argument name used in error messages.
    allow_nan : bool
        Let NaN through (missing data); ±inf is always an error.
    min_samples : int
        Minimum number of rows.
    n_channels : int, optional
        Required number of columns (e.g. the number seen in ``fit``).
    max_abs : float, optional
        Refuse finite values larger in magnitude (:data:`MAX_ABS` for data that statistics are computed on).

    Returns
    -------
    ndarray (n_samples, n_channels) of float64

    Raises
    ------
    ValueError
        Not numeric (or complex), not 2-D, too few samples, wrong channel count, or non-finite values; the
        message lists the offending channels and the first few sample indices.

    Examples
    --------
    >>> import numpy as np
    >>> as_2d_float([[1, 2], [3, 4]]).dtype
    dtype('float64')
    >>> as_2d_float(np.array([[1.0, np.nan], [2.0, 3.0]]), "Y_train")
    Traceback (most recent call last):
    ...
    ValueError: Y_train must be finite: channel 1: NaN at samples [0]
    """
    if is_record_list(Y):
        raise ValueError(f"{name} must be one 2-D array here, got a list of {len(Y)} records")
    try:
        arr = np.asarray(Y)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array, got {type(Y).__name__}: {exc}") from exc
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise ValueError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be real, got complex dtype {arr.dtype}")
    if arr.ndim != 2:
        hint = " (use Y[:, None] for a single channel)" if arr.ndim == 1 else ""
        raise ValueError(f"{name} must be 2-D (n_samples, n_channels), got shape {arr.shape}{hint}")
    if arr.shape[1] < 1:
        raise ValueError(f"{name} must have at least one channel, got shape {arr.shape}")
    if n_channels is not None and arr.shape[1] != n_channels:
        raise ValueError(f"{name} must have {n_channels} channels (as in fit), got {arr.shape[1]}")
    if arr.shape[0] < min_samples:
        raise ValueError(f"{name} must have at least {min_samples} samples, got {arr.shape[0]}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.isfinite(arr).all():
        msg = describe_nonfinite(arr, include_nan=not allow_nan)
        if msg:
            what = "finite (no ±inf)" if allow_nan else "finite"
            raise ValueError(f"{name} must be {what}: {msg}")
    if max_abs is not None and arr.size:
        peak = np.nanmax(np.abs(arr), axis=0, initial=0.0)
        if np.any(peak > max_abs):
            c = int(np.argmax(peak > max_abs))
            raise ValueError(f"{name} channel {c} reaches {peak[c]:.3g} in magnitude, beyond {max_abs:.0e} where its "
                             "statistics overflow float64; rescale the data (other units) first")
    return arr


def is_record_list(Y: object) -> bool:
    """True if ``Y`` is a list/tuple of 2-D records rather than one array (a nested list of rows is one array)."""
    return (
        isinstance(Y, Sequence)
        and not isinstance(Y, (str, bytes, np.ndarray))
        and len(Y) > 0
        and all(np.ndim(y) == 2 for y in Y)
    )


def as_records(
    Y: object,
    name: str = "Y",
    *,
    allow_nan: bool = False,
    min_samples: int = 1,
    n_channels: int | None = None,
    max_abs: float | None = None,
) -> list[np.ndarray]:
    """One 2-D array or a list of them (separate records) -> list of checked float64 arrays.

    All records must have the same number of channels. Errors name the record: ``"Y[2] must be finite: ..."``.

    Parameters
    ----------
    Y : array_like (n_samples, n_channels) or sequence of them
    name, allow_nan, min_samples, n_channels
        As in :func:`as_2d_float`.

    Returns
    -------
    list of ndarray
    """
    if isinstance(Y, (list, tuple)) and len(Y) == 0:
        raise ValueError(f"{name} must be a 2-D array or a non-empty list of records, got an empty list")
    if not is_record_list(Y):
        return [as_2d_float(Y, name, allow_nan=allow_nan, min_samples=min_samples, n_channels=n_channels,
                            max_abs=max_abs)]
    records = []
    for i, y in enumerate(Y):
        rec = as_2d_float(y, f"{name}[{i}]", allow_nan=allow_nan, min_samples=min_samples, n_channels=n_channels,
                          max_abs=max_abs)
        n_channels = rec.shape[1]
        records.append(rec)
    return records


def constant_channels(Y: np.ndarray, *, rtol: float = 1e-12) -> np.ndarray:
    """Indices of channels whose finite values do not vary (peak-to-peak <= ``rtol`` x their magnitude).

    NaN samples are ignored; an all-NaN channel counts as constant.

    Parameters
    ----------
    Y : ndarray (n_samples, n_channels)
    rtol : float
        Relative tolerance on the peak-to-peak range.

    Returns
    -------
    ndarray of int

    Examples
    --------
    >>> import numpy as np
    >>> constant_channels(np.array([[1.0, 2.0, 0.0], [1.0, 3.0, 0.0]]))
    array([0, 2])
    """
    Y = np.asarray(Y, dtype=float)
    finite = np.isfinite(Y)
    hi = np.where(finite, Y, -np.inf).max(axis=0)
    lo = np.where(finite, Y, np.inf).min(axis=0)
    none = ~finite.any(axis=0)
    with np.errstate(invalid="ignore"):
        scale = np.maximum(np.abs(hi), np.abs(lo))
        const = none | ((hi - lo) <= rtol * scale)
    return np.flatnonzero(const)


def constant_channels_across(records: Sequence[np.ndarray], *, rtol: float = 1e-12) -> np.ndarray:
    """Channels that are constant over every record of a list (pooled min/max), as :func:`constant_channels`."""
    lo = np.min([r.min(axis=0) for r in records], axis=0)
    hi = np.max([r.max(axis=0) for r in records], axis=0)
    return constant_channels(np.vstack([lo, hi]), rtol=rtol)


def split_at_nonfinite(records: Sequence[np.ndarray], min_length: int) -> tuple[list[np.ndarray], int]:
    """Cut records at every sample holding a NaN/inf and keep the finite stretches of at least ``min_length``.

    Parameters
    ----------
    records : sequence of ndarray (n_samples, n_channels)
    min_length : int
        Shortest stretch kept (samples).

    Returns
    -------
    pieces : list of ndarray
        The finite stretches, in order (may be empty).
    dropped : int
        Samples not kept: the non-finite ones and those of stretches shorter than ``min_length``.
    """
    pieces: list[np.ndarray] = []
    dropped = 0
    for rec in records:
        bad = ~np.isfinite(rec).all(axis=1)
        if not bad.any():
            pieces.append(rec)
            continue
        edges = np.flatnonzero(np.diff(np.r_[True, bad, True].astype(np.int8)))
        for start, stop in zip(edges[::2], edges[1::2], strict=True):
            if stop - start >= min_length:
                pieces.append(rec[start:stop])
            else:
                dropped += stop - start
        dropped += int(bad.sum())
    return pieces, dropped


def check_no_constant_channels(Y: np.ndarray, name: str = "Y", *, rtol: float = 1e-12) -> None:
    """Raise a ``ValueError`` naming the constant channels of ``Y`` (see :func:`constant_channels`)."""
    const = constant_channels(Y, rtol=rtol)
    if const.size:
        raise ValueError(
            f"{name} has constant channel(s) {_list_indices(const)}: they carry no dynamics and make the "
            "problem singular (a dead or saturated sensor?); remove them before fitting"
        )


def check_number(
    name: str,
    value: object,
    *,
    positive: bool = False,
    nonneg: bool = False,
    low: float | None = None,
    high: float | None = None,
) -> float:
    """Return ``value`` as a float after checking it is a finite real number, optionally in a range.

    Parameters
    ----------
    name : str
        Argument name used in the error message.
    value : float
    positive, nonneg : bool
        Require ``> 0`` or ``>= 0``.
    low, high : float, optional
        Require ``low < value < high`` (open interval).

    Raises
    ------
    ValueError
    """
    if isinstance(value, (bool, str, bytes)) or (not isinstance(value, Real) and np.ndim(value) != 0):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    try:
        v = float(value)  # also numpy scalars and 0-d arrays
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a real number, got {value!r}") from exc
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if positive and v <= 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    if nonneg and v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    if low is not None and not v > low:
        raise ValueError(f"{name} must be > {low}, got {value!r}")
    if high is not None and not v < high:
        raise ValueError(f"{name} must be < {high}, got {value!r}")
    return v


def check_int(name: str, value: object, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """Return ``value`` as an int after checking it is an integer (not bool, not float) within bounds.

    Raises
    ------
    ValueError
    """
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {v}")
    if maximum is not None and v > maximum:
        raise ValueError(f"{name} must be <= {maximum}, got {v}")
    return v


def check_fitted(estimator: object, attributes: str | Sequence[str]) -> None:
    """Raise :class:`NotFittedError` if ``estimator`` lacks any of the fitted ``attributes``."""
    attrs = [attributes] if isinstance(attributes, str) else list(attributes)
    if not all(hasattr(estimator, a) for a in attrs):
        raise NotFittedError(f"this {type(estimator).__name__} is not fitted yet: call fit() first")


def apply_masks(records: list[np.ndarray], mask: object) -> list[np.ndarray]:
    """Training records with NaN where their mask is False (the virtual sensors' ``fit(Y, mask)``).

    Parameters
    ----------
    records : list of ndarray (n_samples, n_channels)
    mask : array_like of bool or list of them, optional
        One mask for all records or one per record, each of a record's shape or ``(n_channels,)``; None: none.

    Returns
    -------
    list of ndarray
        New arrays (the inputs are not modified); the records themselves when ``mask`` is None.

    Raises
    ------
    ValueError
        A list of masks of the wrong length, or a mask of the wrong shape (record index named).
    """
    if mask is None:
        return records
    if isinstance(mask, (list, tuple)) and len(mask) > 0 and not np.isscalar(mask[0]) and np.ndim(mask[0]) >= 1 \
            and (len(records) > 1 or np.ndim(mask[0]) == 2):
        masks = list(mask)
        if len(masks) != len(records):
            raise ValueError(f"mask: a list of {len(masks)} masks for {len(records)} records")
    else:
        masks = [mask] * len(records)
    out = []
    for i, (rec, m) in enumerate(zip(records, masks, strict=True)):
        m = np.asarray(m)
        if m.shape not in (rec.shape, (rec.shape[1],)):
            raise ValueError(f"mask: record {i} needs shape {rec.shape} or ({rec.shape[1]},), got {m.shape}")
        out.append(np.where(np.broadcast_to(m.astype(bool), rec.shape), rec, np.nan))
    return out


def as_sample(y: object, mask: object = None, n_channels: int | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """One streamed sample and its mask checked the same way by every virtual sensor's ``update``.

    Parameters
    ----------
    y : array_like (n_channels,)
        Real numbers; NaN (a lost sample) and any finite magnitude are allowed (the fault screen judges values).
    mask : array_like (n_channels,), optional
        Booleans, or the integers 0/1; True = available.
    n_channels : int, optional
        Expected length (the channels the sensor was fitted on); None: any 1-D length.

    Returns
    -------
    y : ndarray of float (n_channels,)
        A new array.
    mask : ndarray of bool (n_channels,) or None

    Raises
    ------
    TypeError
        ``y`` complex (its imaginary part would be dropped) or not numbers, ``mask`` not booleans.
    ValueError
        Wrong shapes, or a mask with values other than True/False/0/1.
    """
    arr = np.asarray(y)
    if np.iscomplexobj(arr):
        raise TypeError("y must be real; got complex values (their imaginary part would be dropped)")
    if arr.dtype.kind not in "biuf":
        try:
            arr = np.asarray(arr, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"y must hold real numbers, got an array of {arr.dtype} "
                            f"({type(y).__name__})") from None
    expected = "(n_channels,)" if n_channels is None else f"({n_channels},)"
    if arr.ndim != 1 or (n_channels is not None and arr.shape[0] != n_channels):
        raise ValueError(f"y must have shape {expected} (one value per channel), got {arr.shape}")
    out = np.array(arr, dtype=float)
    if mask is None:
        return out, None
    m = np.asarray(mask)
    if m.shape != out.shape:
        raise ValueError(f"mask must have shape {out.shape} like y, got {m.shape}")
    if m.dtype.kind != "b":
        if m.dtype.kind not in "iuf" or np.iscomplexobj(m):
            raise TypeError(f"mask must hold booleans (True = available), got an array of {m.dtype}")
        with np.errstate(invalid="ignore"):
            odd = ~((m == 0) | (m == 1))
        if odd.any():
            raise ValueError(f"mask must hold booleans or 0/1 (True = available); got {m[odd][0].item()!r} at channel "
                             f"{int(np.flatnonzero(odd)[0])}")
    return out, m.astype(bool)
