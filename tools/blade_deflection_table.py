"""Tabulate how much thrust and torque the OC3 rotor loses when its blades are bent downwind (flap deflection).

What
    Runs OpenFAST's AeroDyn driver (through ``tools/aerodyn_rotor_table.py``) twice over a (tip-speed ratio,
    pitch) grid: the deck's straight blades, and the same blades bent downwind along their first flap mode with
    a tip deflection ``--tip`` (default 5 m), at constant length (``--flap-deflection`` of that tool: out-of-plane
    offset, local cant and foreshortening from the ElastoDyn blade file's mode shape). It writes the changes
    ``Ct_bent - Ct`` and ``Cq_bent - Cq`` per grid point to ``surrogates/data/blade_deflection_table.json``,
    which ``surrogates.aero.blade_deflection_table`` reads (the ``blade_deflection`` effect).

Why
    OpenFAST's blades bend 3-5 m at the tip in operation (``OoPDefl1``: 3.2 / 4.4 / 1.7 / 5.1 m mean in the shared
    8 / 12 / 18 m/s and steady-wind runs). The same OpenFAST deck run with its blade DOFs off (FlapDOF1/2,
    EdgeDOF False; ``tools/openfast_blade_flex_runs.py``), platform held at the steady-wind run's mean position
    (surge 24 m, pitch 4.77 deg), steady 12 m/s with shear 0.2, settles at 2.04 deg of blade pitch; with flexible
    blades at 0.99 deg (5.26 m tip deflection); in uniform wind with the platform level at 2.93 and 2.48 deg. The
    rigid rotor table reproduces the rigid deck (2.93 deg in uniform wind; 2.05 deg by AeroDyn's driver at the
    sheared run's inclination and shear), so the bent blades make OpenFAST's rotor 2-4 % weaker in torque at
    rated: a bent blade is coned downwind, turned by its slope, and shorter in radius.

How
    Both runs at the deck's operating conditions near rated: the shaft inclined ``--tilt`` (default 9 deg: 5 deg of
    tilt plus the platform's and the tower top's pitch) in a power-law shear ``--shear`` (default 0.2, the reference
    runs'). Untilted, the blade bent 5 m downwind would pass through AeroDyn's tower potential flow (a "tower
    strike" stops the driver). The bent blades lose more where the rotor is inclined in a sheared wind (at
    tip-speed ratio 6.65 and 1 deg of pitch, 5.26 m of tip deflection: 2.4 % of the torque at 5 deg tilt in
    uniform wind, 2.7 % with shear 0.2, 3.2 % at 10.3 deg with shear 0.2), hence the operating conditions. The
    difference of the two runs is what is tabulated (not their ratio: where the straight rotor's torque changes
    sign at high pitch a ratio is undefined); the surrogate adds it to its aligned, uniform-wind rotor table.
    The coarse grid (default tip-speed ratio 2..14 step 1, pitch -4..30 deg step 2) is interpolated bilinearly.

Usage (maintainer tool, not run by the tests; ~20 s per tip-speed ratio and run on one core)::

    python tools/blade_deflection_table.py --driver /tmp/of/build/modules/aerodyn/aerodyn_driver \\
        [--shared ../shared] [--tip 5] [--workdir DIR]

The driver must be the OpenFAST v5.0.0 build of the reference runs (see ``tools/aerodyn_rotor_table.py``).
"""

from __future__ import annotations

import argparse
import datetime
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import aerodyn_rotor_table as art  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "surrogates" / "data" / "blade_deflection_table.json"


def run(driver: str, shared: Path, tsr: np.ndarray, pitch: np.ndarray, tilt: float, shear: float, tip: float,
        workdir: Path) -> tuple[np.ndarray, np.ndarray]:
    """Ct and Cq over the grid (rows: tsr) for blades bent by ``tip`` m (0: straight)."""
    args = argparse.Namespace(driver=driver, shared=str(shared), run=art.DEFAULT_RUN, set=[], ua_mod=None,
                              tilt=tilt, shear=shear, rpm=12.0, revs=3, keep=False, flap_deflection=tip,
                              workdir=str(workdir / f"tilt{tilt:g}_shear{shear:g}_tip{tip:g}"))
    inp = art.deck_inputs(shared / "reference" / "openfast" / "runs" / art.DEFAULT_RUN)
    rows, _ = art.run_grid(args, inp, tsr, pitch)
    return np.array([r["ct"] for r in rows]), np.array([r["cq"] for r in rows])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--driver", required=True, help="aerodyn_driver binary (OpenFAST v5.0.0 build)")
    ap.add_argument("--shared", default=str(art.DEFAULT_SHARED), help="shared folder (default ../shared)")
    ap.add_argument("--tip", type=float, default=5.0, help="tip deflection of the bent blades, m (default 5)")
    ap.add_argument("--tilt", type=float, default=9.0,
                    help="inclination of the shaft in both runs, deg (default 9: the deck's 5 deg tilt plus the "
                         "platform's and the tower top's pitch at rated)")
    ap.add_argument("--shear", type=float, default=0.2,
                    help="power-law shear exponent of both runs (default 0.2: the reference runs')")
    ap.add_argument("--tsr", type=float, nargs="+", default=list(np.arange(2.0, 14.01, 1.0)))
    ap.add_argument("--pitch", type=float, nargs="+", default=list(np.arange(-4.0, 30.01, 2.0)))
    ap.add_argument("--workdir", default="/tmp/blade_deflection_table", help="driver runs and their cache")
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    args = ap.parse_args(argv)
    shared = Path(args.shared).resolve()
    tsr, pitch = np.array(args.tsr, float), np.array(args.pitch, float)
    work = Path(args.workdir)
    ct0, cq0 = run(args.driver, shared, tsr, pitch, args.tilt, args.shear, 0.0, work)
    ct1, cq1 = run(args.driver, shared, tsr, pitch, args.tilt, args.shear, args.tip, work)
    # differences, not ratios: near the pitch where the straight rotor's torque changes sign the ratio is undefined
    ct_delta, cq_delta = ct1 - ct0, cq1 - cq0
    out = {
        "description": "Thrust and torque coefficients of the OC3 rotor with its blades bent downwind along their "
                       "first flap mode (tip deflection tip_deflection_m, constant length), divided by those of the "
                       "straight blades; AeroDyn driver, OpenFAST v5.0.0, the deck's AeroDyn input (UA, tip/hub "
                       "loss, tower potential flow), steady inflow with power-law shear shear_exponent, the shaft "
                       "inclined tilt_deg.",
        "written_by": "tools/blade_deflection_table.py",
        "written_on": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "openfast_commit": art.OPENFAST_COMMIT,
        "tip_deflection_m": args.tip,
        "tilt_deg": args.tilt,
        "shear_exponent": args.shear,
        "tsr": tsr.tolist(),
        "pitch_deg": pitch.tolist(),
        "ct_delta": np.round(ct_delta, 7).tolist(),
        "cq_delta": np.round(cq_delta, 8).tolist(),
        "ct_straight": np.round(ct0, 6).tolist(),
        "cq_straight": np.round(cq0, 7).tolist(),
    }
    Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {args.out}: Cq change {cq_delta.min():.5f}..{cq_delta.max():.5f}, Ct change "
          f"{ct_delta.min():.4f}..{ct_delta.max():.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
