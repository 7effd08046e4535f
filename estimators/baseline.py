"""Trivial virtual sensors: the floor any estimator must beat, and the proof of the sensor protocol.

The virtual-sensor protocol (used by ``fowt_env.VirtualSensorWrapper``)::

    sensor.fit(Y_train, mask=None) -> sensor     # optional learning from a record (n_samples, n_channels)
    sensor.reset()                               # start of a new stream
    sensor.update(y, mask) -> estimate           # one sample in (NaN/any value where mask is False), full vector out
    sensor.reconstruct(Y, mask) -> Y_hat         # a whole record, same as streaming update() sample by sample
"""

from __future__ import annotations

import numpy as np

from .screening import FaultScreen, make_screen
from .validation import MAX_ABS, apply_masks, as_records, as_sample

__all__ = ["HoldLastValue"]


class HoldLastValue:
    """Estimate a lost channel by its last available value (0.0 if it was never seen, or the training mean).

    Parameters
    ----------
    fill : {"auto", "zero", "mean"}
        What to report for a channel lost since the start of a stream: its mean in the training data
        (``"mean"``, needs :meth:`fit`), 0.0 (``"zero"``), or ``"auto"`` (default): the training mean once
        fitted, else 0.0. (0.0 for a tower-base moment of 5e4 kN m is a poor floor: fit it.)
    screen : bool or FaultScreen
        Once fitted, live values go through the fault screen shared by every sensor
        (:class:`estimators.screening.FaultScreen`): a stuck, spiking or out-of-range live channel holds its last
        good value instead of passing the fault through (``screen_.rejected_`` says which). False: off.

    Examples
    --------
    >>> import numpy as np
    >>> s = HoldLastValue()
    >>> s.reset()
    >>> s.update(np.array([1.0, 2.0]), np.array([True, True]))
    array([1., 2.])
    >>> s.update(np.array([5.0, np.nan]), np.array([True, False]))
    array([5., 2.])
    """

    def __init__(self, fill: str = "auto", screen: bool | FaultScreen = True) -> None:
        self.fill = fill
        self.screen = screen

    def fit(self, Y: object, mask: object = None) -> HoldLastValue:
        """Learn the per-channel mean of the available training data (for ``fill="mean"``).

        Parameters
        ----------
        Y : array_like (n_samples, n_channels) or list of such records
            Training data (channel units); NaN marks missing samples.
        mask : array_like of bool or list of them, optional
            False marks further missing samples: one mask for all records or one per record, each of the
            record's shape or ``(n_channels,)`` (:func:`estimators.validation.apply_masks`).

        Returns
        -------
        self
        """
        records = apply_masks(as_records(Y, "Y", allow_nan=True, min_samples=1, max_abs=MAX_ABS), mask)
        self.screen_ = make_screen(self.screen, records)
        Y = np.concatenate(records, axis=0)
        m = np.isfinite(Y)
        counts = m.sum(axis=0)
        self.mean_ = np.where(counts > 0, np.where(m, Y, 0.0).sum(axis=0) / np.maximum(counts, 1), 0.0)
        self.n_channels_ = Y.shape[1]
        return self

    def reset(self) -> None:
        """Forget the held values."""
        self._last: np.ndarray | None = None
        if hasattr(self, "screen_"):
            self.screen_.reset()

    def update(self, y: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """One sample: available channels pass through, lost ones keep their last available value.

        Parameters
        ----------
        y : ndarray (n_channels,)
            Measured values (ignored where ``mask`` is False; NaN there is fine).
        mask : ndarray of bool (n_channels,), optional
            True = available (default: the finite entries of y). A NaN where mask is True is a dropout.

        Returns
        -------
        ndarray (n_channels,)
        """
        y, mask = as_sample(y, mask)
        if mask is None:
            mask = np.isfinite(y)
        if not hasattr(self, "_last"):
            self.reset()
        expected = self._last.size if self._last is not None else getattr(self, "n_channels_", None)
        if expected is not None and y.size != expected:
            raise ValueError(f"y must have shape ({expected},) (the channels of this stream/training data), "
                             f"got {y.shape}")
        if self._last is None:
            if self.fill not in ("auto", "zero", "mean"):
                raise ValueError(f"fill must be 'auto', 'zero' or 'mean', got {self.fill!r}")
            if self.fill == "mean" and not hasattr(self, "mean_"):
                raise ValueError("fill='mean' needs fit() first")
            if self.fill != "zero" and hasattr(self, "mean_"):
                self._last = self.mean_.astype(float).copy()
            else:
                self._last = np.zeros(y.size)
        ok = mask & np.isfinite(y)
        if hasattr(self, "screen_"):  # fitted: hold the last value that passed the fault screen
            ok = self.screen_.screen(np.where(ok, y, np.nan), ok)
        self._last[ok] = y[ok]
        return self._last.copy()

    def reconstruct(self, Y: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """A whole record (n_samples, n_channels), identical to streaming :meth:`update`.

        ``mask`` (n_samples, n_channels) or (n_channels,): True = available; default the finite entries of ``Y``.
        """
        Y = np.asarray(Y, dtype=float)
        if Y.ndim != 2:
            raise ValueError(f"Y must be 2-D (n_samples, n_channels), got shape {Y.shape}")
        mask = np.isfinite(Y) if mask is None else np.asarray(mask, dtype=bool)
        if mask.shape not in (Y.shape, Y.shape[1:]):
            raise ValueError(f"mask must have the shape of Y {Y.shape} or ({Y.shape[1]},), got {mask.shape}")
        mask = np.broadcast_to(mask, Y.shape)
        self.reset()
        out = np.empty_like(Y)
        rejected = np.zeros(Y.shape, dtype=bool)
        for k, (y, m) in enumerate(zip(Y, mask, strict=True)):
            out[k] = self.update(y, m)
            rejected[k] = self.rejected_
        self.rejected_samples_ = rejected
        return out

    @property
    def rejected_(self) -> np.ndarray:
        """Live channels the fault screen rejected at the latest sample (none before :meth:`fit`)."""
        if hasattr(self, "screen_"):
            return self.screen_.rejected_.copy()
        return np.zeros(self._last.size if getattr(self, "_last", None) is not None else 0, dtype=bool)
