"""The README's "Rotor harmonics by order tracking" paragraph (Identification section). The README gives the
set-ups but no single command; this runs them with fowt_env.identification.identify -- what `fowt-env identify`
runs -- with its defaults and the linearised model of each case as reference:

  steady   20 minutes at 12 m/s, turbulence intensity 0, Hs 2.5 m, Tp 10 s (surrogates.operating_case), seed 0,
           FA and SS planes: the order-tracked "Rotor harmonics" table (order, f, sweep, locking)
  turbulent 30 minutes of OLCs 1, 4, 7, 12, seeds 0, 3, 4, both planes (24 runs): how many find any line;
           for OLC 4 also the rotor speed's std (rpm), the 1st-99th percentile of 3 x RotSpeed (Hz), and the
           SSI-COV lines labelled rotor_band (3P) (frequency, damping) in both planes

Usage: python harmonics.py --json OUT.json [--steady-duration 1200] [--duration 1800] [--cases 1,4,7,12]
       [--seeds 0,3,4]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def _f(v):
    if isinstance(v, dict):
        return {k: _f(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_f(x) for x in v]
    if isinstance(v, np.ndarray):
        return _f(v.tolist())
    if isinstance(v, np.generic):
        return v.item()
    return v


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", required=True)
    ap.add_argument("--steady-duration", type=float, default=1200.0)
    ap.add_argument("--duration", type=float, default=1800.0)
    ap.add_argument("--cases", default="1,4,7,12")
    ap.add_argument("--seeds", default="0,3,4")
    a = ap.parse_args()

    import surrogates
    from fowt_env.identification import identify, model_reference

    model = surrogates.FOWTModel()
    out: dict = {"settings": vars(a), "steady": {}, "turbulent": []}
    t0 = time.perf_counter()

    steady = surrogates.operating_case(12.0, hs=2.5, tp=10.0, turbulence_intensity=0.0)
    rec = surrogates.simulate(model, steady, duration=a.steady_duration, dt=0.0125, seed=0)
    for plane in ("FA", "SS"):
        res = identify(rec, plane=plane, reference=model_reference(model, steady, plane=plane))
        out["steady"][plane] = {"rotor_speed": res.rotor_speed_source, "lines": _f(res.harmonics)}
        print(
            f"steady 12 m/s {plane}:",
            [(round(h["order"], 2), round(h["frequency_hz"], 4)) for h in (res.harmonics or [])],
            flush=True,
        )

    for case in [int(c) for c in a.cases.split(",")]:
        lc = surrogates.load_case(case)
        for seed in [int(s) for s in a.seeds.split(",")]:
            rec = surrogates.simulate(model, case, duration=a.duration, dt=0.0125, seed=seed)
            rpm = np.asarray(rec["RotSpeed"], float)
            row = {
                "case": case,
                "seed": seed,
                "rotspeed_std_rpm": float(rpm.std()),
                "f3p_p1_p99_hz": [float(np.percentile(3 * rpm / 60.0, q)) for q in (1, 99)],
                "planes": {},
            }
            for plane in ("FA", "SS"):
                res = identify(rec, plane=plane, reference=model_reference(model, lc, plane=plane))
                row["planes"][plane] = {
                    "harmonics": _f(res.harmonics),
                    "rotor_speed": res.rotor_speed_source,
                    "ssi_rotor_band": [
                        _f({k: m.get(k) for k in ("frequency_hz", "damping_ratio", "kind")})
                        for m in res.ssi_modes
                        if str(m.get("kind", "")).startswith("rotor_band")
                    ],
                }
            out["turbulent"].append(row)
            print(
                f"OLC {case} seed {seed}: RotSpeed std {row['rotspeed_std_rpm']:.2f} rpm, harmonics FA "
                f"{len(row['planes']['FA']['harmonics'] or [])} SS {len(row['planes']['SS']['harmonics'] or [])}",
                flush=True,
            )
    out["wall_s"] = time.perf_counter() - t0
    with open(a.json, "w") as f:
        json.dump(_f(out), f, indent=1)
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
