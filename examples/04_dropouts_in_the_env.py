"""Random sensor dropouts in the environment, with a trivial virtual sensor filling the gaps.

Runs one episode of ``fowt_env/Spar-v0`` (OLC 5, fore-aft plane) with Markov dropouts (20 % of samples lost
in bursts of 2 s on average), lets a hold-last-value sensor reconstruct the lost channels, and reports how
often each channel was lost and the reconstruction error on lost samples -- the floor that Hankel-DMD and
Kalman sensors must beat. Writes a plot of one channel to ``env_random_dropouts.png``.

Usage: python examples/env_random_dropouts.py [--seconds 120] [--out env_random_dropouts.png]
"""

import argparse

import gymnasium as gym
import numpy as np

import fowt_env
from estimators.baseline import HoldLastValue
from fowt_env.faults import RandomDropout


def main(seconds: float = 120.0, out: str = "env_random_dropouts.png") -> dict:
    env = fowt_env.VirtualSensorWrapper(
        gym.make("fowt_env/Spar-v0", case=5, plane="FA", faults=RandomDropout(rate=0.2, mean_burst_s=2.0),
                 max_episode_steps=None),
        HoldLastValue(),
    )
    obs, info = env.reset(seed=42)
    channels = info["channels"]
    n = int(seconds / env.unwrapped.dt)
    masks, est, truth, t = [], [], [], []
    for _ in range(n):
        obs, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
        masks.append(obs["mask"].astype(bool))
        est.append(obs["estimate"])
        truth.append(info["truth"])
        t.append(info["time"])
    masks, est, truth, t = map(np.array, (masks, est, truth, t))
    lost = ~masks
    err = np.where(lost, est - truth, np.nan)
    rng = truth.max(axis=0) - truth.min(axis=0)
    n_lost = lost.sum(axis=0)
    nrmse = np.sqrt(np.nansum(err**2, axis=0) / np.maximum(n_lost, 1)) / rng
    nrmse[n_lost == 0] = np.nan  # a channel never lost has no reconstruction error to report
    print(f"{seconds:.0f} s of OLC 5 with RandomDropout(0.2, 2 s): {100 * lost.mean():.1f} % of samples lost")
    print(f"{'channel':<12}{'lost %':>8}{'NRMSE on lost samples (hold last value)':>42}")
    for c, lf, e in zip(channels, lost.mean(axis=0), nrmse, strict=True):
        print(f"{c:<12}{100 * lf:>8.1f}{e:>42.3f}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = channels.index("TwHt9ALxt")
    fig, ax = plt.subplots(figsize=(9, 3))
    ax.plot(t, truth[:, k], "k", lw=0.8, label="truth")
    ax.plot(t, est[:, k], color="tab:orange", lw=0.8, label="virtual sensor (hold last value)")
    ax.fill_between(t, truth[:, k].min(), truth[:, k].max(), where=lost[:, k], color="tab:red", alpha=0.15,
                    label="sensor lost")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("TwHt9ALxt (m/s²)")
    ax.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return {"lost_fraction": float(lost.mean()), "nrmse": nrmse}


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seconds", type=float, default=120.0)
    p.add_argument("--out", default="env_random_dropouts.png")
    a = p.parse_args()
    main(a.seconds, a.out)
