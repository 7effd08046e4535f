"""Steps per second of the Gymnasium environment (dt = 0.0125 s, one sample per step).

Prints, measured in this run: a single ``fowt_env/Spar-v0`` through ``gymnasium.make`` (with its checker and
TimeLimit wrappers) and unwrapped, with and without random dropouts, and an 8-env ``SyncVectorEnv`` and
``AsyncVectorEnv``; each also as a real-time factor (simulated seconds per wall second; reference: real time).
Target (issue 15) >= 15,000 steps/s for a single env, goal 20,000. Each rate is the best of ``--repeats`` timed
passes over the same env (after its warm-up), so that other jobs on a shared machine inflate it as little as
possible.

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
    env.reset(seed=0)
    act = np.zeros((env.num_envs, 2) if vector else 2, dtype=np.float32)
    for _ in range(200):
        env.step(act)
    best = 0.0
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(n):
            env.step(act)
        best = max(best, n / (time.perf_counter() - t0))
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    n, rep = args.steps, args.repeats
    print(f"env steps per second, dt = {DT} s, best of {rep} passes of {n} steps after 200 warm-up steps; load "
          f"average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    rows = [
        ("gym.make('fowt_env/Spar-v0')", rate(gym.make("fowt_env/Spar-v0", max_episode_steps=None), n, repeats=rep)),
        ("  + RandomDropout(0.2, 2 s), plane FA",
         rate(gym.make("fowt_env/Spar-v0", plane="FA", faults=RandomDropout(0.2, 2.0), max_episode_steps=None), n,
              repeats=rep)),
        ("unwrapped SparEnv", rate(fowt_env.SparEnv(), n, repeats=rep)),
    ]
    for name, r in rows:
        print(f"  {name:<42} {r:9.0f} steps/s  = {r * DT:6.0f}x real time")
    for cls in (gym.vector.SyncVectorEnv, gym.vector.AsyncVectorEnv):
        venv = cls([lambda: gym.make("fowt_env/Spar-v0", max_episode_steps=None)] * 8)
        r = rate(venv, max(n // 8, 500), vector=True, repeats=rep)
        venv.close()
        print(f"  {cls.__name__ + ' x 8':<42} {r * 8:9.0f} env-steps/s ({r:.0f} vector steps/s)")
    print("  target (issue 15) >= 15,000 steps/s single env, goal 20,000")


if __name__ == "__main__":
    main()
