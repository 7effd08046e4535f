"""The README's "Lyapunov time" paragraph: Rosenstein's exponent on band-passed tower-top fore-aft acceleration
of 300 s of OLC 4, seeds 0-2, and phase-randomised copies of seed 0's band-passed signal.

The procedure (the paragraph's numbers before issue 15's disc-rate lag were made by a script that was not kept;
these are the README's words taken literally, and the paragraph is now regenerated from this tool):
  record   surrogates.simulate(FOWTModel(), 4, duration=300, dt=0.0125, seed=s)  (noisy sensors, as measured)
  signal   TwHt9ALxt (tower-top fore-aft acceleration), zero-phase 4th-order Butterworth 0.25-5 Hz
           (estimators.preprocess.band_sos + scipy sosfiltfilt -- the same filter compare's lyapunov_estimate uses)
  estimate estimators.lyapunov_exponent(x, dt) with everything chosen from the data
  copies   phase-randomised copies of the band-passed seed-0 signal (same amplitude spectrum, uniform random
           phases, DC and Nyquist kept), numpy default_rng(copy_seed) for copy seeds 1 and 2
Every one of these choices is an option, so that the procedure can be matched once it is known.

Usage: python tools/readme_lyapunov.py --json OUT.json [--seeds 0,1,2] [--duration 300] [--copies 1,2]
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np


def phase_randomised(x: np.ndarray, seed: int) -> np.ndarray:
    """Same amplitude spectrum, independent uniform phases (the DC and Nyquist bins kept as they are)."""
    spec = np.fft.rfft(x)
    rng = np.random.default_rng(seed)
    new = np.abs(spec) * np.exp(1j * rng.uniform(0.0, 2.0 * np.pi, spec.size))
    new[0] = spec[0]
    if x.size % 2 == 0:
        new[-1] = spec[-1]
    return np.fft.irfft(new, n=x.size)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", required=True)
    ap.add_argument("--case", type=int, default=4)
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--duration", type=float, default=300.0)
    ap.add_argument("--dt", type=float, default=0.0125)
    ap.add_argument("--channel", default="TwHt9ALxt")
    ap.add_argument("--band", default="0.25,5")
    ap.add_argument("--noise-free", action="store_true", help="use the noise-free truth instead of the sensors")
    ap.add_argument("--copies", default="1,2", help="rng seeds of the phase-randomised copies of the first seed")
    a = ap.parse_args()

    from scipy.signal import sosfiltfilt

    import surrogates
    from estimators.lyapunov import lyapunov_exponent
    from estimators.preprocess import band_sos

    band = tuple(float(v) for v in a.band.split(","))
    seeds = [int(s) for s in a.seeds.split(",")]
    copies = [int(s) for s in a.copies.split(",") if s.strip()]
    sos = band_sos(1.0 / a.dt, band)
    model = surrogates.FOWTModel()

    def estimate(x: np.ndarray) -> dict:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = lyapunov_exponent(x, a.dt, return_details=True)
        return {"exponent_per_s": float(res.exponent), "lyapunov_time_s": float(res.lyapunov_time),
                "lag": int(res.lag), "dim": int(res.dim), "fit_range_s": [float(v) for v in res.fit_range],
                "r2": float(res.r2), "diagnostic": res.diagnostic,
                "warnings": [str(w.message) for w in caught]}

    out = {"settings": {k: getattr(a, k) for k in ("case", "duration", "dt", "channel", "band", "noise_free")}
           | {"seeds": seeds, "copies": copies}, "seeds": [], "copies": []}
    t0 = time.perf_counter()
    first = None
    for s in seeds:
        noisy, truth = surrogates.simulate(model, a.case, duration=a.duration, dt=a.dt, seed=s, return_truth=True)
        rec = truth if a.noise_free else noisy
        x = sosfiltfilt(sos, rec[a.channel])
        r = {"seed": s, **estimate(x)}
        out["seeds"].append(r)
        print(f"OLC {a.case} seed {s}: lambda {r['exponent_per_s']:.3f}/s, Lyapunov time {r['lyapunov_time_s']:.2f} s "
              f"(lag {r['lag']}, dim {r['dim']}) {r['diagnostic']}", flush=True)
        if first is None:
            first = x
    for c in copies:
        r = {"of_seed": seeds[0], "copy_seed": c, **estimate(phase_randomised(first, c))}
        out["copies"].append(r)
        print(f"  phase-randomised copy (rng {c}) of seed {seeds[0]}: lambda {r['exponent_per_s']:.3f}/s", flush=True)
    out["wall_s"] = time.perf_counter() - t0
    with open(a.json, "w") as f:
        json.dump(out, f, indent=1)
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
