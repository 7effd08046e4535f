"""Steps per second of the Gymnasium environment (dt = 0.0125 s, one sample per step).

Prints, measured in this run: a single ``fowt_env/Spar-v0`` through ``gymnasium.make`` (with its checker and
TimeLimit wrappers) and unwrapped, with and without random dropouts, and an 8-env ``SyncVectorEnv`` and
``AsyncVectorEnv``; each also as a real-time factor (simulated seconds per wall second; reference: real time).
Target (issue 15) >= 15,000 steps/s for a single env, goal 20,000. Each rate is the best of ``--repeats`` timed
passes over the same env (after its warm-up), so that other jobs on a shared machine inflate it as little as
possible; a single env's rate is also given per second of this process's CPU time (what an idle core would show).

Usage: python benchmarks/env_step.py [--steps 20000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import time

import gymnasium as gym
import numpy as np

import fowt_env
from fowt_env.faults import RandomDropout

DT = 0.0125


def rate(env: gym.Env | gym.vector.VectorEnv, n: int, vector: bool = False, repeats: int = 1) -> float:
    """Best rate (steps/s) of ``repeats`` passes of ``n`` zero-action steps, after a reset and 200 steps."""
    return rates(env, n, vector, repeats)[0]


def rates(env: gym.Env | gym.vector.VectorEnv, n: int, vector: bool = False, repeats: int = 1
          ) -> tuple[float, float]:
    """Best wall-clock rate and best rate per second of this process's CPU time (steps/s) of ``repeats`` passes
    of ``n`` zero-action steps, after a reset and 200 steps."""
    env.reset(seed=0)
    act = np.zeros((env.num_envs, 2) if vector else 2, dtype=np.float32)
    for _ in range(200):
        env.step(act)
    wall = cpu = 0.0
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(n):
            env.step(act)
        wall = max(wall, n / (time.perf_counter() - t0))
        cpu = max(cpu, n / max(time.process_time() - c0, 1e-9))
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    n, rep = args.steps, args.repeats
    print(f"env steps per second, dt = {DT} s, best of {rep} passes of {n} steps after 200 warm-up steps; load "
          f"average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows = [
        ("gym.make('fowt_env/Spar-v0')", rates(gym.make("fowt_env/Spar-v0", max_episode_steps=None), n, repeats=rep)),
        ("  + RandomDropout(0.2, 2 s), plane FA",
         rates(gym.make("fowt_env/Spar-v0", plane="FA", faults=RandomDropout(0.2, 2.0), max_episode_steps=None), n,
               repeats=rep)),
        ("unwrapped SparEnv", rates(fowt_env.SparEnv(), n, repeats=rep)),
    ]
    for name, (r, r_cpu) in rows:
        print(f"  {name:<42} {r:9.0f} steps/s  = {r * DT:6.0f}x real time ({r_cpu:.0f} per CPU second)")
    for cls in (gym.vector.SyncVectorEnv, gym.vector.AsyncVectorEnv):
        venv = cls([lambda: gym.make("fowt_env/Spar-v0", max_episode_steps=None)] * 8)
        r = rate(venv, max(n // 8, 500), vector=True, repeats=rep)
        venv.close()
        print(f"  {cls.__name__ + ' x 8':<42} {r * 8:9.0f} env-steps/s ({r:.0f} vector steps/s)")
    print("  target (issue 15) >= 15,000 steps/s single env, goal 20,000")


if __name__ == "__main__":
    main()
