"""Figures people would rather look at than read (matplotlib, Agg-safe)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.signal import welch

__all__ = ["psd_figure"]


def psd_figure(
    record,
    channels: list[str],
    path: str | Path,
    modes: list[tuple[str, float]] | None = None,
    rotor_rpm: float | None = None,
    f_max: float = 3.0,
    title: str | None = None,
) -> Path:
    """Welch PSDs of some channels with modal frequencies and 1P/3P/6P lines marked; saved as PNG.

    Parameters
    ----------
    record : surrogates.Record
        The record to plot.
    channels : list of str
        Channel names (one panel each).
    path : str or Path
        Output PNG file.
    modes : list of (label, frequency_hz), optional
        Modal frequencies to mark (dashed grey).
    rotor_rpm : float, optional
        Mean rotor speed; 1P, 3P and 6P are marked (dotted red) when given.
    f_max : float
        Upper frequency limit (Hz).
    title : str, optional
        Figure title.

    Returns
    -------
    Path
        The written file.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fs = record.fs
    nperseg = int(min(len(record), 2 ** int(np.log2(max(fs * 120.0, 256)))))
    fig, axes = plt.subplots(len(channels), 1, figsize=(9, 3.0 * len(channels)), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], channels, strict=True):
        f, p = welch(record[name] - np.mean(record[name]), fs=fs, nperseg=nperseg)
        sel = (f > 0) & (f <= f_max)
        ax.semilogy(f[sel], p[sel], lw=1.0, color="C0")
        unit = record.units[record.channels.index(name)]
        ax.set_ylabel(f"PSD of {name}\n(({unit})²/Hz)")
        for label, fm in modes or []:
            if fm <= f_max:
                ax.axvline(fm, color="0.5", ls="--", lw=0.8)
                ax.text(fm, 1.0, f" {label}", rotation=90, va="top", ha="left", fontsize=7, color="0.35",
                        transform=ax.get_xaxis_transform())
        if rotor_rpm:
            for k, lab in ((1, "1P"), (3, "3P"), (6, "6P")):
                fk = k * rotor_rpm / 60.0
                if fk <= f_max:
                    ax.axvline(fk, color="tab:red", ls=":", lw=1.0)
                    ax.text(fk, 0.02, f" {lab}", rotation=90, va="bottom", ha="left", fontsize=8, color="tab:red",
                            transform=ax.get_xaxis_transform())
        ax.grid(True, which="both", alpha=0.3)
    axes[-1, 0].set_xlabel("frequency (Hz)")
    axes[-1, 0].set_xlim(0.0, f_max)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
