"""Discrepancy workflow: where do model and measurement disagree, which named effect is missing, and how much
does adding it close the gap.

1. **Where** -- the candidate model is simulated under the measured load case with several seeds. Both the
   measurement and each simulation are reduced to *features*: log band powers of key channels in physically
   meaningful bands (platform modes, wave band, 1st tower modes, 1P, 3P, 2nd tower modes), mean offsets and
   higher-order statistics (skewness, kurtosis). Each feature's disagreement is expressed as a z-score
   against the model's own seed-to-seed scatter, so sampling noise is not mistaken for physics. Findings are
   the features with ``|z| > 3``.
2. **Name** -- for each candidate effect (default: all of :data:`surrogates.EFFECTS`) its strength is fitted
   by a 1-D search (a grid of strengths, then a parabolic refinement), re-simulating with the *same* seeds
   (common random numbers). The gap is ``mean(z**2)`` over features. An effect is named only when
   (a) the current gap is above the null level -- the gap of the model's own seeds against each other,
   calibrated in the same run: above ``max(3, 3 x null)`` -- and (b) the improvement is large, a factor of 1.5
   at least, and passes a BIC-like test for one added parameter, ``n_features * ln(gap_before / gap_after) >
   ln(n_features) + 2``. Otherwise the answer is "no significant discrepancy". Greedy forward selection repeats
   this to name several effects in order. Records of 15-20 minutes give reliable answers; 10 minutes is the
   practical minimum for the platform band.
3. **Add and show** -- the updated model is the candidate with the named effects at their fitted strengths;
   the report carries ``gap_before``, ``gap_after``, the per-feature z-scores before and after, the findings
   and a figure (:meth:`DiscrepancyReport.plot`).

The model given is never modified (models are immutable; updates are new objects).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.signal import welch
from scipy.stats import kurtosis, skew

import surrogates
from surrogates import EFFECTS, FOWTModel, LoadCase, Record

from .progress import progress_bar

__all__ = ["run", "DiscrepancyReport", "FeatureSet", "features", "DEFAULT_CHANNELS"]

DEFAULT_CHANNELS = ("TwHt1MLyt", "TwHt1MLxt", "TwHt9ALxt", "TwHt9ALyt", "PtfmSurge", "PtfmSway", "PtfmPitch",
                    "PtfmRoll", "PtfmYaw")
MEAN_CHANNELS = ("PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmPitch", "PtfmRoll", "TwHt1MLyt", "TwHt1MLxt")
SHAPE_CHANNELS = ("PtfmSurge", "PtfmPitch", "TwHt1MLyt")
LOG_FLOOR = 0.05  # minimum scatter of a log band power (~5 %)
MEAN_FLOOR = 0.02  # minimum scatter of a mean, relative to its magnitude (2 %)
MIN_GAP_RATIO = 1.5  # an accepted effect must shrink the gap by at least this factor
FAST_DT = 0.05  # default sample time of the model simulations (20 Hz covers every band)


def _white_noise_scaled(noise, factor: float) -> dict:
    """White-noise standard deviations of ``noise`` multiplied by ``sqrt(factor)`` (``factor = dt_meas / dt_sim``):
    a white sequence's one-sided spectral density is ``2 sigma^2 dt``, so this keeps the density unchanged."""
    g = math.sqrt(factor)
    return {"acceleration_white": noise.acceleration_white * g, "moment_white": noise.moment_white * g,
            "platform_white": noise.platform_white * g, "other_white": noise.other_white * g}


def _bands(case: LoadCase) -> dict[str, tuple[float, float]]:
    p1 = case.rotor_rpm / 60.0 if case.rotor_rpm > 0 else 0.2
    fp = 1.0 / case.tp
    return {
        "platform": (0.004, 0.05),
        "wave": (max(0.05, 0.7 * fp), 1.6 * fp),
        "tower_1": (0.42, 0.56),
        "1P": (p1 - 0.015, p1 + 0.015),
        "3P": (3 * p1 - 0.06, 3 * p1 + 0.06),
        "tower_2": (1.9, 2.8),
    }


@dataclass(frozen=True)
class FeatureSet:
    """Names and values of the features of one record."""

    names: tuple[str, ...]
    values: np.ndarray
    kinds: tuple[str, ...]  # "log_power", "mean", "shape"


def features(record: Record, case: LoadCase, channels: Sequence[str] = DEFAULT_CHANNELS) -> FeatureSet:
    """Reduce a record to discrepancy features (see module docstring).

    Parameters
    ----------
    record : Record
        Measured or simulated record; needs the channels used.
    case : LoadCase
        Its load case (for the wave band and the rotor harmonics).
    channels : sequence of str
        Channels whose band powers are used.

    Returns
    -------
    FeatureSet

    Raises
    ------
    ValueError
        Missing channels (listed), irregular sampling or a sample rate too low for the bands.
    """
    needed = sorted(set(channels) | set(MEAN_CHANNELS) | set(SHAPE_CHANNELS))
    missing = [c for c in needed if c not in record.channels]
    if missing:
        raise ValueError(f"measured record lacks channels the discrepancy features need: {missing}")
    t = record.t
    steps = np.diff(t)
    if np.max(np.abs(steps - record.dt)) > 1e-6 * record.dt + 1e-9:
        raise ValueError("record must be uniformly sampled; resample it first (irregular time steps found)")
    bands = _bands(case)
    if 0.5 * record.fs < max(hi for _, hi in bands.values()):
        raise ValueError(f"record sample rate {record.fs:.3g} Hz is too low for the tower bands (need >= 6 Hz)")
    if record.duration < 120.0:
        raise ValueError(f"record is {record.duration:.0f} s long; the platform band needs at least 120 s")
    names, vals, kinds = [], [], []
    nperseg = int(min(record.n_samples, 2 ** int(math.log2(200.0 * record.fs))))
    for ch in channels:
        x = record[ch]
        x = np.where(np.isfinite(x), x, np.nanmean(x))
        f, p = welch(x - x.mean(), fs=record.fs, nperseg=nperseg)
        for band, (lo, hi) in bands.items():
            sel = (f >= lo) & (f <= hi)
            power = float(np.trapezoid(p[sel], f[sel])) if sel.sum() > 1 else float(p[sel].sum() * (f[1] - f[0]))
            names.append(f"{ch}:{band}")
            vals.append(math.log(max(power, 1e-30)))
            kinds.append("log_power")
    for ch in MEAN_CHANNELS:
        names.append(f"{ch}:mean")
        vals.append(float(np.nanmean(record[ch])))
        kinds.append("mean")
    for ch in SHAPE_CHANNELS:
        x = record[ch][np.isfinite(record[ch])]
        names += [f"{ch}:skewness", f"{ch}:kurtosis"]
        vals += [float(skew(x)), float(kurtosis(x))]
        kinds += ["shape", "shape"]
    return FeatureSet(tuple(names), np.array(vals), tuple(kinds))


@dataclass
class DiscrepancyReport:
    """Outcome of :func:`run`.

    Attributes
    ----------
    effect : str or None
        The first (most significant) named effect, None for "no significant discrepancy".
    strength : float or None
        Its fitted strength.
    effects : list of (str, float)
        All named effects in the order of greedy selection, with fitted strengths.
    gap_before, gap_after : float
        ``mean(z**2)`` over features for the candidate and the updated model (-).
    null_gap : float
        The gap level of the model's own seeds against each other (the significance threshold uses it).
    feature_names : list of str
    z_before, z_after : ndarray
        Per-feature z-scores (measurement minus model mean, in units of the model's seed scatter).
    findings : list of dict
        Features with ``|z| > 3`` before the update: channel, band or statistic, z, relative size.
    candidates : dict
        Per tested effect: fitted strength, gap, accepted (bool) -- for each greedy round.
    updated_model : FOWTModel
    case : LoadCase
    """

    effect: str | None
    strength: float | None
    effects: list[tuple[str, float]]
    gap_before: float
    gap_after: float
    null_gap: float
    feature_names: list[str]
    z_before: np.ndarray
    z_after: np.ndarray
    findings: list[dict]
    candidates: list[dict]
    updated_model: FOWTModel
    case: LoadCase
    _spectra: dict = field(default_factory=dict, repr=False)

    def summary(self) -> str:
        """A few lines for people."""
        lines = [f"gap before: {self.gap_before:.2f}  (null level {self.null_gap:.2f})"]
        if self.effect is None:
            lines.append("no significant discrepancy: the model explains the measurement within its own scatter")
        for name, s in self.effects:
            lines.append(f"named effect: {name} at strength {s:.2f} -- {EFFECTS[name].doc}")
        lines.append(f"gap after: {self.gap_after:.2f}")
        for f in self.findings[:8]:
            lines.append(f"  finding: {f['feature']:<24} z = {f['z']:+.1f}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-friendly form (without the model object: its description instead)."""
        return {
            "effect": self.effect, "strength": self.strength, "effects": [list(e) for e in self.effects],
            "gap_before": self.gap_before, "gap_after": self.gap_after, "null_gap": self.null_gap,
            "features": {n: {"z_before": float(a), "z_after": float(b)}
                         for n, a, b in zip(self.feature_names, self.z_before, self.z_after, strict=True)},
            "findings": self.findings, "candidates": self.candidates,
            "updated_model": self.updated_model.to_dict(), "case": self.case.to_dict(),
        }

    def plot(self, path: str | Path) -> Path:
        """Figure: PSDs of measurement, candidate and updated model for two channels, and the z-scores."""
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        fig, axes = plt.subplots(3, 1, figsize=(10, 10))
        bands = _bands(self.case)
        for ax, ch in zip(axes[:2], ("TwHt9ALxt", "PtfmPitch"), strict=True):
            for label, style in (("measured", "k-"), ("candidate", "C0--"), ("updated", "C3-")):
                if (label, ch) in self._spectra:
                    f, p = self._spectra[(label, ch)]
                    sel = f > 0
                    ax.loglog(f[sel], p[sel], style, lw=1.0, label=label)
            for name, (lo, hi) in bands.items():
                shrunk = [n for n, a, b in zip(self.feature_names, self.z_before, self.z_after, strict=True)
                          if n == f"{ch}:{name}" and abs(a) > 3 and abs(b) < 0.5 * abs(a)]
                ax.axvspan(lo, hi, color="tab:green" if shrunk else "0.9", alpha=0.3 if shrunk else 0.4)
                ax.text(math.sqrt(lo * hi), 1.0, name, transform=ax.get_xaxis_transform(), ha="center",
                        va="top", fontsize=7)
            ax.set_xlim(0.003, 3.0)
            ax.set_ylabel(f"PSD of {ch}")
            ax.legend(fontsize=8)
        ax = axes[2]
        idx = np.arange(len(self.feature_names))
        ax.bar(idx - 0.2, np.abs(self.z_before), 0.4, label="|z| before", color="C0")
        ax.bar(idx + 0.2, np.abs(self.z_after), 0.4, label="|z| after", color="C3")
        ax.axhline(3.0, color="0.3", ls=":", lw=1)
        ax.set_yscale("symlog", linthresh=3)
        ax.set_xticks(idx)
        ax.set_xticklabels(self.feature_names, rotation=90, fontsize=5)
        ax.set_ylabel("|z| (model seed scatter)")
        ax.legend(fontsize=8)
        named = ", ".join(f"{n} x{s:.2f}" for n, s in self.effects) or "none"
        fig.suptitle(f"Discrepancy {self.case.name}: named {named}; gap {self.gap_before:.1f} -> {self.gap_after:.1f}"
                     " (green bands: shrunk)")
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path


class _Evaluator:
    """Simulate a model with fixed seeds and reduce to features (cached per effects setting)."""

    def __init__(self, case: LoadCase, duration: float, dt: float, seeds: list[int], channels: Sequence[str]):
        self.case, self.duration, self.dt, self.seeds, self.channels = case, duration, dt, seeds, channels
        self.cache: dict[tuple, np.ndarray] = {}
        self.n_sims = 0
        self.bar: Any = None  # a progress bar advanced by len(seeds) per evaluation (a cached one is done at once)

    def feature_matrix(self, model: FOWTModel) -> np.ndarray:
        key = tuple(sorted(model.effects.items()))
        if key not in self.cache:
            recs = surrogates.simulate(model, self.case, duration=self.duration, dt=self.dt, seed=self.seeds)
            self.n_sims += len(self.seeds)
            self.cache[key] = np.array([features(r, self.case, self.channels).values for r in recs])
        if self.bar is not None:
            self.bar.update(len(self.seeds))
        return self.cache[key]


def _scatter(fm: np.ndarray, kinds: Sequence[str], reference: np.ndarray) -> np.ndarray:
    sd = fm.std(axis=0, ddof=1)
    floor = np.array([LOG_FLOOR if k == "log_power" else (MEAN_FLOOR * abs(r) + 1e-9 if k == "mean" else 0.05)
                      for k, r in zip(kinds, reference, strict=True)])
    return np.maximum(sd, floor)


def run(
    measured: Record,
    model: FOWTModel,
    case: LoadCase | int,
    seed: int | None = None,
    candidates: Sequence[str] | None = None,
    n_seeds: int = 4,
    strengths: Sequence[float] = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0),
    max_effects: int = 3,
    channels: Sequence[str] = DEFAULT_CHANNELS,
    sim_dt: float | None = None,
    n_scatter: int = 8,
    progress: bool | None = False,
) -> DiscrepancyReport:
    """Find, name and add the physical effect(s) a model misses, given a measured record.

    Parameters
    ----------
    measured : Record
        The measurement (surrogate, OpenFAST or field data with the needed channels, uniformly sampled).
    model : FOWTModel
        The candidate model (not modified).
    case : LoadCase or int
        The measured conditions.
    seed : int, optional
        Base seed of the model simulations (default 1000); the seeds are ``seed, seed + 1, ...``.
    candidates : sequence of str, optional
        Effects to consider (default: all of :data:`surrogates.EFFECTS`).
    n_seeds : int
        Simulations per model setting (>= 3), for the scatter and the mean.
    strengths : sequence of float
        Grid of the 1-D strength search (a parabolic refinement follows).
    max_effects : int
        At most this many effects are named (greedy forward selection).
    channels : sequence of str
        Channels of the band-power features.
    sim_dt : float, optional
        Sample time of the model simulations (default: the measured record's, but at least 0.05 s; when coarser,
        the model's white sensor noise is scaled so its spectral density matches the measurement's).
    n_scatter : int
        Realisations of the candidate model used to estimate the seed-to-seed scatter (>= n_seeds).
    progress : bool or None
        Progress in model simulations with an ETA on standard error (:func:`fowt_env.progress.progress_bar`):
        True, False (default) or None (when it is a terminal). The total covers the search rounds known so far
        and grows when another round starts.

    Returns
    -------
    DiscrepancyReport

    Raises
    ------
    ValueError
        Missing channels, bad sampling, unknown candidate effects, too few seeds.
    """
    if not isinstance(measured, Record):
        raise ValueError(f"measured must be a surrogates.Record, got {type(measured).__name__}")
    if not isinstance(model, FOWTModel):
        raise ValueError(f"model must be a surrogates.FOWTModel, got {type(model).__name__}")
    case = surrogates.load_case(case) if isinstance(case, int) else case
    cands = list(EFFECTS) if candidates is None else list(candidates)
    unknown = [c for c in cands if c not in EFFECTS]
    if unknown:
        raise ValueError(f"candidates: unknown effects {unknown}; known: {sorted(EFFECTS)}")
    if int(n_seeds) < 3:
        raise ValueError(f"n_seeds must be at least 3 (the scatter needs them), got {n_seeds}")
    meas = features(measured, case, channels)
    dt = max(measured.dt, FAST_DT) if sim_dt is None else float(sim_dt)
    if dt > measured.dt * (1 + 1e-9):
        # simulate coarser than measured: keep the white-noise floor's spectral density that of the measurement
        # (density = 2 sigma^2 dt), so noise-dominated bands compare like with like
        model_sim = model.with_noise(**_white_noise_scaled(model.noise, measured.dt / dt))
    else:
        model_sim = model
    seeds = [(1000 if seed is None else int(seed)) + i for i in range(int(n_seeds))]
    ev = _Evaluator(case, measured.duration + dt, dt, seeds, channels)
    # the scatter needs more realisations than the mean: extra seeds for the candidate model only
    extra_seeds = list(range(seeds[-1] + 1, seeds[-1] + 1 + max(0, int(n_scatter) - len(seeds))))
    extra = _Evaluator(case, ev.duration, dt, extra_seeds, channels)

    def round_cost(model_now: FOWTModel, skip: set[str]) -> int:  # simulations of one search round
        return len(seeds) * sum(len(set(map(float, strengths)) - {model_now.effects[e]}) for e in cands
                                if e not in skip)

    bar = progress_bar(len(seeds) + len(extra_seeds) + round_cost(model_sim, set()) + 2, "discrepancy",
                       unit="simulations", progress=progress)
    ev.bar = extra.bar = bar
    try:
        return _search(measured, model, case, cands, strengths, max_effects, channels, meas, dt, model_sim, seeds,
                       ev, extra, bar, round_cost)
    finally:
        bar.close()


def _search(measured: Record, model: FOWTModel, case: LoadCase, cands: list[str], strengths: Sequence[float],
            max_effects: int, channels: Sequence[str], meas: Any, dt: float, model_sim: FOWTModel, seeds: list[int],
            ev: _Evaluator, extra: _Evaluator, bar: Any, round_cost: Any) -> DiscrepancyReport:
    """:func:`run`'s greedy search, advancing ``bar`` by the simulations it runs."""
    base_fm = ev.feature_matrix(model_sim)
    scatter_fm = np.vstack([base_fm, extra.feature_matrix(model_sim)]) if extra.seeds else base_fm
    scatter = _scatter(scatter_fm, meas.kinds, base_fm.mean(axis=0))
    n_f = len(meas.names)

    def zscores(fm: np.ndarray) -> np.ndarray:
        # the measurement is one realisation, the model mean averages n_seeds: both scatter
        return (meas.values - fm.mean(axis=0)) / (scatter * math.sqrt(1.0 + 1.0 / len(seeds)))

    def gap(fm: np.ndarray) -> float:
        return float(np.mean(zscores(fm) ** 2))

    # null level: each of the model's seeds against the mean of the others
    null = []
    for i in range(len(seeds)):
        others = np.delete(base_fm, i, axis=0)
        z = (base_fm[i] - others.mean(axis=0)) / (scatter * math.sqrt(1.0 + 1.0 / len(others)))
        null.append(float(np.mean(z**2)))
    null_gap = float(np.max(null))
    # A measured record is one realisation and the features are correlated, so a model that is right still
    # shows gaps of a few times the null level; only a gap clearly above it calls for a missing effect.
    threshold = max(3.0, 3.0 * null_gap)

    current = model_sim
    current_fm = base_fm
    gap0 = gap(base_fm)
    z0 = zscores(base_fm)
    named: list[tuple[str, float]] = []
    log: list[dict] = []
    g_cur = gap0
    for _round in range(int(max_effects)):
        if g_cur <= threshold:
            break
        if _round:  # another round: its simulations join the total
            bar.total += round_cost(current, {n for n, _ in named})
            bar.refresh()
        best = None
        for eff in cands:
            if eff in (n for n, _ in named):
                continue
            s0 = current.effects[eff]
            grid = sorted({float(s) for s in strengths} - {s0})
            gaps = {s: gap(ev.feature_matrix(current.with_effects(**{eff: s}))) for s in grid}
            s_best = min(gaps, key=gaps.get)
            s_ref = _parabolic(grid, gaps, s_best)
            if s_ref is not None:
                bar.total += len(seeds)
                gaps[s_ref] = gap(ev.feature_matrix(current.with_effects(**{eff: s_ref})))
                s_best = min(gaps, key=gaps.get)
            g = gaps[s_best]
            log.append({"round": _round + 1, "effect": eff, "strength": s_best, "gap": g, "accepted": False})
            if best is None or g < best[2]:
                best = (eff, s_best, g)
        if best is None:
            break
        eff, s_best, g = best
        significant = (g_cur / max(g, 1e-12) > MIN_GAP_RATIO
                       and n_f * math.log(g_cur / max(g, 1e-12)) > math.log(n_f) + 2.0)
        if not significant:
            break
        for entry in log:
            if entry["round"] == _round + 1 and entry["effect"] == eff:
                entry["accepted"] = True
        named.append((eff, s_best))
        current = current.with_effects(**{eff: s_best})
        bar.total += len(seeds)  # evaluated in the round already: counted, not simulated again
        current_fm = ev.feature_matrix(current)
        g_cur = gap(current_fm)
    z1 = zscores(current_fm)
    findings = [
        {"feature": n, "channel": n.split(":")[0], "band_or_statistic": n.split(":")[1], "z": float(z),
         "relative_size": float(z * scatter[i])}
        for i, (n, z) in enumerate(zip(meas.names, z0, strict=True)) if abs(z) > 3.0
    ]
    findings.sort(key=lambda d: -abs(d["z"]))
    updated = model
    for name, strength in named:
        updated = updated.with_effects(**{name: strength})
    report = DiscrepancyReport(
        effect=named[0][0] if named else None,
        strength=named[0][1] if named else None,
        effects=named,
        gap_before=gap0,
        gap_after=g_cur,
        null_gap=null_gap,
        feature_names=list(meas.names),
        z_before=z0,
        z_after=z1,
        findings=findings,
        candidates=log,
        updated_model=updated,
        case=case,
    )
    report._spectra = _spectra(measured, model_sim, current, case, dt, seeds[0])
    bar.update(2)
    return report


def _parabolic(grid: list[float], gaps: dict[float, float], s_best: float) -> float | None:
    """Vertex of the parabola through the best grid point and its neighbours (None at the grid's edge)."""
    i = grid.index(s_best)
    if i == 0 or i == len(grid) - 1:
        return None
    x = np.array(grid[i - 1: i + 2])
    y = np.array([gaps[s] for s in x])
    a, b, _ = np.polyfit(x, y, 2)
    if a <= 0:
        return None
    v = float(-b / (2 * a))
    return round(v, 3) if x[0] < v < x[2] and round(v, 3) not in gaps else None


def _spectra(measured: Record, before: FOWTModel, after: FOWTModel, case: LoadCase, dt: float, seed: int) -> dict:
    out = {}
    runs = {"candidate": before, "updated": after}
    for label, m in runs.items():
        rec = surrogates.simulate(m, case, duration=measured.duration + dt, dt=dt, seed=seed)
        for ch in ("TwHt9ALxt", "PtfmPitch"):
            out[(label, ch)] = welch(rec[ch] - rec[ch].mean(), fs=rec.fs, nperseg=min(rec.n_samples, int(150 * rec.fs)))
    for ch in ("TwHt9ALxt", "PtfmPitch"):
        x = measured[ch]
        out[("measured", ch)] = welch(x - np.nanmean(x), fs=measured.fs,
                                      nperseg=min(measured.n_samples, int(150 * measured.fs)))
    return out
