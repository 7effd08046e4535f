"""Replayed episodes of 1 h, 6 h and 24 h in SparEnv: speed against real time and peak memory (issue 16).

Writes synthetic measured inputs -- a JONSWAP wave elevation (Hs 5 m, Tp 10 s) and a Kaimal hub wind (12 m/s,
TI 0.12), sampled at ``--record-dt`` (default 20 Hz) -- to a record file (``Record.save``, a compressed ``.npz``),
then runs one episode per length in a fresh process: ``SparEnv(replay=FILE, control_dt=...)`` stepped with zero
actions until it truncates at the end of the inputs. Each child prints its wall-clock and CPU time, the ratio of
simulated to wall-clock time, and its peak resident memory (``resource.getrusage(RUSAGE_SELF).ru_maxrss``): flat
memory means the 24 h peak equals the 1 h peak, as the inputs are read chunk by chunk and never held whole.

``--seams`` instead measures the chunked forcing (:class:`surrogates.replay_stream.ReplayForcing`, 600 s windows)
against the whole-record transform (:func:`surrogates.replay.replay_forcing`) on a 2 h record: the largest
deviation of each forcing component over the record, as a fraction of its standard deviation.

Usage::

    python benchmarks/replay_env.py                      # 1 h, 6 h, 24 h at 80 Hz output, 1 s control steps
    python benchmarks/replay_env.py --hours 1 6 --dir /tmp/replay
    python benchmarks/replay_env.py --seams
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def write_inputs(path: Path, hours: float, dt: float, seed: int = 1) -> Path:
    """A synthetic measured record (Wave1Elev, Wind1VelX) of ``hours`` at sample time ``dt`` (s)."""
    import surrogates
    from surrogates.waves import jonswap_spectrum
    from surrogates.wind import synthesize_wind

    n = int(round(hours * 3600.0 / dt))
    rng = np.random.default_rng(seed)
    f = np.fft.rfftfreq(n, dt)
    s = np.zeros_like(f)
    s[1:] = jonswap_spectrum(f[1:], 5.0, 10.0, 3.3)
    amp = np.sqrt(2.0 * s * f[1]) * n / 2.0
    eta = np.fft.irfft(amp * np.exp(2j * np.pi * rng.uniform(size=f.size)), n=n)
    hub = synthesize_wind(12.0, 0.12, n * dt, dt, seed=seed + 1).hub[:n]
    rec = surrogates.Record(np.arange(n) * dt, np.column_stack([eta, hub]), ["Wave1Elev", "Wind1VelX"],
                            ["m", "m/s"], {"source": "benchmarks/replay_env.py", "hours": hours})
    return rec.save(path)


def child(path: str, control_dt: float, dt: float) -> None:
    """One replayed episode to its end; prints one JSON line."""
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    from fowt_env.env import SparEnv

    env = SparEnv(replay=path, dt=dt, control_dt=control_dt)
    t_setup = time.perf_counter() - t_wall
    env.reset(seed=0)
    action = np.zeros(2, dtype=np.float32)
    steps, truncated, terminated = 0, False, False
    while not (truncated or terminated):
        _, _, terminated, truncated, info = env.step(action)
        steps += 1
    wall = time.perf_counter() - t_wall
    cpu = time.process_time() - t_cpu
    simulated = info["time"] + env._sim.warmup * env.dt
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps({"simulated_s": simulated, "steps": steps, "wall_s": wall, "cpu_s": cpu, "setup_s": t_setup,
                      "ratio_wall": simulated / wall, "ratio_cpu": simulated / cpu, "peak_rss_mib": peak_mib,
                      "terminated": terminated}))


def seams(hours: float = 2.0, dt: float = 0.05) -> None:
    """Chunked (600 s windows) vs whole-record replayed forcing: max |difference| / std per component."""
    import surrogates
    from fowt_env.replay import record_case
    from surrogates.model import INPUT_BLOCKS
    from surrogates.replay import MeasuredWaves, MeasuredWind, replay_forcing
    from surrogates.replay_stream import ArraySeries, ReplayForcing, StreamedWaves, StreamedWind

    with tempfile.TemporaryDirectory() as tmp:
        rec = surrogates.Record.load(write_inputs(Path(tmp) / "seams.npz", hours, dt))
    lc = record_case(rec)
    sim = surrogates.Simulator(surrogates.FOWTModel(), lc, 0.0125)
    n_steps = int((rec.t[-1] - rec.t[0]) / sim.dt_int) - 2
    t0 = time.perf_counter()
    u_w, v_w, _, _ = replay_forcing(sim, n_steps, 0.0, MeasuredWaves.from_record(rec), MeasuredWind.from_record(rec),
                                    np.random.SeedSequence(0))
    t_whole = time.perf_counter() - t0
    series = ArraySeries(0.0, dt, np.column_stack([rec["Wave1Elev"], rec["Wind1VelX"]]))
    forcing = ReplayForcing(sim, StreamedWaves(series, 0), StreamedWind(series, "hub", hub_column=1))
    chunk = int(round(600.0 / sim.dt_int))
    t0 = time.perf_counter()
    parts = [forcing(k0, chunk) for k0 in range(0, n_steps, chunk)]
    t_chunks = time.perf_counter() - t0
    u_c = np.concatenate([p[0][:chunk] for p in parts])[: n_steps + 1]
    v_c = np.concatenate([p[1][:chunk] for p in parts])[: n_steps + 1]

    def err(a: np.ndarray, b: np.ndarray) -> float:
        sd = b.std(axis=0)
        return float(np.max(np.abs(a - b)[:, sd > 0] / sd[sd > 0]))

    print(f"{hours:g} h record at {1 / dt:g} Hz, 600 s windows; whole-record transform {t_whole:.1f} s, chunked "
          f"{t_chunks:.1f} s")
    for name in ("elev", "wave", "wind"):
        b = INPUT_BLOCKS[name]
        e = err(u_c[:, b].reshape(len(u_c), -1), u_w[:, b].reshape(len(u_w), -1))
        print(f"  {name:5s} max |chunked - whole| / std = {e:.1e}")
    print(f"  strip velocities (24 strips)        = {err(v_c[..., 0], v_w[..., 0]):.1e}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hours", type=float, nargs="+", default=[1.0, 6.0, 24.0])
    ap.add_argument("--record-dt", type=float, default=0.05, help="sample time of the measured inputs (s)")
    ap.add_argument("--dt", type=float, default=0.0125, help="the environment's output sample time (s)")
    ap.add_argument("--control-dt", type=float, default=1.0, help="seconds per env step (s)")
    ap.add_argument("--dir", type=Path, default=None, help="where the input files are written (kept if given)")
    ap.add_argument("--seams", action="store_true", help="measure the chunk seams instead")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args.child, args.control_dt, args.dt)
        return
    if args.seams:
        seams()
        return
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; inputs at {1 / args.record_dt:g} Hz, "
          f"env dt {args.dt} s, control_dt {args.control_dt} s")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.dir or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        rows = []
        for hours in args.hours:
            path = folder / f"replay_{hours:g}h.npz"
            if not path.exists():
                t0 = time.perf_counter()
                write_inputs(path, hours, args.record_dt)
                print(f"  wrote {path.name} ({path.stat().st_size / 2**20:.1f} MiB) in "
                      f"{time.perf_counter() - t0:.1f} s")
            out = subprocess.run([sys.executable, __file__, "--child", str(path), "--control-dt", str(args.control_dt),
                                  "--dt", str(args.dt)], capture_output=True, text=True, check=True)
            res = json.loads(out.stdout.strip().splitlines()[-1])
            rows.append((hours, res))
            print(f"  {hours:5g} h: {res['wall_s']:7.1f} s wall ({res['setup_s']:.1f} s set-up), "
                  f"{res['ratio_wall']:6.0f}x real time ({res['ratio_cpu']:.0f}x per CPU second), "
                  f"peak RSS {res['peak_rss_mib']:.0f} MiB, {res['steps']} steps"
                  + (" TERMINATED" if res["terminated"] else ""))
        base = rows[0][1]["peak_rss_mib"]
        print("peak RSS relative to the first: " + ", ".join(f"{h:g} h {r['peak_rss_mib'] / base:.2f}x"
                                                             for h, r in rows))


if __name__ == "__main__":
    main()
