"""Replay the OpenFAST reference runs through the surrogate and score them sample by sample (issue 16).

For every operating run: the surrogate is driven by the run's own ``Wave1Elev`` and its wind (the polar rotor
field of ``<run>.inflow.npz`` by default; ``--level rotor_effective`` its disc-mean wind, ``--level hub`` the
``Wind1VelX`` channel through the rotor-averaging filter), starts from the run's first sample (platform
position and rates fitted over the discarded start-up, ``replay_record(initial="fit")``; tower-top deflection,
rotor speed and azimuth) and its first ``--transient`` seconds are discarded.
Per channel and band it prints R² of the surrogate against OpenFAST and, beside it, the linear bound: the
multiple coherence of the OpenFAST channel with the two inputs (wave elevation, rotor-averaged wind), computed
from the OpenFAST record itself (``fowt_env.replay.coherence_bound``); ✗ marks R² < 0.85 x bound.

Usage::

    python benchmarks/replay.py                          # all operating runs in ../shared/reference/openfast
    python benchmarks/replay.py --runs c_op12 --plot replay.png --json replay.json
    python benchmarks/replay.py --level hub              # the hub wind only (what a nacelle anemometer gives)

Needs the shared OpenFAST runs (full 80 Hz records and inflow files); the packaged compact copy has no inflow.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

DEFAULT_REFERENCE = Path(__file__).resolve().parents[2] / "shared" / "reference" / "openfast" / "runs"
SCORED = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "TwrBsMyt", "TwHt9ALxt", "RotSpeed", "BldPitch1")
EXTRA = ("PtfmRoll", "PtfmYaw", "TwrBsMxt", "TwHt9ALyt", "RotThrust", "GenPwr")
PLOT = ("Wave1Elev", "Wind1VelX", "PtfmSurge", "PtfmHeave", "PtfmPitch", "TwrBsMyt", "TwHt9ALxt", "RotSpeed",
        "BldPitch1")


def replay_run(folder: Path, level: str, transient: float, dt: float) -> dict:
    from fowt_env.io import load_record
    from fowt_env.replay import inflow_rotor_wind, replay_record, replay_scores
    from surrogates.replay import MeasuredWind

    name = folder.name
    rec = load_record(folder / f"{name}.outb", unknown_channels="keep")
    case = json.loads((folder / f"{name}.case.json").read_text(encoding="utf-8"))
    inflow = folder / f"{name}.inflow.npz"
    wind = MeasuredWind.from_inflow(inflow, level=level) if inflow.is_file() else None
    t0 = time.perf_counter()
    rp = replay_record(rec, case=case, wind=wind, transient=transient, dt=dt, initial="fit")
    wall = time.perf_counter() - t0
    rotor_wind = inflow_rotor_wind(inflow) if inflow.is_file() else None
    scores = replay_scores(rec, rp, rotor_wind, channels=SCORED + EXTRA)
    return {"run": name, "record": rec, "replay": rp, "scores": scores, "wall_s": wall,
            "level": level if wind is not None else "hub (Wind1VelX)"}


def plot_overlay(result: dict, path: Path, seconds: float = 120.0) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rec, rp = result["record"], result["replay"]
    t1 = rp.t[-1]
    t0 = t1 - seconds
    chans = [c for c in PLOT if c in rec.channels and c in rp.channels]
    fig, axes = plt.subplots(len(chans), 1, figsize=(10, 1.35 * len(chans)), sharex=True)
    for ax, ch in zip(axes, chans, strict=True):
        sel = rec.t >= t0
        ax.plot(rec.t[sel], rec[ch][sel], color="k", lw=1.0, label="OpenFAST")
        sel = rp.t >= t0
        ax.plot(rp.t[sel], rp[ch][sel], color="tab:red", lw=0.9, ls="--", label="surrogate (replay)")
        ax.set_ylabel(f"{ch}\n({rec.units[rec.channels.index(ch)]})", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=7, ncol=2)
    axes[0].set_title(f"{result['run']}: replayed wave elevation and wind ({result['level']}), last {seconds:g} s",
                      fontsize=9)
    axes[-1].set_xlabel("OpenFAST time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reference", type=Path, default=DEFAULT_REFERENCE, help="folder of OpenFAST run folders")
    ap.add_argument("--runs", nargs="*", default=["c_op", "d_steady"], help="run name prefixes")
    ap.add_argument("--level", default="field", choices=("field", "rotor_effective", "hub"),
                    help="wind replayed from the inflow file (runs without one replay Wind1VelX)")
    ap.add_argument("--transient", type=float, default=100.0, help="start-up discarded (s)")
    ap.add_argument("--dt", type=float, default=0.025, help="output sample time (s)")
    ap.add_argument("--json", type=Path, help="write the scores")
    ap.add_argument("--plot", type=Path, help="overlay figure of the first run (PNG)")
    a = ap.parse_args(argv)
    if not a.reference.is_dir():
        print(f"no OpenFAST reference runs at {a.reference}", file=sys.stderr)
        return 1
    from fowt_env.replay import scores_table

    folders = sorted(p for p in a.reference.iterdir() if p.is_dir() and any(p.name.startswith(r) for r in a.runs)
                     and (p / f"{p.name}.outb").is_file())
    results = []
    for folder in folders:
        res = replay_run(folder, a.level, a.transient, a.dt)
        results.append(res)
        span = res["replay"].t
        print(f"\n{res['run']}: wind {res['level']}, scored {span[0]:.0f}-{span[-1]:.0f} s, "
              f"replay {res['wall_s']:.1f} s")
        print(scores_table(res["scores"], res["run"]))
    if a.json:
        a.json.write_text(json.dumps({r["run"]: {"level": r["level"], "scores": [s.to_dict() for s in r["scores"]]}
                                      for r in results}, indent=1), encoding="utf-8")
        print(f"wrote {a.json}")
    if a.plot and results:
        print(f"wrote {plot_overlay(results[0], a.plot)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
