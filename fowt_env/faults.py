"""Sensor faults for the environment: dropouts (mask False) and silent corruptions (mask stays True).

Every fault follows one small protocol::

    fault.reset(rng, channels, dt)      # at env.reset, with a Generator derived from the env's np_random
    fault.apply(step, y, mask)          # per sample, in place on the measured vector and its mask

Faults compose: a list is applied in order. They see only the *measured* vector -- the env's
``info["truth"]`` is never touched. Dropout faults clear the mask (the env then reports 0.0 for that channel);
``Stuck``, ``Spike``, ``Drift`` and ``NoiseBurst`` corrupt values while the mask still says "available", as an
undetected sensor fault would.

The paper's scenarios (Abaei et al., Table 6) are fixed masks on the 18-channel fore-aft plane (sensors 0-8:
accelerations at gauges 1-9, 9-17: bending moments at gauges 1-9): A hides 2, 3, 5, 7, 11, 12, 14, 16; B and C
hide 0, 8, 9, 17 (they differ in their load case, OLC 7 and OLC 2; A was run on OLC 5).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "Fault",
    "RandomDropout",
    "Scenario",
    "FixedMask",
    "Stuck",
    "Spike",
    "Drift",
    "NoiseBurst",
    "SCENARIOS",
    "as_fault_list",
]

SCENARIOS: dict[str, dict] = {
    "A": {"hidden": (2, 3, 5, 7, 11, 12, 14, 16), "olc": 5,
          "description": "massive failure: 8 sensors along the tower"},
    "B": {"hidden": (0, 8, 9, 17), "olc": 7, "description": "boundary loss: tower base and top"},
    "C": {"hidden": (0, 8, 9, 17), "olc": 2, "description": "boundary loss in low waves"},
}


class Fault:
    """Base class: a fault that does nothing. Subclasses override :meth:`reset` and :meth:`apply`."""

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        """Prepare for a new episode.

        Parameters
        ----------
        rng : numpy.random.Generator
            This fault's own random stream (derived from the env's ``np_random``).
        channels : sequence of str
            Names of the observed channels.
        dt : float
            Sample time (s).
        """
        self.rng = rng
        self.channels = list(channels)
        self.dt = float(dt)

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        """Corrupt the measured vector ``y`` and/or clear ``mask`` in place for sample number ``step``."""

    def _indices(self, chans: Sequence[str | int] | None) -> np.ndarray:
        if chans is None:
            return np.arange(len(self.channels))
        idx = []
        for c in chans:
            if isinstance(c, (int, np.integer)) and not isinstance(c, bool):
                if not 0 <= int(c) < len(self.channels):
                    raise ValueError(f"channels: index {c} out of range for {len(self.channels)} channels")
                idx.append(int(c))
            elif c in self.channels:
                idx.append(self.channels.index(c))
            else:
                raise ValueError(f"channels: unknown channel {c!r}; observed channels are {self.channels}")
        return np.array(idx, dtype=int)

    def __repr__(self) -> str:
        fields = ", ".join(f"{k}={v!r}" for k, v in vars(self).items() if not k.startswith("_") and k not in
                           ("rng", "channels", "dt"))
        return f"{type(self).__name__}({fields})"


def _check(name: str, value: float, lo: float | None = None, hi: float | None = None, open_lo: bool = False) -> float:
    v = float(value)
    if not np.isfinite(v) or (lo is not None and (v <= lo if open_lo else v < lo)) or (hi is not None and v > hi):
        raise ValueError(f"{name} must be finite and in range, got {value!r}")
    return v


class RandomDropout(Fault):
    """Per-channel two-state Markov dropouts with a given long-run rate and mean burst length.

    Each channel is independently "up" or "down"; per sample it goes down with probability ``p`` and comes back
    with probability ``q = dt / mean_burst_s``, where ``p = rate q / (1 - rate)`` makes the stationary down
    fraction equal ``rate``. Episodes start in the stationary distribution.

    Parameters
    ----------
    rate : float
        Long-run fraction of samples lost per channel, 0 <= rate < 1.
    mean_burst_s : float
        Mean length of a dropout (s), at least one sample.
    channels : sequence of str or int, optional
        Channels that can drop (default all).
    """

    def __init__(self, rate: float, mean_burst_s: float, channels: Sequence[str | int] | None = None) -> None:
        self.rate = _check("rate", rate, 0.0, 1.0)
        if self.rate >= 1.0:
            raise ValueError("rate must be < 1 (all sensors permanently lost is FixedMask)")
        self.mean_burst_s = _check("mean_burst_s", mean_burst_s, 0.0, open_lo=True)
        self.which = None if channels is None else list(channels)

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        super().reset(rng, channels, dt)
        self._idx = self._indices(self.which)
        self._q = min(1.0, dt / self.mean_burst_s)
        self._p = self.rate * self._q / (1.0 - self.rate) if self.rate > 0 else 0.0
        if self._p > 1.0:
            raise ValueError(f"rate={self.rate} with mean_burst_s={self.mean_burst_s} needs bursts longer than dt")
        self._down = rng.random(self._idx.size) < self.rate

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        u = self.rng.random(self._idx.size)
        self._down = np.where(self._down, u >= self._q, u < self._p)
        mask[self._idx[self._down]] = False


class FixedMask(Fault):
    """Channels permanently lost (mask False) for the whole episode.

    Parameters
    ----------
    hidden : sequence of str or int, or boolean array
        Names or indices of lost channels, or a boolean availability mask (True = available).
    """

    def __init__(self, hidden: Sequence[str | int] | np.ndarray) -> None:
        arr = np.asarray(hidden)
        self.hidden = arr.copy() if arr.dtype == bool else list(hidden)

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        super().reset(rng, channels, dt)
        if isinstance(self.hidden, np.ndarray):
            if self.hidden.shape != (len(self.channels),):
                raise ValueError(f"hidden: a boolean mask needs shape ({len(self.channels)},), got {self.hidden.shape}")
            self._idx = np.nonzero(~self.hidden)[0]
        else:
            self._idx = self._indices(self.hidden)

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        mask[self._idx] = False


class Scenario(FixedMask):
    """The paper's virtual-sensing scenarios (Table 6) as fixed masks on the fore-aft plane.

    Parameters
    ----------
    name : {"A", "B", "C"}
        A hides FA-plane sensors 2, 3, 5, 7, 11, 12, 14, 16; B and C hide 0, 8, 9, 17. Indices refer to the
        18-channel FA order (accelerations at gauges 1-9, then moments at gauges 1-9) and are matched by name,
        so the scenario works on any observed channel set that contains them.
    """

    def __init__(self, name: str) -> None:
        if name not in SCENARIOS:
            raise ValueError(f"name: unknown scenario {name!r}; choose from {sorted(SCENARIOS)}")
        from surrogates.channels import tower_channels

        self.name = name
        fa = tower_channels("FA")
        super().__init__([fa[i] for i in SCENARIOS[name]["hidden"]])

    @property
    def olc(self) -> int:
        """The load case the paper ran this scenario on."""
        return int(SCENARIOS[self.name]["olc"])


class _Window(Fault):
    """A fault active on some channels from ``start`` (s) for ``duration`` (s, None = to the end)."""

    def __init__(self, channels: Sequence[str | int], start: float = 0.0, duration: float | None = None) -> None:
        self.which = list(channels)
        self.start = _check("start", start, 0.0)
        self.duration = None if duration is None else _check("duration", duration, 0.0, open_lo=True)

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        super().reset(rng, channels, dt)
        self._idx = self._indices(self.which)
        self._k0 = int(round(self.start / dt))
        self._k1 = None if self.duration is None else self._k0 + int(round(self.duration / dt))

    def _active(self, step: int) -> bool:
        return step >= self._k0 and (self._k1 is None or step < self._k1)


class Stuck(_Window):
    """Channels freeze at the value they had when the fault started (or at ``value``); mask stays True."""

    def __init__(self, channels: Sequence[str | int], start: float = 0.0, duration: float | None = None,
                 value: float | None = None) -> None:
        super().__init__(channels, start, duration)
        self.value = None if value is None else _check("value", value)

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        super().reset(rng, channels, dt)
        self._held: np.ndarray | None = None

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        if not self._active(step):
            self._held = None
            return
        if self._held is None:
            self._held = np.full(self._idx.size, self.value) if self.value is not None else y[self._idx].copy()
        y[self._idx] = self._held


class Spike(Fault):
    """Random isolated spikes: each sample of each channel is hit with probability ``rate`` by +-amplitude.

    Parameters
    ----------
    rate : float
        Probability per sample and channel.
    amplitude : float or sequence
        Spike size per channel in the channel's unit (or one value for all).
    channels : sequence, optional
    """

    def __init__(self, rate: float, amplitude: float | Sequence[float],
                 channels: Sequence[str | int] | None = None) -> None:
        self.rate = _check("rate", rate, 0.0, 1.0)
        self.amplitude = np.atleast_1d(np.asarray(amplitude, dtype=float))
        if not np.all(np.isfinite(self.amplitude)):
            raise ValueError("amplitude must be finite")
        self.which = None if channels is None else list(channels)

    def reset(self, rng: np.random.Generator, channels: Sequence[str], dt: float) -> None:
        super().reset(rng, channels, dt)
        self._idx = self._indices(self.which)
        if self.amplitude.size not in (1, self._idx.size):
            raise ValueError(f"amplitude: need 1 or {self._idx.size} values, got {self.amplitude.size}")

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        hit = self.rng.random(self._idx.size) < self.rate
        if hit.any():
            sign = np.where(self.rng.random(self._idx.size) < 0.5, -1.0, 1.0)
            amp = np.broadcast_to(self.amplitude, (self._idx.size,))
            y[self._idx[hit]] += (sign * amp)[hit]


class Drift(_Window):
    """A linearly growing offset, ``rate`` (channel unit per second) since ``start``; mask stays True."""

    def __init__(self, channels: Sequence[str | int], rate: float, start: float = 0.0,
                 duration: float | None = None) -> None:
        super().__init__(channels, start, duration)
        self.rate = _check("rate", rate)

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        if self._active(step):
            y[self._idx] += self.rate * (step - self._k0) * self.dt


class NoiseBurst(_Window):
    """Extra white noise of standard deviation ``std`` (channel unit) during a window; mask stays True."""

    def __init__(self, channels: Sequence[str | int], std: float, start: float = 0.0,
                 duration: float | None = None) -> None:
        super().__init__(channels, start, duration)
        self.std = _check("std", std, 0.0)

    def apply(self, step: int, y: np.ndarray, mask: np.ndarray) -> None:
        if self._active(step):
            y[self._idx] += self.std * self.rng.standard_normal(self._idx.size)


def as_fault_list(faults: Fault | Sequence[Fault] | None) -> list[Fault]:
    """Normalise the env's ``faults`` argument to a list, checking the types."""
    if faults is None:
        return []
    items = [faults] if isinstance(faults, Fault) else list(faults)
    for f in items:
        if not isinstance(f, Fault):
            raise ValueError(f"faults: expected Fault instances, got {type(f).__name__}")
    return items
