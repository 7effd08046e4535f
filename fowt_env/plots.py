"""Figures people would rather look at than read (matplotlib, Agg-safe)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.signal import welch

__all__ = [
    "eigenvalue_figure",
    "psd_figure",
    "singular_value_figure",
    "spectrogram_figure",
    "stabilization_figure",
]


_KIND_STYLE = {"structural": ("tab:blue", "o"), "harmonic": ("tab:red", "D"), "rotor_band": ("tab:orange", "s"),
               "unmodelled": ("tab:purple", "v"), "noise": ("0.6", ".")}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _prepare(path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    _pyplot().close(fig)
    return path


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
    plt = _pyplot()
    path = _prepare(path)
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
    return _save(fig, path)


def eigenvalue_figure(dmd, mode_table: list[dict], path: str | Path) -> Path:
    """DMD eigenvalues on the unit circle (left) and frequency vs damping (right), coloured by mode kind.

    Parameters
    ----------
    dmd : estimators.HankelDMD
        A fitted model.
    mode_table : list of dict
        Its :meth:`~estimators.HankelDMD.mode_table` (gives each eigenvalue's kind).
    path : str or Path
        Output PNG file.

    Returns
    -------
    Path
    """
    plt = _pyplot()
    path = _prepare(path)
    kind = np.full(dmd.eigenvalues_.size, "noise", dtype=object)
    for row in mode_table:
        i = row["index"]
        conj = np.argmin(np.abs(dmd.eigenvalues_ - np.conj(dmd.eigenvalues_[i])))
        kind[[i, conj]] = row["kind"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 5))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(th), np.sin(th), color="0.3", lw=0.8)
    for k, (color, marker) in _KIND_STYLE.items():
        sel = kind == k
        mu = dmd.eigenvalues_[sel]
        ax.scatter(mu.real, mu.imag, s=22, color=color, marker=marker, label=f"{k} ({sel.sum()})")
        f = np.abs(dmd.frequencies_hz_[sel])
        bx.scatter(f, 100 * dmd.damping_ratios_[sel], s=22, color=color, marker=marker, label=k)
    ax.set_aspect("equal")
    ax.set_xlabel("Re(mu)")
    ax.set_ylabel("Im(mu)")
    ax.set_title(f"Discrete DMD eigenvalues (rank {dmd.rank_}, d = {dmd.delays_})")
    ax.legend(loc="lower left", fontsize=8)
    ax.grid(alpha=0.3)
    bx.set_xlabel("frequency (Hz)")
    bx.set_ylabel("damping ratio (%)")
    bx.set_title("Modes: frequency and damping")
    bx.set_ylim(-2, 25)
    bx.grid(alpha=0.3)
    return _save(fig, path)


def singular_value_figure(dmd, path: str | Path) -> Path:
    """Singular values of the Hankel matrix with the rank kept and the Gavish-Donoho threshold.

    Parameters
    ----------
    dmd : estimators.HankelDMD
        A fitted model.
    path : str or Path
        Output PNG file.

    Returns
    -------
    Path
    """
    from estimators.hankel_dmd import svht_rank

    plt = _pyplot()
    path = _prepare(path)
    s = np.asarray(dmd.singular_values_)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    k = np.arange(1, s.size + 1)
    ax.semilogy(k, s / s[0], ".", ms=3, color="C0", label="singular values (normalised)")
    ax.axvline(dmd.rank_, color="tab:red", lw=1.2, label=f"rank used: {dmd.rank_}")
    if dmd.method_ != "randomized":
        shape = (dmd.delays_ * dmd.n_features_in_, dmd.n_snapshots_)
        r_gd = svht_rank(s, shape)
        ax.axvline(r_gd, color="tab:green", ls="--", lw=1.0, label=f"Gavish-Donoho threshold: {r_gd}")
    ax.set_xlabel("index")
    ax.set_ylabel("sigma_k / sigma_1")
    ax.set_title("Singular-value spectrum of the Hankel matrix")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return _save(fig, path)


def spectrogram_figure(x: np.ndarray, dt: float, name: str, unit: str, path: str | Path,
                       f_max: float = 3.0, tracks: dict[str, np.ndarray] | None = None) -> Path:
    """Spectrogram (dB) of one channel: how the spectrum moves with time (rotor speed, sea state).

    Parameters
    ----------
    x : ndarray (n_samples,)
        Signal (channel units).
    dt : float
        Sample interval (s).
    name, unit : str
        Channel name and unit (labels).
    path : str or Path
        Output PNG file.
    f_max : float
        Upper frequency (Hz).
    tracks : dict of str to ndarray (n_samples,), optional
        Frequencies (Hz) to draw over the spectrogram, one per sample of ``x`` (e.g. ``{"3P": 3 * rotor
        frequency}``), averaged over each spectrogram window.

    Returns
    -------
    Path
    """
    from scipy.signal import spectrogram

    plt = _pyplot()
    path = _prepare(path)
    fs = 1.0 / dt
    nper = int(min(len(x), 2 ** int(np.log2(max(fs * 40.0, 64)))))
    f, t, S = spectrogram(x - np.mean(x), fs=fs, nperseg=nper, noverlap=nper * 3 // 4)
    sel = f <= f_max
    fig, ax = plt.subplots(figsize=(9, 4.5))
    im = ax.pcolormesh(t, f[sel], 10 * np.log10(S[sel] + 1e-300), shading="auto", cmap="viridis")
    fig.colorbar(im, ax=ax, label=f"PSD (dB re 1 ({unit})²/Hz)")
    for k, (label, track) in enumerate((tracks or {}).items()):
        track = np.asarray(track, dtype=float)
        if track.shape != (len(x),):
            raise ValueError(f"tracks[{label!r}] must have shape ({len(x)},), got {track.shape}")
        win = np.ones(nper) / nper
        smooth = np.convolve(track, win, mode="same")[(t * fs).astype(int).clip(0, len(x) - 1)]
        ax.plot(t, smooth, ls="--", lw=1.2, color=("w", "orange", "r", "c")[k % 4], label=label)
    if tracks:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_ylim(f[sel][0], f[sel][-1])
    ax.set_xlabel("time (s)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"Spectrogram of {name}")
    return _save(fig, path)


def stabilization_figure(ssi, Y: np.ndarray, dt: float, path: str | Path, reference=None,
                         f_max: float | None = None) -> Path:
    """SSI-COV stabilisation diagram over the averaged PSD of the channels, with the selected modes marked.

    Filled black circles are exactly the poles of the modes :meth:`~estimators.SSICov.mode_table` reports
    (stable at ``ssi.min_stable_`` orders or more), red diamonds the poles of its harmonic lines; a pole that
    passed the stability test against the next lower order without forming a mode is hollow, any other pole a
    grey cross.

    Parameters
    ----------
    ssi : estimators.SSICov
        A fitted model.
    Y : ndarray (n_samples, n_channels)
        The data it was fitted on (any scaling; each channel's PSD is normalised before averaging).
    dt : float
        Sample interval of ``Y`` (s).
    path : str or Path
        Output PNG file.
    reference : fowt_env.identification.LinearReference, optional
        Linear-model frequencies to mark (dashed grey, labelled).
    f_max : float, optional
        Upper frequency (Hz); default the highest pole shown, capped at Nyquist.

    Returns
    -------
    Path
    """
    plt = _pyplot()
    path = _prepare(path)
    rows = ssi.stabilization_
    if f_max is None:
        top = max((float(np.max(r["frequencies_hz"])) for r in rows if len(r["frequencies_hz"])), default=1.0)
        f_max = min(1.05 * top, 0.5 / dt)
    fig, ax = plt.subplots(figsize=(10, 5.5))
    n_min = getattr(ssi, "min_stable_", None)
    at = f" (>= {n_min} orders)" if n_min else ""
    kinds = {  # category: (label, style), drawn in this order
        "pole": ("pole", dict(marker="x", color="0.7", s=10)),
        "loose": ("stable vs. lower order, no mode", dict(marker="o", facecolors="none", edgecolors="0.45", s=12,
                                                          linewidths=0.7)),
        "line": ("stable pole of a harmonic line", dict(marker="D", color="tab:red", s=10)),
        "mode": (f"stable pole of a reported mode{at}", dict(marker="o", color="k", s=9)),
    }
    points: dict[str, list[tuple[float, int]]] = {k: [] for k in kinds}
    for r in rows:
        f = np.asarray(r["frequencies_hz"])
        n = f.size
        mode = np.asarray(r.get("mode", np.full(n, -1))) >= 0
        line = np.asarray(r.get("line", np.full(n, -1))) >= 0
        loose = np.asarray(r.get("stable", np.zeros(n, bool)), dtype=bool) & ~mode & ~line
        for key, sel in (("mode", mode), ("line", line & ~mode), ("loose", loose), ("pole", ~(mode | line | loose))):
            points[key] += [(float(fk), int(r["order"])) for fk in f[sel & (f <= f_max)]]
    for key, (label, style) in kinds.items():
        if points[key]:
            xy = np.array(points[key])
            ax.scatter(xy[:, 0], xy[:, 1], label=label, **style)
    for k, fk in enumerate(ssi.frequencies_hz_):
        ax.axvline(fk, color="tab:blue", lw=1.0, alpha=0.6, label="reported mode" if k == 0 else None)
    for k, h in enumerate(getattr(ssi, "harmonics_", [])):
        ax.axvline(h["frequency_hz"], color="tab:red", ls=":", lw=1.0, label="harmonic line" if k == 0 else None)
    if reference is not None:
        for lab, fk in zip(reference.labels, reference.frequencies_hz, strict=True):
            if fk <= f_max:
                ax.axvline(fk, color="0.4", ls="--", lw=0.8)
                ax.text(fk, 1.0, f" {lab}", rotation=90, va="top", ha="left", fontsize=7, color="0.3",
                        transform=ax.get_xaxis_transform())
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("model order")
    ax.set_xlim(0.0, f_max)
    ax.set_title("SSI-COV stabilisation diagram")
    bx = ax.twinx()
    nper = int(min(len(Y), 2 ** int(np.log2(max(40.0 / dt, 256)))))
    f, P = welch(Y - Y.mean(axis=0), fs=1.0 / dt, nperseg=nper, axis=0)
    P = np.mean(P / np.maximum(P.max(axis=0, keepdims=True), 1e-300), axis=1)
    sel = f <= f_max
    bx.semilogy(f[sel], P[sel], color="tab:orange", lw=0.9, alpha=0.8, label="mean normalised PSD")
    bx.set_ylabel("mean normalised PSD (-)")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = bx.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper right", fontsize=8)
    return _save(fig, path)
