"""Time-domain check against OpenFAST: start where OpenFAST starts, follow its series.

:func:`fowt_env.validation.validate` compares statistics (means, standard deviations per band, DELs), which is what
two codes driven by different random seeds can share. Here the surrogate meets OpenFAST runs that record their
start (output from t = 0, the deck's initial conditions): replayed from that state under the run's own measured wave
elevation (and its steady wind), it must follow OpenFAST's time series. The score per channel is

    R^2 = 1 - mean((surrogate - OpenFAST)^2) / var(OpenFAST)

over the record after :data:`TIME_DOMAIN_SKIP_S`, with the ratio of standard deviations and both means.

The packaged runs (``fowt_env/data/openfast_time_domain``, made by ``tools/openfast_time_domain_runs.py``) are the
shared OC3 Hywind deck in the shared steady-wind run's sea (Hs 2.5 m, Tp 10 s): operating in steady 12 m/s wind from
the deck's initial state, and parked without aerodynamics from rest. ``fowt-env validate time-domain`` runs this.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["TIME_DOMAIN_DATA", "TIME_DOMAIN_CHANNELS", "TIME_DOMAIN_SKIP_S", "NEGLIGIBLE_STD", "TimeDomainScore",
           "packaged_time_domain_dir", "time_domain", "format_time_domain", "plot_time_domain"]

TIME_DOMAIN_DATA = "openfast_time_domain"
"""Package folder of the compact OpenFAST runs with their start (``tools/openfast_time_domain_runs.py``)."""

TIME_DOMAIN_CHANNELS: tuple[str, ...] = (
    "PtfmSurge", "PtfmHeave", "PtfmPitch", "PtfmRoll", "PtfmYaw", "RotSpeed", "BldPitch1", "GenPwr", "RotThrust",
    "TwrBsMyt", "TwrBsMxt", "TwHt9ALxt", "TwHt9ALyt",
)
"""Channels scored (those a run varies in)."""

NEGLIGIBLE_STD: dict[str, float] = {"m": 1e-3, "deg": 1e-3, "rpm": 1e-2, "kN": 0.1, "kN-m": 1.0, "kW": 1.0,
                                    "m/s^2": 1e-3}
"""A channel whose OpenFAST standard deviation is below this (per unit) is not scored: in the parked run the
platform roll and yaw (~1e-3 deg) and the rotor speed (~1e-3 rpm) carry only numerical noise."""

TIME_DOMAIN_SKIP_S = 20.0
"""Start of the scored window (s): both codes first settle the controller and the blades' and tower's deflections
from the deck's initial values (OpenFAST's rotor speed rings at the drivetrain's frequency in its first seconds),
which neither resolves alike; the platform's own start (its 30 s and 120 s periods) is scored."""


@dataclass(frozen=True)
class TimeDomainScore:
    """One channel of one run: the surrogate's replay against OpenFAST's series.

    Attributes
    ----------
    run, channel : str
        Run name and OpenFAST channel name.
    r2 : float
        ``1 - mean((s - o)^2) / var(o)`` over the scored window (-).
    std_ratio : float
        Surrogate standard deviation over OpenFAST's (-).
    mean_openfast, mean_surrogate : float
        Means over the window (the channel's unit).
    unit : str
        The channel's unit.
    """

    run: str
    channel: str
    r2: float
    std_ratio: float
    mean_openfast: float
    mean_surrogate: float
    unit: str

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python copy (JSON-ready)."""
        return {k: (float(v) if isinstance(v, float | np.floating) else v) for k, v in asdict(self).items()}


def packaged_time_domain_dir() -> Path:
    """Folder of the compact time-domain OpenFAST runs shipped with fowt_env (:data:`TIME_DOMAIN_DATA`)."""
    return Path(str(resources.files("fowt_env") / "data" / TIME_DOMAIN_DATA))


def _runs(folder: Path, names: Sequence[str] | None) -> list[tuple[str, Path, dict[str, Any]]]:
    import fnmatch

    out = []
    for case_path in sorted(folder.glob("*.case.json")):
        name = case_path.name[: -len(".case.json")]
        if names and not any(fnmatch.fnmatch(name, p) or name.startswith(p) for p in names):
            continue
        record = next((case_path.with_name(name + ext) for ext in (".npz", ".outb", ".out", ".csv", ".parquet")
                       if case_path.with_name(name + ext).is_file()), None)
        if record is None:
            raise ValueError(f"{case_path}: no record <run>.npz/.outb/.out/.csv/.parquet beside it")
        out.append((name, record, json.loads(case_path.read_text(encoding="utf-8"))))
    if not out:
        raise ValueError(f"no run with a <run>.case.json sidecar in {folder}"
                         + (f" matching {list(names)}" if names else ""))
    return out


def _replay(record: Any, case: Mapping[str, Any], model: Any, dt: float) -> Any:
    """The surrogate from the run's start under its waves and wind: the deck's initial conditions (the case's
    ``start``, at rest) when the record begins at the run's t = 0, else the record's first sample."""
    from .replay import replay_record

    start = case.get("start")
    at_start = bool(start) and abs(float(record.t[0])) < 1e-6 and not float(case.get("transient_s") or 0.0)
    initial: bool | dict[str, float] = {str(k): float(v) for k, v in start.items()} if at_start else True
    return replay_record(record, case=dict(case), model=model, transient=0.0, dt=dt, initial=initial)


def time_domain(reference: str | Path | None = None, model: Any = None, *, runs: Sequence[str] | None = None,
                channels: Sequence[str] = TIME_DOMAIN_CHANNELS, skip: float = TIME_DOMAIN_SKIP_S,
                dt: float = 0.0125, return_records: bool = False) -> Any:
    """Replay OpenFAST runs from their first sample and score the surrogate's series against OpenFAST's.

    Parameters
    ----------
    reference : str or path-like, optional
        Folder of runs (``<run>.case.json`` beside a record that starts at the run's t = 0, e.g. an ``.outb``
        written with ``TStart = 0``); default the packaged runs (:func:`packaged_time_domain_dir`).
    model : surrogates.FOWTModel, optional
        Default: :func:`fowt_env.validation.reference_model` (OpenFAST's gauge heights, ``rotor_1p`` off: the
        deck's rotor is balanced), as :func:`fowt_env.validation.validate` uses.
    runs : sequence of str, optional
        Names, prefixes or glob patterns of the runs; default all.
    channels : sequence of str
        Channels to score; those a run lacks or holds (nearly) constant (:data:`NEGLIGIBLE_STD`) are skipped.
    skip : float
        Start of the scored window (s after the record's first sample), >= 0.
    dt : float
        Sample time of the surrogate (s); it is interpolated to the record's times.
    return_records : bool
        Also return ``{run: (openfast_record, surrogate_record)}``.

    Returns
    -------
    list of TimeDomainScore, or (scores, records) with ``return_records``

    Raises
    ------
    ValueError
        For a folder without runs, no matching run, a negative `skip` or a record shorter than it.

    Examples
    --------
    >>> scores = time_domain(runs=["t_parked"], channels=["PtfmPitch"])  # doctest: +SKIP
    >>> scores[0].r2 > 0.9  # doctest: +SKIP
    True
    """
    import surrogates

    from .io import load_record

    if not (np.isfinite(skip) and skip >= 0.0):
        raise ValueError(f"skip must be a finite number of seconds >= 0, got {skip!r}")
    folder = packaged_time_domain_dir() if reference is None else Path(reference)
    if not folder.is_dir():
        raise ValueError(f"{folder}: not a folder of time-domain runs")
    if model is None:
        from .validation import reference_model

        model = reference_model()
    scores: list[TimeDomainScore] = []
    records: dict[str, tuple[Any, Any]] = {}
    for name, path, case in _runs(folder, runs):
        rec = load_record(path, unknown_channels="keep")
        sim = _replay(rec, case, model, dt)
        t = np.asarray(rec.t, float)
        sel = (t >= t[0] + skip) & (t <= float(sim.t[-1]) + 1e-9) & (t >= float(sim.t[0]) - 1e-9)
        if np.count_nonzero(sel) < 10:
            raise ValueError(f"{name}: the record ({t[-1] - t[0]:.0f} s) is shorter than the skipped {skip:g} s")
        for ch in channels:
            if ch not in rec.channels or ch not in sim.channels:
                continue
            ref = np.asarray(rec[ch], float)[sel]
            unit = str(surrogates.UNITS.get(ch, "-"))
            if not float(np.std(ref)) > NEGLIGIBLE_STD.get(unit, 0.0):
                continue
            mod = np.interp(t[sel], np.asarray(sim.t, float), np.asarray(sim[ch], float))
            scores.append(TimeDomainScore(
                run=name, channel=ch, r2=float(1.0 - np.mean((mod - ref) ** 2) / np.var(ref)),
                std_ratio=float(np.std(mod) / np.std(ref)), mean_openfast=float(np.mean(ref)),
                mean_surrogate=float(np.mean(mod)), unit=unit))
        records[name] = (rec, sim)
    return (scores, records) if return_records else scores


def format_time_domain(scores: Sequence[TimeDomainScore]) -> str:
    """A plain-text table of :func:`time_domain`'s scores, one block per run."""
    lines: list[str] = []
    run = None
    for s in scores:
        if s.run != run:
            run = s.run
            lines += ["", f"{run}", f"  {'channel':<11} {'R2':>7} {'std ratio':>10} {'mean OpenFAST':>14} "
                                    f"{'mean surrogate':>15}  unit"]
        lines.append(f"  {s.channel:<11} {s.r2:7.3f} {s.std_ratio:10.3f} {s.mean_openfast:14.4g} "
                     f"{s.mean_surrogate:15.4g}  {s.unit}")
    return "\n".join(lines[1:]) + "\n" if lines else "no scores\n"


def plot_time_domain(records: Mapping[str, tuple[Any, Any]], out_dir: str | Path,
                     channels: Sequence[str] = ("PtfmSurge", "PtfmPitch", "PtfmHeave", "PtfmYaw", "RotSpeed",
                                                "BldPitch1", "TwrBsMyt")) -> list[str]:
    """One figure per run: OpenFAST's and the surrogate's series of `channels` (those the run varies in).

    Parameters
    ----------
    records : mapping
        ``{run: (openfast_record, surrogate_record)}`` from ``time_domain(..., return_records=True)``.
    out_dir : str or path-like
        Created if needed; files ``<run>.png``.
    channels : sequence of str
        Panels, top to bottom.

    Returns
    -------
    list of str
        The written paths.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for run, (rec, sim) in records.items():
        chans = [c for c in channels if c in rec.channels and c in sim.channels and float(np.std(rec[c])) > 0]
        if not chans:
            continue
        fig, axes = plt.subplots(len(chans), 1, figsize=(10, 1.7 * len(chans) + 0.6), sharex=True, squeeze=False)
        for ax, c in zip(axes[:, 0], chans, strict=True):
            ax.plot(rec.t, rec[c], color="k", lw=1.4, label="OpenFAST")
            ax.plot(sim.t, sim[c], color="tab:red", lw=1.0, alpha=0.85, label="surrogate (replay)")
            ax.set_ylabel(c, fontsize=8)
            ax.grid(True, alpha=0.3)
        axes[0, 0].legend(loc="upper right", fontsize=8)
        axes[-1, 0].set_xlabel("time (s)")
        fig.suptitle(f"{run}: from OpenFAST's initial state, under its wave elevation", fontsize=10)
        fig.tight_layout()
        path = out / f"{run}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        paths.append(str(path))
    return paths
