"""Virtual sensing of one record: fill the lost tower channels of a measurement with a trained estimator.

:func:`sense` is what ``fowt-env sense`` runs. The measured record (any format :mod:`fowt_env.io` reads) holds
NaN where a sensor was lost; ``hide`` loses further channels on purpose (to test a sensor against data it has).
The estimator -- any name of :data:`fowt_env.compare.ESTIMATORS` (``dmd``, ``kalman``, ``koopman``, ``hold``) --
is trained either on the user's own complete records (``train=[...]``, e.g. a healthy week of the same
turbine) or, by default, on the surrogate's training set of the comparison harness (the seed paper's OLCs,
:class:`fowt_env.compare.CompareSettings`). The result carries the reconstructed record (every channel; live
channels as the sensor returns them), the per-channel standard deviation for uncertainty-aware sensors, the mask
and R² and NRMSE of every lost channel over the samples it was lost: against the noise-free truth if one is
given, else, for the channels hidden on purpose (``hide``), against their measured values.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["SensingResult", "sense"]


@dataclass
class SensingResult:
    """What :func:`sense` returns.

    Attributes
    ----------
    record : surrogates.Record
        The reconstruction: the sensed channels, in the measured record's units and time base.
    std : surrogates.Record or None
        Per-channel standard deviation of the estimate (uncertainty-aware sensors only).
    mask : ndarray of bool (n_samples, n_channels)
        True where the channel was live (measured, finite, not hidden).
    estimator : str
    scores : dict
        Per lost channel: ``lost_fraction`` and ``r2`` and ``nrmse`` over the samples it was lost (normalised by
        the variance and range of the whole reference record), None without a reference; ``reference`` says
        which: ``"truth"`` (the given noise-free truth) or ``"measured"`` (a channel hidden on purpose, scored
        against its own measured values).
    timing : dict
        ``fit_s``, ``reconstruct_s``, ``us_per_sample`` (wall clock).
    measured : ndarray (n_samples, n_channels) or None
        The measured values of the sensed channels (channel units), for the figure.
    """

    record: Any
    std: Any
    mask: np.ndarray
    estimator: str
    scores: dict[str, dict[str, float | None]] = field(default_factory=dict)
    timing: dict[str, float] = field(default_factory=dict)
    measured: np.ndarray | None = None

    def summary(self) -> str:
        """Readable table of the lost channels (fraction lost, R² and NRMSE if a truth was given)."""
        lines = [f"virtual sensing with {self.estimator!r}: {self.record.n_channels} channels, "
                 f"{self.record.n_samples} samples ({self.record.duration:.1f} s), "
                 f"{100 * (1 - self.mask.mean()):.1f} % of channel samples lost",
                 f"{'channel':<12}{'unit':>8}{'lost %':>9}{'R2':>10}{'NRMSE %':>10}"]
        units = dict(zip(self.record.channels, self.record.units, strict=True))
        for name, s in self.scores.items():
            r2 = "-" if s.get("r2") is None else f"{s['r2']:.4f}"
            nr = "-" if s.get("nrmse") is None else f"{100 * s['nrmse']:.2f}"
            lines.append(f"{name:<12}{units[name]:>8}{100 * s['lost_fraction']:>9.1f}{r2:>10}{nr:>10}"
                         + ("  (vs the measured values)" if s.get("reference") == "measured" else ""))
        if not self.scores:
            lines.append("(no channel was lost)")
        lines.append(f"fit {self.timing.get('fit_s', 0.0):.1f} s, reconstruction "
                     f"{self.timing.get('us_per_sample', 0.0):.0f} us per sample")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able summary (no time series)."""
        return {"estimator": self.estimator, "channels": self.record.channels, "units": self.record.units,
                "n_samples": self.record.n_samples, "dt": self.record.dt, "scores": self.scores,
                "timing": self.timing}

    def plot(self, folder: str | Path, max_channels: int = 6, seconds: float | None = 60.0,
             truth: Any = None) -> Path:
        """Figure of the lost channels: measured (live samples), reconstruction (+- 1.96 std) and truth if given.

        Parameters
        ----------
        folder : str or Path
            Created if needed; the figure is ``sensing.png``.
        max_channels : int
            Lost channels shown (those lost longest first).
        seconds : float or None
            Window shown: the last ``seconds`` of the record (None: all).
        truth : surrogates.Record, optional
            Noise-free truth with the same channels.

        Returns
        -------
        Path
        """
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        order = sorted(self.scores, key=lambda n: -self.scores[n]["lost_fraction"])[:max_channels]
        if not order:
            order = self.record.channels[:1]
        t = self.record.t
        sel = slice(None) if seconds is None else (t >= t[-1] - seconds)
        fig, axes = plt.subplots(len(order), 1, figsize=(9, 2.2 * len(order) + 0.8), sharex=True, squeeze=False)
        for ax, name in zip(axes[:, 0], order, strict=True):
            j = self.record.channels.index(name)
            live = self.mask[:, j]
            est = self.record.y[:, j]
            if truth is not None and name in truth:
                ax.plot(t[sel], truth[name][sel], color="k", lw=1.2, label="truth")
            if self.measured is not None:
                meas = np.where(live, self.measured[:, j], np.nan)
                ax.plot(t[sel], meas[sel], color="0.6", lw=0.8, label="measured (live)")
            ax.plot(t[sel], est[sel], color="C1", lw=1.0, label=f"{self.estimator} estimate")
            if self.std is not None:
                s = self.std.y[:, j]
                ax.fill_between(t[sel], (est - 1.96 * s)[sel], (est + 1.96 * s)[sel], color="C1", alpha=0.25,
                                lw=0, label="95 % interval")
            lost_t = np.where(~live, 1.0, np.nan)[sel]
            ax.fill_between(t[sel], 0, 1, where=lost_t == 1.0, transform=ax.get_xaxis_transform(), color="C3",
                            alpha=0.08, lw=0, label="lost")
            ax.set_ylabel(f"{name}\n[{self.record.units[j]}]", fontsize=8)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper right")
        axes[-1, 0].set_xlabel("time (s)")
        fig.suptitle(f"Virtual sensing with {self.estimator}: lost channels (red shading) reconstructed", fontsize=10)
        fig.tight_layout()
        path = folder / "sensing.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path


def _channels(record: Any, plane: str | None, channels: Sequence[str] | None) -> list[str]:
    from surrogates.channels import tower_channels

    names = list(channels) if channels else (tower_channels("FA") + tower_channels("SS") if plane is None
                                            else tower_channels(plane))
    missing = [c for c in names if c not in record]
    if missing:
        raise ValueError(f"the measured record lacks channels {missing} (it has {record.channels[:8]}"
                         f"{' ...' if record.n_channels > 8 else ''}); pick a plane or --channels it has")
    return names


def sense(
    measured: Any,
    estimator: str = "dmd",
    *,
    plane: str | None = "FA",
    channels: Sequence[str] | None = None,
    hide: Sequence[str] = (),
    train: Sequence[Any] | None = None,
    update_interval: float = 1.0,
    options: dict[str, Any] | None = None,
    truth: Any = None,
    settings: Any = None,
    progress: bool | None = False,
) -> SensingResult:
    """Reconstruct the lost channels of a measured record with a trained virtual sensor.

    Parameters
    ----------
    measured : surrogates.Record
        The measurement; NaN marks lost samples.
    estimator : str
        Name in :data:`fowt_env.compare.ESTIMATORS`.
    plane : {"FA", "SS"} or None
        The 18 tower channels of one plane (the paper's set-up), or None for all 36.
    channels : sequence of str, optional
        Explicit channel list instead of a plane.
    hide : sequence of str
        Channels to lose on purpose (in addition to NaN in the record).
    train : sequence of surrogates.Record, optional
        Training records with the same channels (NaN allowed where the estimator allows it). Default: the
        surrogate training set of :class:`fowt_env.compare.CompareSettings` (``settings``), which needs the
        measured record at the settings' sample time.
    update_interval : float
        Recalibration interval (s) for sensors that use one (DMD).
    options : dict, optional
        Keyword options of the estimator's factory (e.g. ``{"rank": 40}``).
    truth : surrogates.Record, optional
        Noise-free truth with the same channels, for scores.
    settings : fowt_env.compare.CompareSettings, optional
        Default training set-up (used only without ``train``).
    progress : bool or None
        Progress of the steps (training, reconstruction) with an ETA on standard error
        (:func:`fowt_env.progress.progress_bar`): True, False (default) or None (when it is a terminal).

    Returns
    -------
    SensingResult

    Raises
    ------
    ValueError
        Unknown estimator or channel, channels missing from the record, a training record without them, a
        sample-time mismatch, or no live data at all.
    """
    import surrogates

    from .compare import ESTIMATORS, CompareSettings, _hidden_scores, fit_sensor

    if estimator not in ESTIMATORS:
        raise ValueError(f"unknown estimator {estimator!r}; choose from {sorted(ESTIMATORS)}")
    names = _channels(measured, plane, channels)
    unknown = [h for h in hide if h not in names]
    if unknown:
        raise ValueError(f"--hide: {unknown} are not among the sensed channels {names}")
    y = measured.select(names).y
    mask = np.isfinite(y)
    for h in hide:
        mask[:, names.index(h)] = False
    if not mask.any():
        raise ValueError("no live data: every sensed channel is lost in every sample")
    from .progress import progress_bar

    with progress_bar(2, "sense", progress=progress) as bar:
        bar.set_postfix_str("training" if train else "training on the surrogate's load cases")
        t0 = time.perf_counter()
        if train:
            factory = ESTIMATORS[estimator]
            sensor = factory(measured.dt, update_interval, channels=names, **(options or {}))
            data = []
            for i, rec in enumerate(train):
                miss = [c for c in names if c not in rec]
                if miss:
                    raise ValueError(f"training record {i} lacks channels {miss}")
                if abs(rec.dt - measured.dt) > 1e-6 * measured.dt:
                    raise ValueError(f"training record {i} has dt = {rec.dt:g} s, the measurement {measured.dt:g} s")
                data.append(rec.select(names).y)
            if getattr(factory, "concatenate_training", False):
                data = [np.concatenate(data, axis=0)]
            sensor.fit(data)
        else:
            base = settings or CompareSettings()
            if abs(base.dt - measured.dt) > 1e-6 * base.dt:
                raise ValueError(f"the measurement has dt = {measured.dt:g} s but the default surrogate training set "
                                 f"is at {base.dt:g} s: resample the record or give training records (--train)")
            from dataclasses import replace

            st = replace(base, plane=plane if channels is None else base.plane,
                         estimator_options={estimator: dict(options or {})} if options else base.estimator_options)
            if channels is not None and list(channels) != st.channels:
                raise ValueError("explicit channels need training records (--train); the default training set has "
                                 f"the channels of plane {st.plane!r}")
            sensor = fit_sensor(estimator, st, update_interval)
        fit_s = time.perf_counter() - t0
        bar.update(1)
        bar.set_postfix_str("reconstruct")
        y_in = np.where(mask, y, np.nan)
        t1 = time.perf_counter()
        try:
            est, std = sensor.reconstruct(y_in, mask, return_std=True)
        except TypeError:
            est, std = sensor.reconstruct(y_in, mask), None
        wall = time.perf_counter() - t1
        bar.update(1)
    units = list(measured.select(names).units)
    meta = {"source": "fowt-env sense", "estimator": estimator, "measured_meta": measured.meta,
            "lost_fraction": {n: float(1 - mask[:, j].mean()) for j, n in enumerate(names)}}
    rec = surrogates.Record(measured.t, np.asarray(est), names, units, meta)
    std_rec = None if std is None else surrogates.Record(measured.t, np.asarray(std), names, units,
                                                         {**meta, "kind": "std"})
    scores: dict[str, dict[str, float | None]] = {}
    tr = None
    if truth is not None:
        miss = [c for c in names if c not in truth]
        if miss:
            raise ValueError(f"the truth record lacks channels {miss}")
        tr = truth.select(names).y
        if tr.shape[0] != y.shape[0]:
            raise ValueError(f"the truth has {tr.shape[0]} samples, the measurement {y.shape[0]}")
    for j, n in enumerate(names):
        lost = ~mask[:, j]
        if not lost.any():
            continue
        s: dict[str, Any] = {"lost_fraction": float(lost.mean()), "r2": None, "nrmse": None}
        if tr is not None:  # over the lost samples, normalised by the whole truth record (as compare scores)
            s["r2"], s["nrmse"] = _hidden_scores(tr[:, j], est[:, j], lost)
            s["reference"] = "truth"
        elif n in hide:  # hidden on purpose: the measured values are the reference, where the record has them
            known = np.isfinite(y[:, j])
            if (lost & known).any():
                s["r2"], s["nrmse"] = _hidden_scores(y[known, j], est[known, j], lost[known])
                s["reference"] = "measured"
        scores[n] = s
    return SensingResult(rec, std_rec, mask, estimator, scores,
                         {"fit_s": fit_s, "reconstruct_s": wall, "us_per_sample": 1e6 * wall / max(len(y), 1)},
                         measured=y)


def write_json(result: SensingResult, path: str | Path) -> Path:
    """Write :meth:`SensingResult.to_dict` as JSON."""
    path = Path(path)
    path.write_text(json.dumps(result.to_dict(), indent=2))
    return path
