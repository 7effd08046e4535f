"""Lesson 1 -- waves and wind: a load case is a pair of spectra.

The physics. An operational load case (``surrogates.load_case(n)``) does not prescribe a time series: it
prescribes *statistics*. The sea state is a JONSWAP spectrum S(f) of the wave elevation, fixed by the
significant wave height Hs, the peak period Tp and the peak-enhancement factor gamma (DNV-RP-C205). The wind is
a Kaimal spectrum of the longitudinal turbulence at hub height, fixed by the mean speed V and the turbulence
intensity TI = sigma / V (IEC 61400-1). The simulator turns each spectrum into one random realisation -- a sum
of sinusoids with amplitudes sqrt(2 S(f) df) and random phases -- so a different ``seed`` is a different
storm with the same statistics.

What this script does. It simulates OLC 7 (Hs 3 m, Tp 10 s, waves along a 12 m/s wind), takes the wave
probe ``Wave1Elev`` and the hub anemometer ``Wind1VelX`` from the record, estimates their power spectral
densities (Welch) and draws them over the target spectra. It then estimates the sea state back from the record:
Hs = 4 std(eta) (the spectral definition, 4 sqrt(m0)), Tp = 1 / (frequency of the PSD peak), and the wind's mean
and TI.

What to look for.

* The measured PSDs lie on the targets, with the wave energy in a narrow peak at 1/Tp = 0.1 Hz, and the wind
  energy at very low frequencies (gusts lasting minutes) falling off as f^(-5/3) above about 0.01 Hz.
* The wave PSD is much smoother than a wave-buoy PSD would be. The simulator uses the random-*phase* method:
  every sinusoid has exactly its target amplitude, only the phases are random. In a real sea the amplitudes
  scatter too (Rayleigh), and a periodogram of one record scatters about the target by 100 %.
* Hs from the record agrees with the load case within a few per cent, not exactly: the record is a finite piece
  of the synthesised series and the variance below the lowest frequency of the synthesis grid is missing.
* Because the Kaimal spectrum keeps so much variance at low frequencies, a short record underestimates TI;
  the full run (one hour) gets closer than ``--quick`` (ten minutes).

Writes ``01_waves_and_spectra.png``. Next: lesson 2 (``02_linear_model_and_modes.py``) shows what the turbine
does with these loads -- its natural frequencies, and where they sit relative to these spectra.

Usage: python examples/01_waves_and_spectra.py [--quick] [--out DIR]
"""

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy.signal import welch

import surrogates
from surrogates.waves import jonswap_spectrum
from surrogates.wind import kaimal_spectrum

CASE = 7  # OLC 7: Hs 3 m, Tp 10 s, waves aligned with the 12 m/s wind


def psd(x: np.ndarray, fs: float, segment_s: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch PSD of ``x`` (units²/Hz) with segments of ``segment_s`` seconds."""
    nperseg = min(len(x), int(segment_s * fs))
    return welch(x - x.mean(), fs=fs, nperseg=nperseg)


def main(quick: bool = False, out: str = ".") -> dict:
    duration = 600.0 if quick else 3600.0
    case = surrogates.load_case(CASE)
    rec = surrogates.simulate(surrogates.FOWTModel(), case, duration=duration, dt=0.0125, seed=0)
    eta, wind = rec["Wave1Elev"], rec["Wind1VelX"]

    # the sea state estimated back from the record
    hs = 4.0 * float(np.std(eta))
    f_eta, p_eta = psd(eta, rec.fs, segment_s=200.0)  # 0.005 Hz resolution
    tp = 1.0 / float(f_eta[np.argmax(p_eta)])
    v_mean = float(np.mean(wind))
    ti = float(np.std(wind)) / v_mean
    f_wind, p_wind = psd(wind, rec.fs, segment_s=300.0 if quick else 600.0)

    print(f"{case.name}, {duration:.0f} s record (seed 0)")
    print(f"{'quantity':<28}{'load case':>12}{'from record':>14}")
    print(f"{'significant wave height Hs':<28}{case.hs:>10.2f} m{hs:>12.2f} m")
    print(f"{'peak period Tp':<28}{case.tp:>10.2f} s{tp:>12.2f} s")
    print(f"{'mean wind at hub':<28}{case.wind_speed:>8.2f} m/s{v_mean:>10.2f} m/s")
    print(f"{'turbulence intensity TI':<28}{case.turbulence_intensity:>12.3f}{ti:>14.3f}")

    # figure: measured PSDs over the target spectra
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    f_target = np.linspace(0.0, 0.4, 801)
    ax.plot(f_eta, p_eta, color="tab:blue", lw=1.0, label=f"record (Welch), Hs = {hs:.2f} m")
    ax.plot(f_target, jonswap_spectrum(f_target, case.hs, case.tp, case.gamma), "k--", lw=1.5,
            label=f"JONSWAP target, Hs = {case.hs:g} m, Tp = {case.tp:g} s, gamma = {case.gamma:g}")
    ax.axvline(1.0 / case.tp, color="0.5", ls=":", lw=1.0, label="1 / Tp")
    ax.set_xlim(0.0, 0.4)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("wave elevation PSD (m²/Hz)")
    ax.set_title("Wave elevation Wave1Elev")
    ax.legend(fontsize=8)
    sel = f_wind > 0
    bx.loglog(f_wind[sel], p_wind[sel], color="tab:green", lw=1.0, label=f"record (Welch), TI = {ti:.3f}")
    bx.loglog(f_wind[sel], kaimal_spectrum(f_wind[sel], case.wind_speed, case.turbulence_intensity), "k--",
              lw=1.5, label=f"Kaimal target, V = {case.wind_speed:g} m/s, TI = {case.turbulence_intensity:.3f}")
    bx.set_xlabel("frequency (Hz)")
    bx.set_ylabel("hub wind speed PSD ((m/s)²/Hz)")
    bx.set_title("Hub-height wind Wind1VelX")
    bx.legend(fontsize=8)
    bx.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"{case.name}: one {duration:.0f} s realisation against the load case's spectra")
    fig.tight_layout()
    path = Path(out) / "01_waves_and_spectra.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
    return {"case": case.name, "duration_s": duration, "hs_m": hs, "hs_target_m": case.hs, "tp_s": tp,
            "tp_target_s": case.tp, "wind_mean_m_s": v_mean, "turbulence_intensity": ti,
            "turbulence_intensity_target": case.turbulence_intensity, "figures": [path]}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a 10-minute record instead of one hour")
    ap.add_argument("--out", default=".", help="folder for the figure")
    a = ap.parse_args()
    main(quick=a.quick, out=a.out)
