"""Hankel-DMD fit time and peak memory: ours (estimators.HankelDMD) against PyDMD's HankelDMD, and at scale.

Prints, measured in this run on surrogate data (OLC 4, fore-aft planar state: 18 channels at 80 Hz, band-passed
and z-scored as in the seed paper):

1. 20,000 samples x 18 channels, d = 60, r = 24 and r = 90: fit time and peak memory of ours and of PyDMD
   (``pydmd.HankelDMD(svd_rank=r, d=d)``, snapshots as columns), their ratios, and the largest relative
   difference of the sorted eigenvalues;
2. 1 h at 80 Hz (288,000 x 18), d = 60, r = 90: ours only (PyDMD's dense Hankel SVD would take minutes);
3. a 60 s delay (d = 4800) on 30 min of data with the randomized solver: the dense Hankel matrix would need
   ~100 GB and its Gram matrix ~60 GB.

Peak memory is the peak of Python/numpy allocations during the fit (tracemalloc), above what was allocated
before it; time is wall-clock (ours: best of ``--repeats``; PyDMD: one run).

Usage: python benchmarks/hankel_dmd.py [--repeats 5] [--skip-pydmd]
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
import warnings

import numpy as np

import surrogates
from estimators.hankel_dmd import HankelDMD
from estimators.preprocess import preprocess

FS = 80.0


def measure(fn, repeats: int = 1) -> tuple[float, float, object]:
    """Best wall time over ``repeats`` runs (untraced) and the peak traced memory of one more run (MiB)."""
    times = []
    result = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    tracemalloc.start()
    tracemalloc.reset_peak()
    fn()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return min(times), peak / 2**20, result


def measure_once(fn) -> tuple[float, float, object]:
    """Time and peak traced memory of a single run (for the slow reference)."""
    tracemalloc.start()
    t0 = time.perf_counter()
    result = fn()
    elapsed = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return elapsed, peak / 2**20, result


def record(duration: float, seed: int = 0) -> np.ndarray:
    y = surrogates.simulate(surrogates.FOWTModel(), 4, duration=duration, seed=seed).planar("FA").y
    return preprocess(y, FS)


def sorted_eigs(mu: np.ndarray) -> np.ndarray:
    return mu[np.lexsort((mu.imag, mu.real))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--skip-pydmd", action="store_true", help="do not run the (slow) PyDMD reference")
    args = parser.parse_args()
    pydmd = None
    if not args.skip_pydmd:
        try:
            import pydmd

            warnings.filterwarnings("ignore", message="Input data condition number", module="pydmd")
        except ImportError:
            print("PyDMD not installed (pip install pydmd): reference columns skipped")

    Y = record(250.0)[:20000]
    n, p = Y.shape
    HankelDMD(delays=60, rank=24).fit(Y[:2000])  # warm-up (imports, FFT plans)
    print(f"Hankel-DMD fit, surrogate OLC 4 fore-aft, {n} samples x {p} channels, d = 60")
    header = f"{'case':<34}{'ours s':>9}{'ours MiB':>10}{'PyDMD s':>10}{'PyDMD MiB':>11}{'speed-up':>10}"
    print(header + f"{'mem ratio':>11}{'max rel eig diff':>18}")
    print("-" * (len(header) + 29))
    for r in (24, 90):
        t_ours, m_ours, ours = measure(lambda r=r: HankelDMD(delays=60, rank=r, dt=1 / FS).fit(Y), args.repeats)
        row = f"{f'20,000 x 18, r = {r} ({ours.method_})':<34}{t_ours:>9.3f}{m_ours:>10.1f}"
        if pydmd is not None:
            t_ref, m_ref, ref = measure_once(lambda r=r: pydmd.HankelDMD(svd_rank=r, d=60).fit(Y.T))
            a, b = sorted_eigs(ours.eigenvalues_), sorted_eigs(np.asarray(ref.eigs))
            diff = np.max(np.abs(a - b)) / np.max(np.abs(b))
            row += f"{t_ref:>10.2f}{m_ref:>11.1f}{t_ref / t_ours:>9.0f}x{m_ref / m_ours:>10.1f}x{diff:>18.1e}"
        print(row, flush=True)

    Y_hour = record(3600.0, seed=1)
    t, m, est = measure(lambda: HankelDMD(delays=60, rank=90, dt=1 / FS).fit(Y_hour), 1)
    print(f"{f'1 h at 80 Hz {Y_hour.shape[0]:,} x {p}, r = 90 ({est.method_})':<34}{t:>9.3f}{m:>10.1f}", flush=True)

    Y_half = Y_hour[: int(1800 * FS)]
    d = 4800
    P, cols = d * p, Y_half.shape[0] - d
    for r in (24, 90):
        t, m, est = measure(lambda r=r: HankelDMD(delays=d, rank=r, dt=1 / FS, method="randomized").fit(Y_half), 1)
        label = f"30 min, d = {d} (60 s), r = {r} ({est.method_})"
        print(f"{label:<34}{t:>9.2f}{m:>10.1f}", flush=True)
    print(
        f"  (d = {d}: the dense Hankel matrix is {P:,} x {cols:,} = {8 * P * cols / 1e9:.0f} GB, its Gram matrix "
        f"{8 * P**2 / 1e9:.0f} GB)"
    )
    table = sorted(est.mode_table(), key=lambda row: -row["energy"])[:6]
    print(
        "  d = 4800, r = 90, six strongest modes (Hz / damping % / phase locking / kind): "
        + ", ".join(
            f"{x['frequency_hz']:.3f}/{100 * x['damping_ratio']:.2f}/{x['phase_locking']:.2f}/{x['kind']}"
            for x in table
        )
    )


if __name__ == "__main__":
    main()
