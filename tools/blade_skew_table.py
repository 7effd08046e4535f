"""Tabulate how one blade's loads answer a change of its tangential airspeed, over the rotor table's grid.

A wind component in the rotor plane (the shaft's inclination under the wind: 5 deg of tilt plus the platform's
pitch; a yaw misalignment; the hub's own in-plane motion) adds to the airspeed of the blades moving against it and
takes from those moving with it, once per revolution: the advancing and retreating blades. Each blade's thrust,
and its moment about the rotor centre, change with that airspeed, so an inclined rotor carries a yaw moment and a
yawed one a tilt moment; its in-plane force changes too (an in-plane aerodynamic force against the hub's in-plane
motion). How strongly, and with which sign, is a property of the blade at its tip-speed ratio and pitch: near
fine pitch more airspeed means more lift and thrust; at high pitch the outer blade runs at negative angles of
attack and more airspeed means *less* thrust.

This script computes the three sensitivities with the quasi-steady blade-element momentum model of the OC3 deck's
AeroDyn blade in ``tools/blade_inplane_sensitivity.py`` (the deck's blade and polars, Prandtl tip and hub losses,
Buhl's correction), by central differences (+-0.1 m/s of tangential airspeed, the same at every node, as a uniform
in-plane wind gives) at every (tip-speed ratio, pitch) point of :func:`surrogates.aero.rotor_table`, in
non-dimensional form (``q = 0.5 rho pi R^2 V``, ``V`` the axial wind):

* ``k_thrust = (dT_blade/dVt) / q``: one blade's thrust per m/s of tangential airspeed;
* ``k_moment = (dM_blade/dVt) / (q R)``: its moment about the rotor centre (the thrust times its radius);
* ``k_inplane = (dF_blade/dVt) / q``: its in-plane force along the rotation.

Quasi-steady BEM at the rotor's mean operating points gives, per blade and m/s of airspeed, a thrust moment of
+84 / +72 / -168 kN m at 8 / 12 / 18 m/s. Against OpenFAST's steady-wind run (12 m/s, 9.8 deg inclination):
the 1P sine term of its blade-root flap moment ``RootMyc1`` is 329 kN m; this model, from the shaft's inclination
alone (no flap dynamics), gives 233 kN m at the run's own pitch and rotor speed (and 78 / 183 / -328 kN m against
OpenFAST's 72 / 213 / -34 at 8 / 12 / 18 m/s, where the shear's lagged flap response adds its own share).

It writes ``surrogates/data/blade_skew_table.json`` (the grid, the three tables, the sha256 of every deck file
read); :func:`surrogates.aero.blade_skew_table` reads it.

Usage::

    python tools/blade_skew_table.py [--deck ../shared/reference/openfast/decks/5MW_Baseline]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from blade_inplane_sensitivity import DEFAULT_DECK, RHO, TIP_RADIUS, Blade, sha256

REPO = Path(__file__).resolve().parents[1]
WIND = 10.0  # m/s: the polars carry no Reynolds number, so the non-dimensional table holds at any speed
STEP = 0.1  # m/s of tangential airspeed


def blade_sensitivities(blade: Blade, tsr: float, pitch_rad: float) -> tuple[float, float, float]:
    """(dT/dVt, dM/dVt, dF/dVt) of one blade (N per m/s, N m per m/s, N per m/s) at tip-speed ratio ``tsr`` and
    pitch, in the axial wind :data:`WIND`; NaN where the BEM residual has no root."""
    omega = tsr * WIND / TIP_RADIUS
    d_t = d_m = d_f = 0.0
    for i in range(1, blade.r.size - 1):
        vt = omega * blade.r[i]
        try:
            hi = blade.node_forces(i, WIND, vt + STEP, pitch_rad)
            lo = blade.node_forces(i, WIND, vt - STEP, pitch_rad)
        except ValueError:
            return float("nan"), float("nan"), float("nan")
        w = blade.width[i] / (2.0 * STEP)
        d_t += (hi[0] - lo[0]) * w
        d_m += (hi[0] - lo[0]) * w * blade.r[i]
        d_f += (hi[1] - lo[1]) * w
    return d_t, d_m, d_f


def fill_nan(table: np.ndarray) -> np.ndarray:
    """Replace NaN entries by the nearest valid entry along the pitch axis (then along the tip-speed ratio)."""
    out = table.copy()
    for axis in (1, 0):
        for _ in range(out.shape[axis]):
            bad = np.isnan(out)
            if not bad.any():
                return out
            for shift in (1, -1):
                nb = np.roll(out, shift, axis=axis)
                edge = [slice(None)] * 2
                edge[axis] = 0 if shift == 1 else -1
                nb[tuple(edge)] = np.nan
                take = np.isnan(out) & ~np.isnan(nb)
                out[take] = nb[take]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--deck", type=Path, default=DEFAULT_DECK, help="the OC3 deck's 5MW_Baseline folder")
    ap.add_argument("--out", type=Path, default=REPO / "surrogates" / "data" / "blade_skew_table.json")
    args = ap.parse_args(argv)
    from surrogates.aero import operating_point, rotor_table

    rt = rotor_table()
    blade = Blade(args.deck)
    q = 0.5 * RHO * np.pi * rt.radius**2 * WIND
    shape = (rt.tsr.size, rt.pitch_rad.size)
    k_t, k_m, k_f = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    for i, lam in enumerate(rt.tsr):
        for j, beta in enumerate(rt.pitch_rad):
            d_t, d_m, d_f = blade_sensitivities(blade, float(lam), float(beta))
            k_t[i, j], k_m[i, j], k_f[i, j] = d_t / q, d_m / (q * rt.radius), d_f / q
    n_bad = int(np.isnan(k_t).sum())
    k_t, k_m, k_f = fill_nan(k_t), fill_nan(k_m), fill_nan(k_f)
    for v in (8.0, 12.0, 18.0):
        op = operating_point(v)
        lam = op.rotor_speed * rt.radius / v
        d_t, d_m, d_f = blade_sensitivities(blade, lam, op.pitch)
        d_t, d_m, d_f = d_t * v / WIND, d_m * v / WIND, d_f * v / WIND
        print(f"{v:4.1f} m/s (tsr {lam:4.2f}, pitch {np.rad2deg(op.pitch):5.2f} deg): per blade and m/s of "
              f"tangential airspeed thrust {d_t / 1e3:6.2f} kN, moment {d_m / 1e3:7.1f} kN m, in-plane force "
              f"{d_f / 1e3:6.2f} kN")
    data = {
        "description": "Quasi-steady BEM sensitivity of one blade of the NREL 5 MW (OC3 deck's AeroDyn blade and "
                       "polars) to its tangential airspeed, on the rotor table's (tip-speed ratio, pitch) grid; "
                       "made by tools/blade_skew_table.py",
        "units": {"tsr": "-", "pitch": "rad", "k_thrust": "dT_blade/dVt / (0.5 rho pi R^2 V)",
                  "k_moment": "dM_blade/dVt / (0.5 rho pi R^3 V)", "k_inplane": "dF_blade/dVt / (0.5 rho pi R^2 V)"},
        "radius": float(rt.radius),
        "tsr": np.round(rt.tsr, 6).tolist(),
        "pitch": np.round(rt.pitch_rad, 8).tolist(),
        "k_thrust": np.round(k_t, 8).tolist(),
        "k_moment": np.round(k_m, 8).tolist(),
        "k_inplane": np.round(k_f, 8).tolist(),
        "filled_points": n_bad,
        "sources": {p.name: sha256(p) for p in blade.files},
    }
    args.out.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {args.out} ({n_bad} grid points without a BEM root, filled from their neighbours)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
