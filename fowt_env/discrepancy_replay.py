"""Discrepancy workflow with replay: compare residual time series under the measured forcing.

The statistical workflow (:mod:`fowt_env.discrepancy`) compares *statistics* of the measurement with the
model's seed-to-seed scatter, so the randomness of the waves and the wind is part of every feature's scatter.
When the record carries its own forcing -- the wave elevation at the spar axis (``Wave1Elev``, m) and the
hub-height wind (``Wind1VelX``, m/s) -- the model can be driven by it instead (:func:`surrogates.simulate` with
``waves=`` and ``wind=``, see :mod:`surrogates.replay` and :func:`fowt_env.replay.record_initial`), and the
measurement compared sample by sample with what the model predicts under the same forcing:

1. **Replay** -- each model setting is simulated once under the record's waves and wind, from the record's first
   sample (platform position and rates, tower-top deflection, rotor speed and azimuth), linearised about the
   record's mean hub wind; the first :data:`REPLAY_TRANSIENT` seconds are discarded (hidden states such as the
   controller's settle).
2. **Features** -- the residual ``r = y - y_hat`` (measured minus replayed) per channel and band (the bands of
   the statistical workflow): ``ln`` of its band power (``<band>_residual``), ``ln`` of the ratio of replayed to
   measured band power (``<band>_ratio``: an amplitude error; kept only where the model's replays of its own
   records carry at least :data:`RATIO_MIN_SHARE` of the band's power -- elsewhere the band is sensor noise or
   unresolved forcing), and the mean residual of the mean channels in units of the measured channel's standard
   deviation (``mean_residual``).
3. **Scatter and null** -- the same features of the model's *own* records (``n_scatter`` seeds of the stochastic
   simulation with its sensor noise, default 16: the residual features have heavier tails than the statistics),
   each replayed from its own ``Wave1Elev`` and ``Wind1VelX``: the residual a correct model leaves when all it
   knows of the forcing is one elevation point and the hub-height wind (unresolved turbulence over the rotor,
   sensor noise, the start-up). Feature rows are handed to the search of
   :mod:`fowt_env.discrepancy` as ``own - measured``, so that its z-scores, gap, null level, acceptance test,
   greedy search, verdicts and intervals apply unchanged (common random numbers: the own records of two model
   settings share their seeds).

Every model setting costs one replay of the measurement plus, per seed, one stochastic simulation and one replay
of it. :func:`run` is reached through :func:`fowt_env.discrepancy.run` with ``replay=True``.

Measured (hidden-truth runs, 20-minute records at 10 Hz; README, "With replay"): the wave-band response under the
record's own waves is known to a fraction of a percent, so an added mass 10 % high is named (1.11, interval
1.01-1.19) where the statistics see nothing; but with only the hub-height wind the unresolved turbulence over the
rotor dominates the residual of the platform band, where the quadratic drag's remainder acts at rated wind: a
missing ``quadratic_drag`` (OLC 7) and a drag coefficient x1.5 (OLC 10) stay below the null level, as they do in
the statistical mode.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

import surrogates
from surrogates import FOWTModel, LoadCase, Record
from surrogates.parameters import ParametricModel, as_parametric
from surrogates.replay import MeasuredWaves, MeasuredWind

from . import discrepancy as _d
from .progress import progress_bar
from .replay import record_initial

__all__ = ["MIN_REPLAY_SECONDS", "RATIO_MIN_SHARE", "REPLAY_CHANNELS", "REPLAY_TRANSIENT", "check_forcing",
           "replay_features", "replay_model", "run"]

REPLAY_CHANNELS: tuple[str, ...] = ("Wave1Elev", "Wind1VelX")
"""The forcing a record must carry for replay mode: wave elevation at the spar axis (m), hub-height wind (m/s)."""

REPLAY_TRANSIENT = 60.0
"""Start-up of every replay discarded before the residual is formed (s)."""

RATIO_MIN_SHARE = 0.1
"""A power-ratio feature is kept where the candidate model's replays of its own records carry at least this
share of the band's measured power (median over its seeds): where they carry less, the band of that channel is
sensor noise or unresolved forcing, and the ratio of a noise-free replay to it is a heavy-tailed nuisance."""

MIN_REPLAY_SECONDS = 120.0
"""Shortest residual window (s): the platform band needs a few of its periods."""


def check_forcing(record: Record) -> None:
    """Raise a ValueError naming the forcing channel (:data:`REPLAY_CHANNELS`) the record lacks or has gaps in."""
    missing = [c for c in REPLAY_CHANNELS if c not in record.channels]
    if missing:
        what = {"Wave1Elev": "the wave elevation at the spar axis, m", "Wind1VelX": "the hub-height wind, m/s"}
        raise ValueError("replay=True needs the record's own forcing; the measured record lacks "
                         + ", ".join(f"{c} ({what[c]})" for c in missing))
    for c in REPLAY_CHANNELS:
        x = np.asarray(record[c], float)
        if not np.all(np.isfinite(x)):
            raise ValueError(f"replay=True: the measured record's {c} holds NaN or inf; fill or cut the gaps "
                             "before replaying")


def replay_model(model: FOWTModel, record: Record, case: LoadCase, transient: float = REPLAY_TRANSIENT) -> Record:
    """Simulate ``model`` under the record's own waves and wind (noise-free).

    Parameters
    ----------
    model : FOWTModel
        The model to replay.
    record : Record
        A record with ``Wave1Elev`` (m) and ``Wind1VelX`` (m/s), uniformly sampled.
    case : LoadCase
        Its conditions; the wind speed (the linearisation point) is replaced by the record's mean ``Wind1VelX``.
    transient : float
        Start-up discarded (s).

    Returns
    -------
    Record
        Sampled as the record, time stamps on its axis from ``record.t[0] + transient``.

    Raises
    ------
    ValueError
        A missing or non-finite forcing channel.
    """
    check_forcing(record)
    wind_mean = float(np.mean(record["Wind1VelX"]))
    lc = case.replace(wind_speed=wind_mean) if case.wind_speed > 0 else case
    waves = MeasuredWaves.from_record(record) if case.hs > 0 else None
    wind = MeasuredWind.from_record(record) if case.wind_speed > 0 else None
    if waves is None and wind is None:
        raise ValueError("replay=True: the load case has neither waves (hs = 0) nor wind (wind_speed = 0): there "
                         "is no forcing to replay")
    init = record_initial(record)
    if case.wind_speed <= 0:
        init.pop("RotSpeed", None)
        init.pop("Azimuth", None)
    out = surrogates.simulate(model, lc, duration=None, dt=record.dt, seed=0, transient=transient, noise=False,
                              initial=init, waves=waves, wind=wind)
    assert isinstance(out, Record)
    return out


def _band_powers(x: NDArray[np.float64], fs: float, bands: Sequence[tuple[float, float]]) -> NDArray[np.float64]:
    """Mean square of ``x`` (its mean removed) in each band, by Parseval over the FFT bins ``lo <= f <= hi``
    (the power of :func:`fowt_env.replay.band_pass`'s output)."""
    n = x.size
    spec = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(n, 1.0 / fs)
    p = 2.0 * np.abs(spec) ** 2 / n**2
    if n % 2 == 0:
        p[-1] *= 0.5
    return np.array([float(np.sum(p[(f >= lo) & (f <= hi) & (f > 0)])) for lo, hi in bands])


def replay_features(record: Record, replayed: Record, case: LoadCase,
                    channels: Sequence[str] = _d.DEFAULT_CHANNELS) -> _d.FeatureSet:
    """Residual features of a record against its replay (see the module docstring).

    Parameters
    ----------
    record : Record
        The measurement (or one of the model's own records).
    replayed : Record
        :func:`replay_model`'s output for it (a sub-span of its time axis, same sample time).
    case : LoadCase
        For the bands (wave band, rotor harmonics).
    channels : sequence of str
        Channels of the band features.

    Returns
    -------
    FeatureSet
        ``<channel>:<band>_residual`` (ln of the residual's band power, ln of the channel's unit squared),
        ``<channel>:<band>_ratio`` (ln of replayed over measured band power, -) and ``<channel>:mean_residual``
        (mean residual over the measured standard deviation, -).

    Raises
    ------
    ValueError
        Missing channels, time axes that do not match, a window shorter than :data:`MIN_REPLAY_SECONDS`.
    """
    needed = list(dict.fromkeys([*channels, *_d.MEAN_CHANNELS]))
    missing = [c for c in needed if c not in record.channels]
    if missing:
        raise ValueError(f"measured record lacks channels the replay features need: {missing}")
    t = np.asarray(replayed.t, float)
    i0 = int(np.searchsorted(record.t, t[0] - 0.25 * record.dt))
    n = t.size
    if i0 + n > record.n_samples or np.max(np.abs(record.t[i0:i0 + n] - t)) > 0.01 * record.dt:
        raise ValueError("the replay's time axis does not match the record's (replay_model's output expected)")
    if n * record.dt < MIN_REPLAY_SECONDS:
        raise ValueError(f"the replayed window is {n * record.dt:.0f} s; replay mode needs at least "
                         f"{MIN_REPLAY_SECONDS:.0f} s after the {REPLAY_TRANSIENT:.0f} s start-up")
    bands = _d._bands(case)
    fs = 1.0 / record.dt
    names: list[str] = []
    vals: list[float] = []
    kinds: list[str] = []
    for ch in channels:
        y = np.asarray(record[ch][i0:i0 + n], float)
        y = np.where(np.isfinite(y), y, np.nanmean(y))
        m = np.asarray(replayed[ch], float)
        p_y = _band_powers(y, fs, list(bands.values()))
        p_m = _band_powers(m, fs, list(bands.values()))
        p_r = _band_powers(y - m, fs, list(bands.values()))
        for j, band in enumerate(bands):
            names += [f"{ch}:{band}_residual", f"{ch}:{band}_ratio"]
            vals += [math.log(max(p_r[j], 1e-30)), math.log(max(p_m[j], 1e-30) / max(p_y[j], 1e-30))]
            kinds += ["log_residual", "log_ratio"]
    for ch in _d.MEAN_CHANNELS:
        y = np.asarray(record[ch][i0:i0 + n], float)
        r = np.nanmean(y - np.asarray(replayed[ch], float))
        names.append(f"{ch}:mean_residual")
        vals.append(float(r / max(float(np.nanstd(y)), 1e-12)))
        kinds.append("mean_residual")
    return _d.FeatureSet(tuple(names), np.array(vals), tuple(kinds))


class _ReplayEvaluator:
    """:class:`fowt_env.discrepancy._Evaluator`'s interface for replay mode: ``rows(model, seeds)`` are the
    residual features of the model's own records (replayed from their own forcing) minus those of the
    measurement replayed by the same model (cached per model setting and seed)."""

    def __init__(self, measured: Record, case: LoadCase, channels: Sequence[str], bar: Any):
        self.measured, self.case, self.channels, self.bar = measured, case, channels, bar
        self.duration = measured.duration + measured.dt
        self.own: dict[tuple, np.ndarray] = {}
        self.meas: dict[tuple, _d.FeatureSet] = {}
        self.n_sims = 0
        self.keep: np.ndarray | None = None  # feature columns used (None: all)

    def _count(self, k: int) -> None:
        need = self.n_sims + k
        if self.bar.total is not None and need > self.bar.total:
            self.bar.total = need + 2
            self.bar.refresh()
        self.n_sims += k
        self.bar.update(k)

    def measured_set(self, model: ParametricModel) -> _d.FeatureSet:
        """Residual features of the measurement replayed by ``model``."""
        k = _d._Evaluator.key(model)
        if k not in self.meas:
            rep = replay_model(model, self.measured, self.case)
            self.meas[k] = replay_features(self.measured, rep, self.case, self.channels)
            self._count(1)
        return self.meas[k]

    def own_values(self, model: ParametricModel, seeds: Sequence[int]) -> np.ndarray:
        """All residual features of the model's own records replayed from their own forcing (every column)."""
        k = _d._Evaluator.key(model)
        todo = [s for s in seeds if (k, s) not in self.own]
        if todo:
            recs = surrogates.simulate(model, self.case, duration=self.duration, dt=self.measured.dt,
                                       seed=list(todo))
            assert isinstance(recs, list)
            self._count(len(todo))
            for s, r in zip(todo, recs, strict=True):
                self.own[(k, s)] = replay_features(r, replay_model(model, r, self.case), self.case,
                                                   self.channels).values
                self._count(1)
        return np.array([self.own[(k, s)] for s in seeds])

    def rows(self, model: ParametricModel, seeds: Sequence[int]) -> np.ndarray:
        """Rows ``(len(seeds), n_features)``: own-record features minus the measurement's, for ``model``."""
        out = self.own_values(model, seeds) - self.measured_set(model).values
        return out if self.keep is None else out[:, self.keep]


def run(measured: Record, model: FOWTModel, case: LoadCase, *, seed: int | None, names: Sequence[str],
        n_seeds: int, strengths: Sequence[float] | None, max_effects: int, channels: Sequence[str],
        n_scatter: int, progress: bool | None, n_screen: int, n_refine: int) -> _d.DiscrepancyReport:
    """Replay mode of :func:`fowt_env.discrepancy.run` (arguments checked there; see its docstring).

    Returns
    -------
    DiscrepancyReport
        ``mode == "replay"``; its features are the residual features of :func:`replay_features`.

    Raises
    ------
    ValueError
        The record lacks ``Wave1Elev`` or ``Wind1VelX`` (named), or holds gaps in them.
    """
    check_forcing(measured)
    if measured.duration - REPLAY_TRANSIENT < MIN_REPLAY_SECONDS:
        raise ValueError(f"record is {measured.duration:.0f} s long; replay mode needs at least "
                         f"{REPLAY_TRANSIENT + MIN_REPLAY_SECONDS:.0f} s ({REPLAY_TRANSIENT:.0f} s start-up)")
    base = as_parametric(model)
    first = 1000 if seed is None else int(seed)
    seeds = [first + i for i in range(int(n_seeds))]
    scatter_seeds = [first + i for i in range(int(n_scatter))]
    screen_seeds = seeds[:max(1, min(int(n_screen), len(seeds)))]
    cands = _d._make_candidates(names, strengths, model)
    per_setting = 1  # the measurement's replay; each own record costs a simulation and a replay
    estimate = (per_setting + 2 * len(scatter_seeds) + (per_setting + 2 * len(screen_seeds)) * len(cands)
                + min(int(n_refine), len(cands)) * 3 * (per_setting + 2 * len(seeds)) + 3)
    bar = progress_bar(estimate, "discrepancy (replay)", unit="simulations", progress=progress)
    try:
        ev = _ReplayEvaluator(measured, case, channels, bar)
        full = ev.measured_set(base)
        ratio = np.median(ev.own_values(base, scatter_seeds), axis=0)
        keep = np.array([k != "log_ratio" or r >= math.log(RATIO_MIN_SHARE) for k, r in zip(full.kinds, ratio,
                                                                                         strict=True)])
        ev.keep = np.flatnonzero(keep)
        # the search sees the rows "own - measured" against a measurement of zeros
        meas = _d.FeatureSet(tuple(n for n, k in zip(full.names, keep, strict=True) if k), np.zeros(int(keep.sum())),
                             tuple(n for n, k in zip(full.kinds, keep, strict=True) if k))
        rep, current = _d._search(measured, model, base, case, cands, int(max_effects), int(n_refine), meas,
                                  seeds, scatter_seeds, screen_seeds, ev)  # type: ignore[arg-type]
        rep.mode = "replay"
        runs = {"candidate": base} if rep.verdict != "explained" else {"candidate": base, "updated": current}
        rep._spectra = _spectra(measured, runs, case, ev)
        rep.n_simulations = ev.n_sims
        bar.total = bar.n
        bar.refresh()
        return rep
    finally:
        bar.close()


def _spectra(measured: Record, runs: dict[str, ParametricModel], case: LoadCase, ev: _ReplayEvaluator) -> dict:
    """Welch PSDs of the figure's channels: the measurement and each model's replay of it (same window)."""
    from scipy.signal import welch

    out: dict = {}
    for label, m in runs.items():
        rec = replay_model(m, measured, case)
        ev._count(1)
        for ch in ("TwHt9ALxt", "PtfmPitch"):
            out[(label, ch)] = welch(rec[ch] - rec[ch].mean(), fs=rec.fs, nperseg=min(rec.n_samples, int(150 * rec.fs)))
            if ("measured", ch) not in out:
                i0 = int(np.searchsorted(measured.t, rec.t[0] - 0.25 * measured.dt))
                x = np.asarray(measured[ch][i0:i0 + rec.n_samples], float)
                out[("measured", ch)] = welch(x - np.nanmean(x), fs=measured.fs,
                                              nperseg=min(x.size, int(150 * measured.fs)))
    return out
