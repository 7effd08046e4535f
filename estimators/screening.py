"""Sensor fault screening shared by every virtual sensor: flat-lined (stuck) and spiking channels that still
report live are taken out of the estimate, and said so.

A sensor's mask says which channels *claim* to be available; a stuck accelerometer or a wild sample claims it too.
:class:`FaultScreen` learns from the training data what each channel normally does, then, sample by sample and
causally, rejects a live value that

* **flat-lines**: the channel has repeated the same value (to ``1e-9`` of its training spread) for more than
  ``flat_samples`` samples and for more than twice the longest such run seen in training (a quantised, slowly
  varying channel is allowed the runs it had in training);
* **jumps** (a spike): it is further from the last accepted value of the channel than ``spike_factor`` times the
  largest sample-to-sample change seen in training, times the number of samples since that accepted value (a
  channel back from a dropout may have moved); a spike lasting more than ``spike_samples`` samples is a new level,
  not a spike, and is accepted from then on;
* **leaves the range**: it is further from the training median than ``range_factor`` times the largest training
  excursion (this catches 1e307 and anything else no structure does, whatever the filter's state).

Every test is a comparison of differences that may overflow to ``inf`` but never to NaN, so no finite input can
turn the screen or the estimate behind it into NaN. The model-based sensors add their innovation gate on top and
report it in the same counters (reason ``"innovation"``).

Examples
--------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> screen = FaultScreen().fit([rng.standard_normal((2000, 2))])
>>> for k in range(30):
...     ok = screen.screen(np.array([0.5, rng.standard_normal()]), np.array([True, True]))
>>> ok.tolist(), screen.counts_["flat"].tolist()  # 29 repeats of 0.5, the 10th and later are rejected
([False, True], [20, 0])
>>> screen.screen(np.array([np.nan, 1e307]), np.array([True, True])).tolist(), screen.reasons_
([False, False], ['', 'range'])
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .validation import check_int, check_number

__all__ = ["FaultScreen", "REASONS", "make_screen"]

REASONS = ("flat", "spike", "range", "innovation")
"""Why a live channel value was rejected: stuck (flat-lined), a jump, out of range, or the filter's innovation
gate (model-based sensors only)."""


class FaultScreen:
    """Causal, per-channel rejection of stuck, spiking and out-of-range live values.

    Parameters
    ----------
    flat_samples : int
        Shortest run of repeated values (samples) read as a stuck sensor; the learned threshold is the larger of
        this and twice the longest run in training, plus one.
    spike_factor : float
        Allowed jump from the last accepted value, in units of the largest training sample-to-sample change
        (times the samples since that value).
    spike_samples : int
        A jump held for more than this many samples is accepted as a new level.
    range_factor : float
        Allowed distance from the training median, in units of the largest training excursion from it.
    active : bool
        False: reject nothing (only :meth:`note` records a filter's own rejections).

    Attributes
    ----------
    n_channels_ : int
    center_, excursion_, max_step_ : ndarray (n_channels,)
        Training median, largest distance from it, largest sample-to-sample change (channel units).
    flat_limit_ : ndarray of int (n_channels,)
        Repeats after which a channel counts as stuck.
    rejected_ : ndarray of bool (n_channels,)
        Channels rejected at the latest sample (by the screen or, via :meth:`note`, by a filter's gate).
    reasons_ : list of str
        Why, for each channel of :attr:`rejected_` (``""`` if accepted).
    counts_ : dict of str to ndarray of int (n_channels,)
        Rejected samples per channel since :meth:`reset`, by reason (keys :data:`REASONS`).
    """

    def __init__(self, flat_samples: int = 10, spike_factor: float = 10.0, spike_samples: int = 40,
                 range_factor: float = 10.0, active: bool = True) -> None:
        self.flat_samples = flat_samples
        self.spike_factor = spike_factor
        self.spike_samples = spike_samples
        self.range_factor = range_factor
        self.active = active

    def fit(self, records: Sequence[np.ndarray]) -> FaultScreen:
        """Learn each channel's normal behaviour from training records (NaN = missing, ignored).

        Parameters
        ----------
        records : sequence of ndarray (n_samples, n_channels)

        Returns
        -------
        self
        """
        check_int("flat_samples", self.flat_samples, minimum=2)
        check_number("spike_factor", self.spike_factor, positive=True)
        check_int("spike_samples", self.spike_samples, minimum=1)
        check_number("range_factor", self.range_factor, positive=True)
        records = [np.asarray(r, dtype=np.float64) for r in records]
        n_ch = records[0].shape[1]
        stacked = np.vstack(records)
        with np.errstate(invalid="ignore", over="ignore"):
            finite_any = np.isfinite(stacked).any(axis=0)
            center = np.zeros(n_ch)
            if finite_any.any():
                center[finite_any] = np.nanmedian(stacked[:, finite_any], axis=0)
            excursion = np.nanmax(np.where(np.isfinite(stacked), np.abs(stacked - center), -np.inf), axis=0)
            steps = [np.abs(np.diff(r, axis=0)) for r in records if r.shape[0] > 1]
            max_step = (np.max([np.nanmax(np.where(np.isfinite(s), s, -np.inf), axis=0) for s in steps], axis=0)
                        if steps else np.full(n_ch, -np.inf))
        excursion = np.where(np.isfinite(excursion) & (excursion > 0), excursion, np.inf)  # unknown: no range test
        max_step = np.where(np.isfinite(max_step) & (max_step > 0), max_step, np.inf)
        tol = 1e-9 * np.where(np.isfinite(excursion), excursion, 0.0)
        longest = np.zeros(n_ch, dtype=np.int64)
        for r in records:
            longest = np.maximum(longest, _longest_repeat(r, tol))
        self.n_channels_ = n_ch
        self.center_, self.excursion_, self.max_step_ = center, excursion, max_step
        self._tol = tol
        self.flat_limit_ = np.maximum(int(self.flat_samples), 2 * longest + 1)
        self.reset()
        return self

    def reset(self) -> None:
        """Start a new stream: no history, counters to zero."""
        n = self.n_channels_
        self._prev = np.full(n, np.nan)  # previous live value (for repeats)
        self._run = np.zeros(n, dtype=np.int64)  # repeats of the previous value so far
        self._ref = np.full(n, np.nan)  # last accepted value
        self._since = np.zeros(n, dtype=np.int64)  # samples since the last accepted value
        self._jumped = np.zeros(n, dtype=np.int64)  # consecutive samples rejected as a jump
        self.rejected_ = np.zeros(n, dtype=bool)
        self.reasons_ = [""] * n
        self.counts_ = {reason: np.zeros(n, dtype=np.int64) for reason in REASONS}

    def screen(self, y: np.ndarray, live: np.ndarray) -> np.ndarray:
        """The live channels of one sample that pass the screen.

        Parameters
        ----------
        y : ndarray (n_channels,)
            The sample (channel units; anything where not live).
        live : ndarray of bool (n_channels,)
            Channels reported available with a finite value.

        Returns
        -------
        ndarray of bool (n_channels,)
            ``live`` without the rejected channels (listed in :attr:`rejected_`, counted in :attr:`counts_`).
        """
        live = np.asarray(live, dtype=bool) & ~np.isnan(y)
        if not self.active:
            self.rejected_ = np.zeros(self.n_channels_, dtype=bool)
            self.reasons_ = [""] * self.n_channels_
            return live
        yv = np.where(live, y, np.nan)
        with np.errstate(over="ignore", invalid="ignore"):
            same = live & (np.abs(yv - self._prev) <= self._tol)
            self._run = np.where(same, self._run + 1, 0)
            self._prev = np.where(live, yv, self._prev)
            flat = live & (self._run >= self.flat_limit_)
            out_of_range = live & ~flat & (np.abs(yv - self.center_) > self.range_factor * self.excursion_)
            self._since += 1
            allowed = self.spike_factor * self.max_step_ * self._since
            has_ref = ~np.isnan(self._ref)
            jump = live & ~flat & ~out_of_range & has_ref & (np.abs(yv - self._ref) > allowed)
        self._jumped = np.where(jump, self._jumped + 1, 0)
        new_level = jump & (self._jumped > int(self.spike_samples))
        jump &= ~new_level
        ok = live & ~flat & ~out_of_range & ~jump
        self._ref = np.where(ok, yv, self._ref)
        self._since = np.where(ok, 0, self._since)
        self._jumped = np.where(ok, 0, self._jumped)
        self.rejected_ = flat | out_of_range | jump
        self.reasons_ = ["flat" if f else "range" if r else "spike" if j else ""
                         for f, r, j in zip(flat, out_of_range, jump, strict=True)]
        self.counts_["flat"] += flat
        self.counts_["range"] += out_of_range
        self.counts_["spike"] += jump
        return ok

    def screen_block(self, Y: np.ndarray, live: np.ndarray) -> np.ndarray:
        """:meth:`screen` of every row of a record in turn (after a :meth:`reset`); the rows' rejections are kept
        in ``rejected_samples_`` (n_samples, n_channels)."""
        self.reset()
        out = np.zeros(np.shape(live), dtype=bool)
        rejected = np.zeros(np.shape(live), dtype=bool)
        for k in range(out.shape[0]):
            out[k] = self.screen(Y[k], live[k])
            rejected[k] = self.rejected_
        self.rejected_samples_ = rejected
        return out

    def note(self, channels: np.ndarray, reason: str = "innovation") -> None:
        """Record channels a filter rejected after the screen at the latest sample (its innovation gate)."""
        channels = np.asarray(channels, dtype=np.int64)
        if channels.size:
            self.rejected_[channels] = True
            for c in channels:
                self.reasons_[int(c)] = reason
            np.add.at(self.counts_[reason], channels, 1)


def _longest_repeat(Y: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """Longest run, per channel, of consecutive finite samples repeating the previous one within ``tol``."""
    n, n_ch = Y.shape
    if n < 2:
        return np.zeros(n_ch, dtype=np.int64)
    with np.errstate(invalid="ignore", over="ignore"):
        same = np.abs(np.diff(Y, axis=0)) <= tol
    out = np.zeros(n_ch, dtype=np.int64)
    for c in np.flatnonzero(same.any(axis=0)):
        edges = np.flatnonzero(np.diff(np.r_[0, same[:, c].astype(np.int8), 0]))
        out[c] = int((edges[1::2] - edges[::2]).max())
    return out


def make_screen(spec: object, records: Sequence[np.ndarray]) -> FaultScreen:
    """A fitted screen from a sensor's ``screen`` argument: True (defaults), False (inactive) or a
    :class:`FaultScreen` (its settings; a fitted copy is returned, the argument is left as it is)."""
    if isinstance(spec, FaultScreen):
        screen = FaultScreen(spec.flat_samples, spec.spike_factor, spec.spike_samples, spec.range_factor,
                             spec.active)
    elif spec is True or spec is False:
        screen = FaultScreen(active=bool(spec))
    else:
        raise ValueError(f"screen must be True, False or an estimators.FaultScreen, got {spec!r}")
    return screen.fit(records)
