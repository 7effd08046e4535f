"""Draw the README's figure of the rotor's 3P side-to-side load across the operating range.

Left: the tower base's side-to-side 3P line (``TwrBsMxt``) in steady wind at 8-18 m/s, OpenFAST's
(``fowt_env/data/openfast_rotor_harmonics/``, ``tools/openfast_rotor_harmonics_runs.py``) against the surrogate's
(:func:`fowt_env.validation.reference_model`), each demodulated against its own azimuth over the last 60 s
(:func:`fowt_env.validation.harmonic_amplitude`). Right: the tower's side-to-side free decay in operation at 8 and
12 m/s (``fowt_env/data/openfast_side_decays/``), ``TTDspSS`` band-passed at 0.3-0.8 Hz, OpenFAST against the
surrogate started from the same ElastoDyn initial conditions. Prints the figures it draws.

Usage::

    python tools/readme_rotor_harmonics.py [--figure docs/figures/rotor_3p_side_to_side.png]

About 10 s.
"""

from __future__ import annotations

import argparse
import json
from importlib import resources
from pathlib import Path

import numpy as np
from scipy.signal import butter, sosfiltfilt

import surrogates
from fowt_env.io import load_record
from fowt_env.validation import azimuth_from_rotor_speed, harmonic_amplitude, reference_model

REPO = Path(__file__).resolve().parents[1]
DATA = resources.files("fowt_env") / "data"
SPEEDS = (8, 10, 12, 14, 18)
WINDOW_S = 60.0


def _surrogate(case: dict, duration: float, initial: dict) -> surrogates.Record:
    wind = float(case["wind_speed"])
    lc = surrogates.operating_case(wind, 0.0, 10.0, turbulence_intensity=0.0) if wind > 0 else None
    return surrogates.simulate(reference_model(), lc, duration, 0.0125, 0, transient=0.0, noise=False,
                               initial=initial)


def lines() -> tuple[list[float], list[float]]:
    """OpenFAST's and the surrogate's ``TwrBsMxt`` 3P amplitudes (kN m) at :data:`SPEEDS`."""
    of, sur = [], []
    for u in SPEEDS:
        folder = DATA / "openfast_rotor_harmonics"
        rec = load_record(folder / f"h_st{u:02d}.npz")
        case = json.loads((folder / f"h_st{u:02d}.case.json").read_text())
        of.append(harmonic_amplitude(rec.t, rec["Azimuth"], rec["TwrBsMxt"], window_s=WINDOW_S))
        sim = _surrogate(case, float(case["duration_s"]), {**case["start"], "Azimuth": 0.0})
        azimuth = azimuth_from_rotor_speed(sim.t, sim["RotSpeed"])
        sur.append(harmonic_amplitude(sim.t, azimuth, sim["TwrBsMxt"], window_s=WINDOW_S))
    return of, sur


def _band(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    fs = 1.0 / float(np.median(np.diff(t)))
    return sosfiltfilt(butter(2, [0.3, 0.8], btype="band", fs=fs, output="sos"), x)


def main(argv: list[str] | None = None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--figure", type=Path, default=REPO / "docs" / "figures" / "rotor_3p_side_to_side.png")
    args = ap.parse_args(argv)

    of, sur = lines()
    fig, (a0, a1, a2) = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.0, 1.2, 1.2]})
    a0.plot(SPEEDS, of, "ko-", label="OpenFAST")
    a0.plot(SPEEDS, sur, "s--", color="tab:orange", label="surrogate (side force ~ V² dQ/dV)")
    a0.set_xlabel("steady wind (m/s)")
    a0.set_ylabel("TwrBsMxt 3P amplitude (kN m)")
    a0.set_title("tower base side-to-side 3P line")
    a0.axvline(11.4, color="0.7", lw=0.8, ls=":")
    a0.legend(fontsize=8)
    for ax, name, label in ((a1, "sd_op08_ss0p3", "8 m/s (region 2)"), (a2, "sd_op12_ss0p3", "12 m/s")):
        folder = DATA / "openfast_side_decays"
        rec = load_record(folder / f"{name}.npz")
        case = json.loads((folder / f"{name}.case.json").read_text())
        sim = _surrogate(case, float(case["duration_s"]), case["start"])
        ax.plot(rec.t, _band(np.asarray(rec.t), np.asarray(rec["TTDspSS"])), "k", lw=1.0, label="OpenFAST")
        ax.plot(sim.t, _band(np.asarray(sim.t), np.asarray(sim["TTDspSS"])), color="tab:orange", lw=0.9, ls="--",
                label="surrogate")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("TTDspSS, 0.3-0.8 Hz (m)")
        ax.set_title(f"tower side-to-side free decay in operation, {label}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    args.figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.figure, dpi=90)
    print("wind (m/s):       ", " ".join(f"{u:7d}" for u in SPEEDS))
    print("OpenFAST (kN m):  ", " ".join(f"{v:7.0f}" for v in of))
    print("surrogate (kN m): ", " ".join(f"{v:7.0f}" for v in sur))
    print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
