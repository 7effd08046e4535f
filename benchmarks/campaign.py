"""Campaign throughput: the same comparison grid serially and on a 2-worker Dask LocalCluster.

The grid (default): scenario B on test OLCs 2, 4, 5, 10 x seeds 0, 1 x estimators hold and dmd = 16 records of
120 s, trained on OLCs 1, 3, 6, 11 (120 s each). Each run starts cold (no memoised simulations or fits; every Dask
worker simulates the training records and fits the sensors itself, as on a real cluster). Prints, for each
scheduler, the wall-clock time, the throughput in records per minute (with and without the cluster's start-up)
and the ratio to the first scheduler, and checks that every summary is the same JSON (apart from ``wall_clock``).

What to expect: a cluster pays a fixed price -- starting the workers, and in every worker importing the package,
loading the compiled kernel, simulating the training records and fitting the sensors -- before its first record,
and then shares the records out. On a small grid that price can exceed the whole serial run; on a grid of many
records, or on more cores or machines, the records dominate. The machine's load average is printed: on a shared
machine the workers compete with other processes for the cores and cannot scale.

Usage: python benchmarks/campaign.py [--cases 2,4,5,10] [--seeds 0,1] [--duration 120] [--schedulers serial,local:2]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

from fowt_env import compare as C
from fowt_env.campaign import parse_scheduler, run_campaign


def run(spec: str, folder: Path, grid: dict) -> tuple[float, float, str, int]:
    """(seconds including the scheduler's start-up and shut-down, seconds of the campaign itself, summary JSON
    without wall_clock, number of records)."""
    C.clear_cache()  # cold: this process simulates and fits again too
    t0 = time.perf_counter()
    with parse_scheduler(spec) as executor:
        done = run_campaign(folder, **grid, executor=executor)
    total = time.perf_counter() - t0
    if not done.ok:
        raise SystemExit(done.report())
    summary = json.loads((folder / "summary.json").read_text())
    summary.pop("wall_clock")
    return total, done.total_s, json.dumps(summary), len(done.result.runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", default="2,4,5,10", help="test OLCs (default 2,4,5,10)")
    parser.add_argument("--seeds", default="0,1", help="test seeds (default 0,1)")
    parser.add_argument("--estimators", default="hold,dmd", help="estimators (default hold,dmd)")
    parser.add_argument("--duration", type=float, default=120.0, help="seconds per test record (default 120)")
    parser.add_argument("--train-cases", default="1,3,6,11", help="training OLCs (default 1,3,6,11)")
    parser.add_argument("--train-duration", type=float, default=120.0, help="seconds per training record")
    parser.add_argument("--schedulers", default="serial,local:2",
                        help="schedulers to compare, the first is the reference (default serial,local:2)")
    args = parser.parse_args()
    settings = C.CompareSettings(train_cases=tuple(C.parse_int_list(args.train_cases)),
                                 train_duration=args.train_duration, duration=args.duration)
    grid = {"scenarios": ["B"], "estimators": args.estimators.split(","), "cases": C.parse_int_list(args.cases),
            "seeds": C.parse_int_list(args.seeds), "settings": settings, "lyapunov_time": None}
    print(f"grid: scenario B x OLC {args.cases} x seeds {args.seeds} x {args.estimators}; {args.duration:g} s records, "
          f"trained on OLC {args.train_cases} ({args.train_duration:g} s each); every run cold")
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} (1 min)")
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args.schedulers.split(","):
            total, work, summary, n = run(spec, Path(tmp) / spec.replace(":", "_").replace("/", "_"), grid)
            rows[spec] = (total, work, summary)
            print(f"{spec:<10} {n} records in {total:6.1f} s ({work:6.1f} s without the scheduler's start-up): "
                  f"{60 * n / total:6.1f} records/min ({60 * n / work:6.1f} without start-up)")
    ref, (t_ref, w_ref, j_ref) = next(iter(rows.items()))
    for spec, (total, work, _) in list(rows.items())[1:]:
        print(f"ratio {spec} / {ref}: {t_ref / total:.2f}x ({w_ref / work:.2f}x without start-up)")
    same = all(j == j_ref for _, _, j in rows.values())
    print(f"load average {os.getloadavg()[0]:.1f} (1 min); summary JSON identical (apart from wall_clock): "
          f"{'yes' if same else 'NO'}")
    if not same:
        raise SystemExit(1)

if __name__ == "__main__":
    main()
