"""Band-pass filtering and z-scoring of sensor records, offline (zero-phase) and online (causal, streaming).

The seed paper's preprocessing: a 4th-order Butterworth band-pass (0.25-5 Hz), zero-phase (forward-backward),
then a z-score per channel, so that accelerations (m/s²) and bending moments (kN·m) weigh equally in the SVD.
Offline this is :func:`preprocess`. A live estimator cannot look into the future: :class:`Preprocessor` in
causal mode (``zero_phase=False``) runs the same Butterworth filter forward only, carries the filter state from
sample to sample in :meth:`Preprocessor.step`, and z-scores with the statistics of the training data.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from .validation import (
    MAX_ABS,
    as_2d_float,
    as_records,
    check_fitted,
    check_int,
    check_no_constant_channels,
    check_number,
    is_record_list,
)

__all__ = ["Preprocessor", "band_sos", "preprocess"]


def _check_band(band: object, fs: float) -> tuple[float | None, float | None]:
    if not isinstance(band, (tuple, list)) or len(band) != 2:
        raise ValueError(f"band must be a pair (low_hz, high_hz) (either may be None), got {band!r}")
    nyq = fs / 2.0
    lo = None if band[0] is None else check_number("band[0] (low edge, Hz)", band[0], positive=True)
    hi = None if band[1] is None else check_number("band[1] (high edge, Hz)", band[1], positive=True)
    for edge, label in ((lo, "band[0]"), (hi, "band[1]")):
        if edge is not None and edge >= nyq:
            raise ValueError(f"{label} = {edge} Hz must be below the Nyquist frequency fs/2 = {nyq} Hz (fs = {fs} Hz)")
    if lo is not None and hi is not None and not lo < hi:
        raise ValueError(f"band must have low < high, got {band!r}")
    if lo is None and hi is None:
        raise ValueError("band must give at least one edge, got (None, None)")
    return lo, hi


def band_sos(fs: float, band: tuple[float | None, float | None] = (0.25, 5.0), order: int = 4) -> np.ndarray:
    """Second-order sections of the Butterworth filter used by :func:`preprocess` and :class:`Preprocessor`.

    Parameters
    ----------
    fs : float
        Sampling frequency (Hz).
    band : (float or None, float or None)
        Pass band edges (Hz), both below ``fs / 2``. ``(low, None)`` gives a high-pass, ``(None, high)`` a low-pass.
    order : int
        Butterworth order (of the prototype: a band-pass of order 4 has 8 poles, as ``scipy.signal.butter``).

    Returns
    -------
    ndarray (n_sections, 6)

    Raises
    ------
    ValueError
        Bad ``fs``, ``order`` or band edges (non-positive, crossed, or at/above Nyquist).
    """
    fs = check_number("fs", fs, positive=True)
    order = check_int("order", order, minimum=1, maximum=32)
    lo, hi = _check_band(band, fs)
    if lo is not None and hi is not None:
        return signal.butter(order, [lo, hi], btype="bandpass", fs=fs, output="sos")
    if lo is not None:
        return signal.butter(order, lo, btype="highpass", fs=fs, output="sos")
    return signal.butter(order, hi, btype="lowpass", fs=fs, output="sos")


def _zero_phase(sos: np.ndarray, Y: np.ndarray, name: str) -> np.ndarray:
    # sosfiltfilt's default pad length; a clear message instead of scipy's when the record is too short
    padlen = 3 * (2 * len(sos) + 1 - min((sos[:, 2] == 0).sum(), (sos[:, 5] == 0).sum()))
    if Y.shape[0] <= padlen:
        raise ValueError(
            f"{name} has {Y.shape[0]} samples; the zero-phase filter needs more than {padlen} "
            "(use a longer record, a lower order, or zero_phase=False)"
        )
    return signal.sosfiltfilt(sos, Y, axis=0)


def _zi_steady(sos: np.ndarray, y0: np.ndarray) -> np.ndarray:
    """Filter state of a filter that has seen the constant input ``y0`` forever: shape (n_sections, 2, p)."""
    return signal.sosfilt_zi(sos)[:, :, None] * y0[None, None, :]


def _causal(sos: np.ndarray, Y: np.ndarray) -> np.ndarray:
    out, _ = signal.sosfilt(sos, Y, axis=0, zi=_zi_steady(sos, Y[0]))
    return out


def _zscore_stats(F: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    mean = F.mean(axis=0)
    std = F.std(axis=0)
    dead = np.flatnonzero(~(std > 0))
    if dead.size:
        raise ValueError(f"{name}: channel(s) {dead.tolist()} have zero variance after filtering; cannot z-score")
    return mean, std


def preprocess(
    Y: object, fs: float, band: tuple[float | None, float | None] = (0.25, 5.0), order: int = 4
) -> np.ndarray:
    """Zero-phase Butterworth band-pass, then z-score each channel over the whole record.

    Parameters
    ----------
    Y : array_like (n_samples, n_channels)
        Raw record in channel units (finite).
    fs : float
        Sampling frequency (Hz).
    band : (float or None, float or None)
        Pass band (Hz), default the seed paper's 0.25-5 Hz. Edges must be below ``fs / 2``.
    order : int
        Butterworth order (applied forward and backward, so the magnitude response is squared).

    Returns
    -------
    ndarray (n_samples, n_channels)
        Filtered record with zero mean and unit standard deviation per channel (dimensionless).

    Raises
    ------
    ValueError
        Non-finite data (channels and samples listed), a constant channel, a record too short for the filter's
        padding, or a bad band.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(4000) / 80.0
    >>> Y = np.c_[np.sin(2 * np.pi * 1.0 * t) + 5.0, 1e3 * np.sin(2 * np.pi * 0.5 * t)]
    >>> Z = preprocess(Y, fs=80.0)
    >>> np.allclose(Z.mean(axis=0), 0.0), np.allclose(Z.std(axis=0), 1.0)
    (True, True)
    """
    Y = as_2d_float(Y, "Y", min_samples=2, max_abs=MAX_ABS)
    check_no_constant_channels(Y, "Y")
    sos = band_sos(fs, band, order)
    F = _zero_phase(sos, Y, "Y")
    mean, std = _zscore_stats(F, "Y")
    return (F - mean) / std


class Preprocessor:
    """Band-pass filter + z-score with the training statistics; offline (zero-phase) or causal and streaming.

    Parameters
    ----------
    fs : float
        Sampling frequency (Hz).
    band : (float or None, float or None)
        Pass band (Hz); edges below ``fs / 2``; ``None`` for a one-sided (high- or low-pass) filter.
    order : int
        Butterworth order.
    zero_phase : bool
        ``True``: :meth:`fit` and :meth:`transform` filter forward-backward (``sosfiltfilt``; offline only).
        ``False``: causal forward filtering (``sosfilt``), the same as streaming with :meth:`step`.

    Attributes
    ----------
    sos_ : ndarray (n_sections, 6)
        The filter's second-order sections.
    mean_, std_ : ndarray (n_channels,)
        Per-channel mean and standard deviation of the *filtered* training data (channel units).
    n_channels_ : int

    Notes
    -----
    Causal filtering (batch and streaming) starts from the filter's steady state for a constant input equal to
    the first sample (``sosfilt_zi`` scaled by it), so a large sensor offset does not ring through the
    band-pass at start-up. With ``zero_phase=False``, ``transform(Y)`` equals ``[step(y) for y in Y]`` after
    :meth:`reset` to round-off.

    :meth:`step` is always causal. If the model was fitted with ``zero_phase=True`` the streaming output is
    scaled with zero-phase statistics (the squared magnitude response gives a slightly smaller variance); fit
    with ``zero_phase=False`` when an online estimator must see exactly the training distribution.

    Missing data in :meth:`step`: a NaN channel returns NaN and its filter state is held (not updated) until it
    comes back, so a dropout does not poison the filter; the other channels are unaffected.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> Y = rng.standard_normal((2000, 3))
    >>> pre = Preprocessor(fs=80.0, zero_phase=False).fit(Y)
    >>> Z = pre.transform(Y)
    >>> pre.reset()
    >>> Zs = np.array([pre.step(y) for y in Y])
    >>> bool(np.allclose(Z, Zs))
    True
    """

    def __init__(
        self,
        fs: float,
        band: tuple[float | None, float | None] = (0.25, 5.0),
        order: int = 4,
        zero_phase: bool = True,
    ) -> None:
        self.fs = fs
        self.band = band
        self.order = order
        self.zero_phase = zero_phase

    # ------------------------------------------------------------------ batch
    def _filter(self, Y: np.ndarray, name: str) -> np.ndarray:
        return _zero_phase(self.sos_, Y, name) if self.zero_phase else _causal(self.sos_, Y)

    def fit(self, Y: object) -> Preprocessor:
        """Learn the filter and the per-channel statistics of the filtered training data.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels) or list of such records
            Raw training data (finite). Records are filtered separately; statistics pool all of them.

        Returns
        -------
        self
        """
        self.sos_ = band_sos(self.fs, self.band, self.order)
        records = as_records(Y, "Y", min_samples=2, max_abs=MAX_ABS)
        for i, rec in enumerate(records):
            check_no_constant_channels(rec, "Y" if len(records) == 1 else f"Y[{i}]")
        F = np.concatenate([self._filter(rec, "Y") for rec in records], axis=0)
        self.mean_, self.std_ = _zscore_stats(F, "Y")
        self.n_channels_ = F.shape[1]
        return self

    def transform(self, Y: object) -> np.ndarray | list[np.ndarray]:
        """Filter (each record separately) and z-score with the training statistics.

        Parameters
        ----------
        Y : array_like (n_samples, n_channels) or list of records
            Raw data (finite), same channels as in :meth:`fit`.

        Returns
        -------
        ndarray (n_samples, n_channels) or list of them (dimensionless)
        """
        check_fitted(self, "mean_")
        records = as_records(Y, "Y", min_samples=1, n_channels=self.n_channels_, max_abs=MAX_ABS)
        out = [(self._filter(rec, "Y") - self.mean_) / self.std_ for rec in records]
        return out if is_record_list(Y) else out[0]

    def fit_transform(self, Y: object) -> np.ndarray | list[np.ndarray]:
        """:meth:`fit` then :meth:`transform` on the same data."""
        return self.fit(Y).transform(Y)

    def inverse_scale(self, Z: object) -> np.ndarray:
        """Undo the z-score: ``Z * std_ + mean_`` (back to filtered channel units; the filter is not undone).

        Parameters
        ----------
        Z : array_like (..., n_channels)

        Returns
        -------
        ndarray, same shape
        """
        check_fitted(self, "mean_")
        Z = np.asarray(Z, dtype=float)
        if Z.ndim < 1 or Z.shape[-1] != self.n_channels_:
            raise ValueError(f"Z must have {self.n_channels_} channels in its last axis, got shape {Z.shape}")
        return Z * self.std_ + self.mean_

    # -------------------------------------------------------------- streaming
    def reset(self) -> None:
        """Start a new stream: the filter state is initialised from the next sample given to :meth:`step`."""
        check_fitted(self, "mean_")
        self._zi: np.ndarray | None = None
        self._zi_unit = signal.sosfilt_zi(self.sos_)

    def step(self, y: object) -> np.ndarray:
        """Filter and z-score one sample causally, carrying the filter state.

        Parameters
        ----------
        y : array_like (n_channels,)
            Raw sample in channel units; NaN marks a missing channel (its output is NaN and its state held).

        Returns
        -------
        ndarray (n_channels,)
            z-scored, band-passed sample (dimensionless).
        """
        if not hasattr(self, "_zi"):
            self.reset()
        y = np.asarray(y, dtype=float)
        if y.shape != (self.n_channels_,):
            raise ValueError(f"y must have shape ({self.n_channels_},), got {y.shape}")
        if np.isinf(y).any():
            raise ValueError(f"y must not hold ±inf: channels {np.flatnonzero(np.isinf(y)).tolist()}")
        ok = np.isfinite(y)
        if self._zi is None:
            self._zi = self._zi_unit[:, :, None] * np.where(ok, y, 0.0)[None, None, :]
            self._started = ok.copy()
        elif not self._started.all():
            new = ok & ~self._started  # a channel seen for the first time: steady state from its first value
            if new.any():
                self._zi[:, :, new] = self._zi_unit[:, :, None] * y[new][None, None, :]
                self._started |= new
        out = np.full(self.n_channels_, np.nan)
        if ok.all():
            z, self._zi = signal.sosfilt(self.sos_, y[None, :], axis=0, zi=self._zi)
            out = z[0]
        elif ok.any():
            z, zi = signal.sosfilt(self.sos_, y[None, ok], axis=0, zi=self._zi[:, :, ok])
            self._zi[:, :, ok] = zi
            out[ok] = z[0]
        return (out - self.mean_) / self.std_
