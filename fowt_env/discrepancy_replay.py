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
   measured band power (``<band>_ratio``: an amplitude error), and the mean residual of the mean channels in
   units of the measured channel's standard deviation (``mean_residual``). A channel's band is used only where
   the candidate model's replays of its own records explain at least :data:`R2_MIN` of its power; elsewhere the
   record does not resolve its forcing, and its residual is the measurement itself.
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

Which wind: the hub point resolves the wind that drives the slow platform motion poorly (replayed from
``Wind1VelX`` the model explains about half of its own records' platform-band surge at 12 m/s); the rotor-effective
wind estimated from the record's own thrust, rotor speed and pitch (:mod:`fowt_env.wind_estimate`) explains
0.90-0.96 of it. ``wind="auto"`` uses the estimate when the record has the rotor channels and the rotor turns.

Measured (hidden-truth runs, 20-minute records at 10 Hz; README, "With replay"): a missing ``quadratic_drag`` at
rated wind (OLC 7), which the statistics do not see, is named at 0.85 (interval 0.01-1.55), with a drag
coefficient at its lower bound reported beside it as equally consistent; an added mass 10 % high is named at 1.10
(1.08-1.12); a drag coefficient x1.5 at OLC 10 stays below the null level, as in the statistical mode.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.signal.windows import tukey

import surrogates
from surrogates import FOWTModel, LoadCase, Record
from surrogates.parameters import ParametricModel, as_parametric
from surrogates.replay import MeasuredWaves, MeasuredWind

from . import discrepancy as _d
from .progress import progress_bar
from .replay import ROTOR_INITIAL_CHANNELS, record_initial
from .wind_estimate import ROTOR_WIND_CHANNELS, rotor_effective_wind

__all__ = ["MIN_REPLAY_SECONDS", "R2_MIN", "REPLAY_CHANNELS", "REPLAY_TRANSIENT", "check_forcing",
           "choose_wind", "replay_bands", "replay_features", "replay_model", "run"]

REPLAY_CHANNELS: tuple[str, ...] = ("Wave1Elev", "Wind1VelX")
"""The forcing a record must carry for replay mode: wave elevation at the spar axis (m), hub-height wind (m/s)."""

REPLAY_TRANSIENT = 60.0
"""Start-up of every replay discarded before the residual is formed (s)."""

R2_MIN = 0.5
"""A channel's band is compared where the candidate model's replays of its own records explain at least this
share of its power (median R² over its seeds): where they explain less, the band is sensor noise or forcing the
record does not resolve (turbulence over the rotor at 1P and 3P, the tower modes' excitation), its residual is
the measurement itself -- the statistical mode's business -- and comparing it only dilutes the gap."""

PLATFORM_SPLIT_HZ = 0.02
"""Where replay mode splits the platform band (Hz): surge mode 0.008 Hz below, heave and pitch 0.032-0.034 above."""

TAPER = 0.1
"""Share of the residual window tapered (cosine, half at each end) before its band powers are taken (-)."""

MIN_REPLAY_SECONDS = 120.0
"""Shortest residual window (s): the platform band needs a few of its periods."""


ROTOR_PHASE_BANDS: tuple[str, ...] = ("1P", "3P")
"""Bands whose residual depends on the rotor's azimuth: with the rotor turning, compared only when the record has
``Azimuth`` (a parked rotor has no phase to miss)."""


def replay_bands(case: LoadCase) -> dict[str, tuple[float, float]]:
    """The bands (Hz) of the residual features: the statistical workflow's, with its platform band split at
    :data:`PLATFORM_SPLIT_HZ` into the surge mode's (``surge``) and the heave and pitch modes' (``heave_pitch``) --
    under the record's own forcing their residuals can be told apart (a slow-drift force acts on the first, a
    damping change on both)."""
    out: dict[str, tuple[float, float]] = {}
    for name, (lo, hi) in _d._bands(case).items():
        if name == "platform":
            out["surge"] = (lo, PLATFORM_SPLIT_HZ)
            out["heave_pitch"] = (PLATFORM_SPLIT_HZ, hi)
        else:
            out[name] = (lo, hi)
    return out


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


def replay_model(model: FOWTModel, record: Record, case: LoadCase, transient: float = REPLAY_TRANSIENT,
                 wind: MeasuredWind | None = None) -> Record:
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
    wind : surrogates.replay.MeasuredWind, optional
        The wind to replay (e.g. :func:`fowt_env.wind_estimate.rotor_effective_wind` of the record); default the
        record's hub wind ``Wind1VelX``.

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
    if case.wind_speed <= 0:
        wind = None
    elif wind is None:
        wind = MeasuredWind.from_record(record)
    if waves is None and wind is None:
        raise ValueError("replay=True: the load case has neither waves (hs = 0) nor wind (wind_speed = 0): there "
                         "is no forcing to replay")
    init = record_initial(record)
    if case.wind_speed <= 0:  # a parked rotor: no rotor speed, azimuth, pitch or torque to start from
        for name in ROTOR_INITIAL_CHANNELS:
            init.pop(name, None)
    out = surrogates.simulate(model, lc, duration=None, dt=record.dt, seed=0, transient=transient, noise=False,
                              initial=init, waves=waves, wind=wind)
    assert isinstance(out, Record)
    return out


def _band_powers(x: NDArray[np.float64], fs: float, bands: Sequence[tuple[float, float]]) -> NDArray[np.float64]:
    """Mean square of ``x`` (its mean removed) in each band: Parseval over the FFT bins ``lo <= f <= hi`` of the
    series tapered by a Tukey window (10 % cosine ends, power restored by ``1 / mean(w^2)``). Without the taper the
    FFT sees the jump between the residual's last and first samples, whose leakage into the high bands dominated
    them in some records (a 2nd-tower-band z of +12 for one of the model's own records)."""
    n = x.size
    w = tukey(n, TAPER)
    spec = np.fft.rfft((x - x.mean()) * w)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    p = 2.0 * np.abs(spec) ** 2 / (n**2 * float(np.mean(w * w)))
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
    return _features_and_r2(record, replayed, case, channels)[0]


def _features_and_r2(record: Record, replayed: Record, case: LoadCase, channels: Sequence[str]
                     ) -> tuple[_d.FeatureSet, NDArray[np.float64]]:
    """:func:`replay_features` and, per feature, the R² of its channel and band (``1 - P_residual / P_measured``,
    NaN for the mean residuals)."""
    t = np.asarray(replayed.t, float)
    i0 = int(np.searchsorted(record.t, t[0] - 0.25 * record.dt))
    n = t.size
    bands = replay_bands(case)
    fs = 1.0 / record.dt
    names: list[str] = []
    vals: list[float] = []
    kinds: list[str] = []
    r2: list[float] = []
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
            r2 += [1.0 - p_r[j] / max(p_y[j], 1e-30)] * 2
    for ch in _d.MEAN_CHANNELS:
        y = np.asarray(record[ch][i0:i0 + n], float)
        r = np.nanmean(y - np.asarray(replayed[ch], float))
        names.append(f"{ch}:mean_residual")
        vals.append(float(r / max(float(np.nanstd(y)), 1e-12)))
        kinds.append("mean_residual")
        r2.append(math.nan)
    return _d.FeatureSet(tuple(names), np.array(vals), tuple(kinds)), np.array(r2)


def choose_wind(record: Record, case: LoadCase, wind: str = "auto") -> str:
    """``"rotor"`` or ``"hub"``: the wind replay mode uses for ``record`` (see :func:`run`'s ``wind``)."""
    if wind not in ("auto", "rotor", "hub"):
        raise ValueError(f"replay wind must be 'auto', 'rotor' or 'hub', got {wind!r}")
    has = all(c in record.channels for c in ROTOR_WIND_CHANNELS)
    turning = has and case.wind_speed > 0 and float(np.nanmedian(record["RotSpeed"])) > 0.5
    if wind == "rotor" and not turning:
        missing = [c for c in ROTOR_WIND_CHANNELS if c not in record.channels]
        raise ValueError("replay wind 'rotor' needs an operating rotor and the channels "
                         f"{list(ROTOR_WIND_CHANNELS)}" + (f"; the record lacks {missing}" if missing else ""))
    return "rotor" if wind == "rotor" or (wind == "auto" and turning) else "hub"


class _ReplayEvaluator:
    """:class:`fowt_env.discrepancy._Evaluator`'s interface for replay mode: ``rows(model, seeds)`` are the
    residual features of the model's own records (replayed from their own forcing) minus those of the
    measurement replayed by the same model (cached per model setting and seed)."""

    def __init__(self, measured: Record, case: LoadCase, channels: Sequence[str], bar: Any, wind: str = "hub"):
        self.measured, self.case, self.channels, self.bar, self.wind = measured, case, channels, bar, wind
        self._measured_wind = self.wind_of(measured)
        self.duration = measured.duration + measured.dt
        self.own: dict[tuple, np.ndarray] = {}
        self.own_r2: dict[tuple, np.ndarray] = {}
        self.meas: dict[tuple, _d.FeatureSet] = {}
        self.n_sims = 0
        self.keep: np.ndarray | None = None  # feature columns used (None: all)

    def wind_of(self, record: Record) -> MeasuredWind | None:
        """The wind a record is replayed with: its rotor-effective wind estimate, or None (its ``Wind1VelX``)."""
        return rotor_effective_wind(record) if self.wind == "rotor" else None

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
            rep = replay_model(model, self.measured, self.case, wind=self._measured_wind)
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
                rep = replay_model(model, r, self.case, wind=self.wind_of(r))
                replay_features(r, rep, self.case, self.channels)  # the checks
                f, r2 = _features_and_r2(r, rep, self.case, self.channels)
                self.own[(k, s)], self.own_r2[(k, s)] = f.values, r2
                self._count(1)
        return np.array([self.own[(k, s)] for s in seeds])

    def rows(self, model: ParametricModel, seeds: Sequence[int]) -> np.ndarray:
        """Rows ``(len(seeds), n_features)``: own-record features minus the measurement's, for ``model``."""
        out = self.own_values(model, seeds) - self.measured_set(model).values
        return out if self.keep is None else out[:, self.keep]


def run(measured: Record, model: FOWTModel, case: LoadCase, *, seed: int | None, names: Sequence[str],
        n_seeds: int, strengths: Sequence[float] | None, max_effects: int, channels: Sequence[str],
        n_scatter: int, progress: bool | None, n_screen: int, n_refine: int, wind: str = "auto"
        ) -> _d.DiscrepancyReport:
    """Replay mode of :func:`fowt_env.discrepancy.run` (arguments checked there; see its docstring).

    Parameters
    ----------
    wind : {"auto", "rotor", "hub"}
        The wind the measurement and the model's own records are replayed with: ``"rotor"`` the rotor-effective
        wind estimated from each record's rotor thrust, speed and pitch (:func:`fowt_env.wind_estimate.
        rotor_effective_wind`), ``"hub"`` its ``Wind1VelX``; ``"auto"``: ``"rotor"`` when the record has the
        channels (:data:`fowt_env.wind_estimate.ROTOR_WIND_CHANNELS`) and its rotor turns, else ``"hub"``.

    Returns
    -------
    DiscrepancyReport
        ``mode == "replay"``, ``replay_wind`` the wind used; its features are those of :func:`replay_features`.

    Raises
    ------
    ValueError
        The record lacks ``Wave1Elev`` or ``Wind1VelX`` (named), or holds gaps in them; ``wind="rotor"`` on a
        record without the rotor channels or with a parked rotor.
    """
    check_forcing(measured)
    wind = choose_wind(measured, case, wind)
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
        ev = _ReplayEvaluator(measured, case, channels, bar, wind)
        full = ev.measured_set(base)
        ev.own_values(base, scatter_seeds)
        key = _d._Evaluator.key(base)
        r2 = np.median([ev.own_r2[(key, s)] for s in scatter_seeds], axis=0)
        keep = np.isnan(r2) | (r2 >= R2_MIN)  # the mean residuals, and the bands the replay predicts
        if "Azimuth" not in measured.channels and case.wind_speed > 0:
            # without the rotor's azimuth the replay's rotor turns at a phase of its own: started from the
            # record's speed, pitch and torque it keeps that phase offset for the whole record, so the residual
            # in the rotor-harmonic bands is a lottery on one random angle (near zero when the two happen to
            # align: z -3.9 in a null record of OLC 3). Their power ratios stay.
            keep &= np.array([not n.endswith(tuple(f":{b}_residual" for b in ROTOR_PHASE_BANDS))
                              for n in full.names])
        ev.keep = np.flatnonzero(keep)
        # the search sees the rows "own - measured" against a measurement of zeros
        meas = _d.FeatureSet(tuple(n for n, k in zip(full.names, keep, strict=True) if k), np.zeros(int(keep.sum())),
                             tuple(n for n, k in zip(full.kinds, keep, strict=True) if k))
        rep, current = _d._search(measured, model, base, case, cands, int(max_effects), int(n_refine), meas,
                                  seeds, scatter_seeds, screen_seeds, ev,  # type: ignore[arg-type]
                                  prefer_inside=True, quadratic_screen=True)
        rep.mode, rep.replay_wind = "replay", wind
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
        rec = replay_model(m, measured, case, wind=ev._measured_wind)
        ev._count(1)
        for ch in ("TwHt9ALxt", "PtfmPitch"):
            out[(label, ch)] = welch(rec[ch] - rec[ch].mean(), fs=rec.fs, nperseg=min(rec.n_samples, int(150 * rec.fs)))
            if ("measured", ch) not in out:
                i0 = int(np.searchsorted(measured.t, rec.t[0] - 0.25 * measured.dt))
                x = np.asarray(measured[ch][i0:i0 + rec.n_samples], float)
                out[("measured", ch)] = welch(x - np.nanmean(x), fs=measured.fs,
                                              nperseg=min(x.size, int(150 * measured.fs)))
    return out
