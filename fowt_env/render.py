"""Rendering of :class:`fowt_env.env.SparEnv` frames with matplotlib (Agg for ``rgb_array``)."""

from __future__ import annotations

import numpy as np

__all__ = ["render_frame"]


def render_frame(env, fig=None, interactive: bool = False):
    """Draw the current state of ``env``; returns (RGB uint8 array (H, W, 3), figure).

    Left: the tower and spar in the fore-aft plane (deflection exaggerated x20 for the tower's bending), gauges
    coloured green (live) or red (dropped). Right: per observed channel, truth, measured value and -- if a
    virtual-sensor wrapper is active -- the estimate, each normalised by the channel's running scale.
    """
    import matplotlib

    if not interactive:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    last = env._last
    st = env.model.structure
    x = env._sim.state
    q = x[:10]
    if fig is None:
        fig = plt.figure(figsize=(8, 4.5), dpi=80)
    fig.clf()
    ax0 = fig.add_axes([0.07, 0.1, 0.28, 0.8])
    ax1 = fig.add_axes([0.45, 0.1, 0.52, 0.8])

    # --- structure in the FA plane
    z_sp = np.linspace(-120.0, st.data.tower_base_height, 20)
    x_sp = q[0] + q[4] * z_sp
    z_tw = np.linspace(st.data.tower_base_height, st.data.tower_top_height, 40)
    phi = st.shapes.value(z_tw)
    x_tw = q[0] + q[4] * z_tw + 20.0 * (phi[0] * q[6] + phi[1] * q[7])
    ax0.plot(x_sp, z_sp, color="0.3", lw=6, solid_capstyle="butt")
    ax0.plot(x_tw, z_tw, color="tab:blue", lw=3)
    ax0.axhline(0.0, color="tab:cyan", lw=1)
    mask = last.get("mask")
    for g, h in enumerate(env.gauge_heights, start=1):
        names = [f"TwHt{g}ALxt", f"TwHt{g}ALyt", f"TwHt{g}MLyt", f"TwHt{g}MLxt"]
        idx = [env.channels.index(n) for n in names if n in env.channels]
        live = bool(np.all(mask[idx])) if (mask is not None and idx) else True
        xh = q[0] + q[4] * h + 20.0 * float(st.shapes.value(h)[0, 0] * q[6] + st.shapes.value(h)[1, 0] * q[7])
        ax0.plot(xh, h, "o", color="tab:green" if live else "tab:red", ms=7)
    ax0.set_xlim(-20, 50)
    ax0.set_ylim(-125, 100)
    ax0.set_xlabel("fore-aft position (m)\n(tower bending x20)")
    ax0.set_ylabel("height above SWL (m)")
    ax0.set_title(f"t = {env._sim.time:7.2f} s, pitch {np.rad2deg(q[4]):.1f} deg", fontsize=9)

    # --- channel values
    truth = last.get("truth_all")
    if truth is not None:
        tr = truth[env._idx]
        meas = last.get("y")
        est = last.get("estimate")
        scale = np.maximum(np.abs(tr), 1e-9)
        n = len(env.channels)
        pos = np.arange(n)
        ax1.plot(pos, tr / scale, "k_", ms=12, label="truth")
        live = mask.astype(bool) if mask is not None else np.ones(n, bool)
        ax1.plot(pos[live], (meas / scale)[live], "o", color="tab:green", ms=4, label="measured")
        ax1.plot(pos[~live], np.zeros((~live).sum()), "x", color="tab:red", ms=6, label="dropped")
        if est is not None:
            ax1.plot(pos, np.asarray(est) / scale, "s", mfc="none", color="tab:orange", ms=6, label="estimate")
        ax1.set_xticks(pos)
        ax1.set_xticklabels(env.channels, rotation=90, fontsize=6)
        ax1.set_ylim(-3, 3)
        ax1.set_ylabel("value / |truth|")
        ax1.legend(fontsize=7, loc="upper right", ncol=4)
    fig.canvas.draw()
    frame = np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()
    if interactive:
        plt.pause(0.001)
    return frame, fig
