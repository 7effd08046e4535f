"""Time of ``identify`` with its defaults (order tracking included) on a long record of all 36 tower channels.

Prints, measured in this run on a surrogate record (OLC 7 by default, rated wind, the rotor turning):

1. ``identify`` with the defaults of ``fowt-env identify`` (Hankel-DMD, SSI-COV, and the rotor harmonics by order
   tracking on the ``RotSpeed`` channel): the target is under 10 s for 30 minutes x 36 channels;
2. the reference, measured in the same run on the same record: ``identify`` with ``rotor_speed=None`` (no order
   tracking), and the ratio of the two, which says what the order tracking costs whatever the machine's speed;
3. with ``--all-channels``, also the order tracking on every channel (``rotor_harmonics(components=None)``, the
   behaviour before issue 19: its Gram matrices are ``36 x delays`` square and their cost does not shrink with
   the record), for comparison.

Best of ``--repeats`` runs each (wall clock). The numbers depend on the machine; the ratio much less.

Usage: python benchmarks/identify.py [--duration 1800] [--case 7] [--repeats 1] [--all-channels]
"""

from __future__ import annotations

import argparse
import platform
import time
from unittest import mock

import surrogates
from estimators import order_tracking
from fowt_env import identification
from fowt_env.identification import identify


def best_of(fn, repeats: int) -> tuple[float, float, object]:
    """Best wall time, the CPU time (all threads) of that run, and the result."""
    runs, out = [], None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        runs.append((time.perf_counter() - t0, time.process_time() - c0))
    wall, cpu = min(runs)
    return wall, cpu, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=1800.0, help="record length in s (default 1800)")
    parser.add_argument("--case", type=int, default=7, help="OLC of the record (default 7)")
    parser.add_argument("--repeats", type=int, default=1, help="runs per measurement, best kept (default 1)")
    parser.add_argument("--all-channels", action="store_true",
                        help="also time the order tracking on every channel (slow: the behaviour before issue 19)")
    args = parser.parse_args()

    rec = surrogates.simulate(surrogates.FOWTModel(), args.case, duration=args.duration, seed=0)
    n_tower = sum(c.startswith("TwHt") for c in rec.channels)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}; record: "
          f"OLC {args.case}, {rec.duration:.0f} s at {1 / rec.dt:.0f} Hz, {n_tower} tower channels")

    identify(rec.slice_time(0.0, 120.0))  # warm-up: first-call imports and caches are not what is measured
    t_ref, c_ref, _ = best_of(lambda: identify(rec, rotor_speed=None), args.repeats)
    t_def, c_def, res = best_of(lambda: identify(rec), args.repeats)
    orders = ", ".join(f"{h['order']:.2f}" for h in (res.harmonics or [])) or "none"
    print(f"{'':44}{'wall':>8}{'CPU':>9}   ratio to reference (wall, CPU)")
    print(f"{'identify, rotor_speed=None (reference)':<44}{t_ref:7.2f}s{c_ref:8.2f}s")
    print(f"{'identify, defaults (order tracking)':<44}{t_def:7.2f}s{c_def:8.2f}s   {t_def / t_ref:5.2f} "
          f"{c_def / c_ref:5.2f}   orders found: {orders}   target < 10 s: {'met' if t_def < 10.0 else 'MISSED'}")
    if args.all_channels:
        def every_channel(*a, **k):
            return order_tracking.rotor_harmonics(*a, **{**k, "components": None})

        with mock.patch.object(identification, "rotor_harmonics", every_channel):
            t_all, c_all, res_all = best_of(lambda: identify(rec), args.repeats)
        orders = ", ".join(f"{h['order']:.2f}" for h in (res_all.harmonics or [])) or "none"
        print(f"{'identify, order tracking on every channel':<44}{t_all:7.2f}s{c_all:8.2f}s   {t_all / t_ref:5.2f} "
              f"{c_all / c_ref:5.2f}   orders found: {orders}")


if __name__ == "__main__":
    main()
