"""Lesson 3 -- switching effects on: one named piece of physics at a time, same waves, same wind.

The physics. The linear model of lesson 2 (``FOWTModel(effects="none")``) is what a frequency-domain design tool
sees. The real turbine has more: viscous drag on the spar, a catenary mooring that hardens with offset, a rotor
that damps the tower through the wind it pushes, blades that pass the tower three times per revolution...
Each of these is a *named effect* in ``surrogates.EFFECTS`` with a strength (0 off, 1 nominal), so a model is
``FOWTModel(effects="none").with_effects(rotor_3p=1.0)`` or ``FOWTModel().without("aero_damping")``.

What this script does. It simulates OLC 8 (Hs 3 m, Tp 12 s, waves at 45 deg to the 12 m/s wind, so that both
bending planes respond) twice with the *same seed* -- identical waves, wind and rotor azimuth -- once with the
linear model and once with a single effect switched on (``--effect``, default ``rotor_3p``), noise free, and
compares the power spectral densities of three tower channels band by band (platform modes, waves, 1P, 1st tower
mode, 3P, 6P, 2nd tower mode) and the mean values of the platform motions. Because the random forcing is
identical, every difference is the effect itself, not sampling scatter. A band that holds almost no energy can
change by 30 dB and not matter, so besides the change in dB the script reports it as a share of the channel's
variance, and "largest change" is measured that way.

What to look for (default ``rotor_3p``, amplitudes measured on OpenFAST's OC3 Hywind in steady wind): the
side-to-side tower-base moment gains ~20 dB at 3P (the blades' in-plane forces and the yaw moment no longer
cancel when one blade passes the tower) and ~8 dB at the 1st tower mode just below 3P, which the wandering 3P
forcing drives resonantly (broad bands rather than lines: the rotor speed wanders by a couple of rpm in
turbulence); the fore-aft base moment gains ~5 dB at 3P and the tower-top accelerometer ~6 dB at 6P but almost
nothing at 3P, because the thrust dip and the tilt moment of the blade passing the tower push the tower top in
opposite directions (OpenFAST shows them in anti-phase). Nothing changes below 0.3 Hz. Try the others::

    --effect aero_damping       the 1st fore-aft tower peak drops by ~4 dB and the slow platform motion seen by the
                                tower-top accelerometer shrinks (damping); side-to-side does not change
    --effect p_delta            gravity softens the structure: more slow platform motion, a larger mean tilt
                                and a much larger mean tower-base moment
    --effect mooring_nonlinear  the spectra barely move but the means do: the catenary pulls the platform back
                                and down (surge and heave offsets) -- some nonlinearity shows in means only
    --effect quadratic_drag     a little less platform motion (viscous damping); small at this sea state
    --effect gyroscopic         small: the spinning rotor couples fore-aft and side-to-side rates
    --effect rotor_1p           a 1P line (0.2 Hz) from rotor imbalance, tiny next to the wave response here

Writes ``03_effect_<name>.png``. Next: lesson 4 (``04_dropouts_in_the_env.py``) puts the full model in a
Gymnasium environment and starts losing sensors.

Usage: python examples/03_switching_effects_on.py [--effect rotor_3p] [--quick] [--out DIR]
"""

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.signal import welch

import surrogates

CASE = 8  # OLC 8: Hs 3 m, Tp 12 s, waves at 45 deg to the 12 m/s wind
CHANNELS = ("TwHt9ALxt", "TwHt1MLyt", "TwHt1MLxt")  # tower-top FA acceleration, tower-base FA and SS moments
MEAN_CHANNELS = ("PtfmSurge", "PtfmHeave", "PtfmPitch", "TwHt1MLyt")
CAP_DB = 60.0  # a band with no energy at all in one of the models: shown as +-60 dB


def bands(case: surrogates.LoadCase) -> dict[str, tuple[float, float]]:
    """Frequency bands (Hz) where each kind of response lives."""
    p1 = case.rotor_rpm / 60.0
    return {
        "platform": (0.004, 0.05),
        "waves": (0.7 / case.tp, 1.6 / case.tp),
        "1P": (p1 - 0.015, p1 + 0.015),
        "tower_1": (0.42, 0.54),
        "3P": (3 * p1 - 0.06, 3 * p1 + 0.06),
        "6P": (6 * p1 - 0.06, 6 * p1 + 0.06),
        "tower_2": (1.9, 2.8),
    }


def band_powers(f: np.ndarray, p: np.ndarray, bnds: dict) -> dict[str, float]:
    """Integral of a PSD over each band (channel units²)."""
    out = {}
    for name, (lo, hi) in bnds.items():
        sel = (f >= lo) & (f < hi)
        out[name] = float(np.trapezoid(p[sel], f[sel]))
    return out


def change_db(on: float, off: float) -> float:
    """10 log10(on / off), capped at +-CAP_DB (a band with no energy at all in one model)."""
    tiny = 1e-300
    return float(np.clip(10.0 * np.log10((on + tiny) / (off + tiny)), -CAP_DB, CAP_DB))


def main(quick: bool = False, out: str = ".", effect: str = "rotor_3p") -> dict:
    if effect not in surrogates.EFFECTS:
        raise ValueError(f"effect must be one of {sorted(surrogates.EFFECTS)}, got {effect!r}")
    duration = 300.0 if quick else 1200.0
    case = surrogates.load_case(CASE)
    linear = surrogates.FOWTModel(effects="none")
    with_effect = linear.with_effects(**{effect: 1.0})
    off = surrogates.simulate(linear, case, duration=duration, seed=0, noise=False)
    on = surrogates.simulate(with_effect, case, duration=duration, seed=0, noise=False)
    print(f"{effect}: {surrogates.EFFECTS[effect].doc}")
    print(f"{case.name}, {duration:.0f} s, seed 0, noise free: linear model vs linear + {effect}\n")

    bnds = bands(case)
    nperseg = int(min(len(off), 200.0 * off.fs))  # 200 s segments: 0.005 Hz resolution, enough to see 1P
    spectra, changes, shares, largest = {}, {}, {}, {}
    for ch in CHANNELS:
        f, p_off = welch(off[ch] - off[ch].mean(), fs=off.fs, nperseg=nperseg)
        _, p_on = welch(on[ch] - on[ch].mean(), fs=on.fs, nperseg=nperseg)
        spectra[ch] = (f, p_off, p_on)
        b_off, b_on = band_powers(f, p_off, bnds), band_powers(f, p_on, bnds)
        total = float(np.trapezoid(p_off, f))
        changes[ch] = {b: change_db(b_on[b], b_off[b]) for b in bnds}
        shares[ch] = {b: 100.0 * (b_on[b] - b_off[b]) / total for b in bnds}
        largest[ch] = max(shares[ch], key=lambda b: abs(shares[ch][b]))
    print("change of band power in dB (+ = the effect adds energy), and where the most energy is added or removed:")
    print(f"{'channel':<11}" + "".join(f"{b:>10}" for b in bnds) + "   largest change")
    for ch in CHANNELS:
        b = largest[ch]
        print(f"{ch:<11}" + "".join(f"{changes[ch][b]:>+10.1f}" for b in bnds)
              + f"   {b} ({shares[ch][b]:+.2g} % of the variance)")
    shifts = {ch: float(on[ch].mean() - off[ch].mean()) for ch in MEAN_CHANNELS}
    print("\nchange of mean value:")
    for ch in MEAN_CHANNELS:
        print(f"  {ch:<11}{shifts[ch]:+12.4g} {off.units[off.channels.index(ch)]}")

    # figure: PSDs of both models, bands shaded, and the band-power changes
    fig, axes = plt.subplots(len(CHANNELS) + 1, 1, figsize=(10, 12))
    for ax, ch in zip(axes[:-1], CHANNELS, strict=True):
        f, p_off, p_on = spectra[ch]
        sel = (f > 0) & (f <= 3.0)
        ax.loglog(f[sel], p_off[sel], color="0.3", lw=1.0, label="linear model")
        ax.loglog(f[sel], p_on[sel], color="tab:red", lw=1.0, alpha=0.8, label=f"linear + {effect}")
        for i, (name, (lo, hi)) in enumerate(bnds.items()):
            ax.axvspan(lo, hi, color="tab:green" if name == largest[ch] else "0.85", alpha=0.3)
            ax.text(np.sqrt(lo * hi), 0.98 - 0.07 * (i % 2), name, transform=ax.get_xaxis_transform(),
                    ha="center", va="top", fontsize=7)
        unit = off.units[off.channels.index(ch)]
        ax.set_ylabel(f"PSD of {ch}\n(({unit})²/Hz)")
        ax.set_xlim(0.003, 3.0)
        ax.grid(True, which="both", alpha=0.2)
        ax.legend(fontsize=8, loc="lower left")
    axes[-2].set_xlabel("frequency (Hz)")
    ax = axes[-1]
    x = np.arange(len(bnds))
    width = 0.8 / len(CHANNELS)
    for i, ch in enumerate(CHANNELS):
        ax.bar(x + (i - (len(CHANNELS) - 1) / 2) * width, [shares[ch][b] for b in bnds], width, label=ch)
    ax.axhline(0.0, color="0.3", lw=0.8)
    ax.set_yscale("symlog", linthresh=0.01)
    top = max(abs(v) for ch in CHANNELS for v in shares[ch].values())
    ax.set_ylim(-3.0 * max(top, 0.1), 3.0 * max(top, 0.1))
    ax.set_xticks(x)
    ax.set_xticklabels(list(bnds))
    ax.set_ylabel("band power change\n(% of the linear model's variance)")
    ax.set_xlabel("frequency band")
    ax.legend(fontsize=8)
    fig.suptitle(f"{case.name}, same seed: linear model vs linear + {effect} (green: largest change)")
    fig.tight_layout()
    path = Path(out) / f"03_effect_{effect}.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
    return {"effect": effect, "duration_s": duration, "band_change_db": changes, "band_change_percent": shares,
            "largest_change": largest, "mean_shift": shifts, "figures": [path]}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--effect", default="rotor_3p", choices=sorted(surrogates.EFFECTS))
    ap.add_argument("--quick", action="store_true", help="5-minute records instead of 20 minutes")
    ap.add_argument("--out", default=".", help="folder for the figure")
    a = ap.parse_args()
    main(quick=a.quick, out=a.out, effect=a.effect)
