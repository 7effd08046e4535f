"""Lesson 4 -- dropouts in the environment: sensors fail, the truth does not.

The physics (and the engineering). Tower accelerometers and strain gauges on a real turbine drop out: cables,
loggers and wireless links fail for seconds to hours. ``fowt_env/Spar-v0`` is the surrogate of lessons 1-3 as a
Gymnasium environment: each step advances the turbine by one sample (0.0125 s) and returns the 18 (or 36) tower
channels, a ``mask`` saying which are alive, and -- in ``info["truth"]`` -- the noise-free values the sensors
should have read. Faults from ``fowt_env.faults`` act only on what the agent observes, never on the truth.
A *virtual sensor* fills in the lost channels from the live ones; ``fowt_env.VirtualSensorWrapper`` adds its
full-channel estimate to every observation.

What this script does. One episode at OLC 5, fore-aft plane, with ``RandomDropout(rate=0.2, mean_burst_s=2.0)``
-- every channel independently lost 20 % of the time, in bursts of 2 s on average (a two-state Markov chain) --
and the simplest virtual sensor, ``HoldLastValue``: a lost channel keeps its last reading. It reports how often
each channel was lost and the reconstruction error on the lost samples (NRMSE: RMS error over the range of the
truth), and plots the dropout pattern and one channel.

What to look for.

* The lost fraction is near 20 % overall but differs between channels: a short episode holds only a few bursts
  per channel. The bursts in the mask plot are independent across channels.
* Holding the last value is fine for a fraction of a second and poor after that. The tower-top acceleration is
  a slow drift -- the platform pitches, so the tilted accelerometer reads part of gravity -- plus an oscillation
  at the 1st tower mode (~0.5 Hz): the held value keeps up with the drift but loses the oscillation within a
  second. Its error is the floor that every real virtual sensor must beat (lessons 6 and 7).
* The environment never shows NaN: a lost channel reads 0.0 with mask 0.

Writes ``04_dropouts.png``. Next: lesson 5 (``05_dmd_identification.py``) learns the tower's dynamics from the
measured channels alone -- the model that lesson 6 turns into a virtual sensor.

Usage: python examples/04_dropouts_in_the_env.py [--quick] [--seconds 120] [--out DIR]
"""

import argparse
from pathlib import Path

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import fowt_env
from estimators.baseline import HoldLastValue
from fowt_env.faults import RandomDropout

RATE, MEAN_BURST_S = 0.2, 2.0


def main(quick: bool = False, out: str = ".", seconds: float | None = None) -> dict:
    seconds = (30.0 if quick else 120.0) if seconds is None else float(seconds)
    env = fowt_env.VirtualSensorWrapper(
        gym.make("fowt_env/Spar-v0", case=5, plane="FA", faults=RandomDropout(rate=RATE, mean_burst_s=MEAN_BURST_S),
                 max_episode_steps=None),
        HoldLastValue(),
    )
    obs, info = env.reset(seed=42)
    channels = info["channels"]
    n = int(round(seconds / env.unwrapped.dt))
    masks, est, truth, sensors, t = [], [], [], [], []
    for _ in range(n):
        obs, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))  # baseline control
        masks.append(obs["mask"].astype(bool))
        est.append(obs["estimate"])
        sensors.append(obs["sensors"])
        truth.append(info["truth"])
        t.append(info["time"])
    env.close()
    masks, est, truth, sensors, t = map(np.array, (masks, est, truth, sensors, t))
    lost = ~masks
    err = np.where(lost, est - truth, np.nan)
    rng = truth.max(axis=0) - truth.min(axis=0)
    n_lost = lost.sum(axis=0)
    nrmse = np.sqrt(np.nansum(err**2, axis=0) / np.maximum(n_lost, 1)) / rng
    nrmse[n_lost == 0] = np.nan  # a channel never lost has no reconstruction error to report
    print(f"{seconds:.0f} s of OLC 5 with RandomDropout({RATE}, {MEAN_BURST_S} s): {100 * lost.mean():.1f} % of "
          "samples lost")
    print(f"{'channel':<12}{'lost %':>8}{'NRMSE on lost samples (hold last value)':>42}")
    for c, lf, e in zip(channels, lost.mean(axis=0), nrmse, strict=True):
        print(f"{c:<12}{100 * lf:>8.1f}{e:>42.3f}")

    k = channels.index("TwHt9ALxt")
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(10, 7), gridspec_kw={"height_ratios": [1.2, 1.0]})
    ax.imshow(lost.T, aspect="auto", interpolation="nearest", cmap="Reds", vmin=0, vmax=1.6,
              extent=(t[0], t[-1], len(channels) - 0.5, -0.5))
    ax.set_yticks(range(len(channels)))
    ax.set_yticklabels(channels, fontsize=6)
    ax.set_xlabel("time (s)")
    ax.set_title(f"Dropout pattern: red = channel lost ({100 * lost.mean():.1f} % of samples, "
                 f"target {100 * RATE:.0f} %)")
    bx.plot(t, truth[:, k], "k", lw=0.8, label="truth (info['truth'])")
    bx.plot(t, est[:, k], color="tab:orange", lw=0.8, label="virtual sensor (hold last value)")
    bx.fill_between(t, truth[:, k].min(), truth[:, k].max(), where=lost[:, k], color="tab:red", alpha=0.15,
                    label="sensor lost")
    bx.set_xlabel("time (s)")
    bx.set_ylabel("TwHt9ALxt (m/s²)")
    bx.set_title(f"Tower-top fore-aft acceleration: NRMSE on lost samples {nrmse[k]:.3f}")
    bx.legend(fontsize=8, ncol=3, loc="upper right")
    fig.suptitle("fowt_env/Spar-v0, OLC 5, fore-aft plane, random dropouts")
    fig.tight_layout()
    path = Path(out) / "04_dropouts.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
    return {"seconds": seconds, "channels": channels, "lost_fraction": float(lost.mean()),
            "lost_fraction_per_channel": lost.mean(axis=0), "nrmse": nrmse,
            "sensors_zero_where_lost": bool(np.all(sensors[lost] == 0.0)), "figures": [path]}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="30 s instead of 120 s")
    ap.add_argument("--seconds", type=float, default=None, help="episode length (s); overrides --quick")
    ap.add_argument("--out", default=".", help="folder for the figure")
    a = ap.parse_args()
    main(quick=a.quick, out=a.out, seconds=a.seconds)
