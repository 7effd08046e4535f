"""Derive the blades' in-plane force sensitivity to the streamwise wind from the OC3 deck's AeroDyn blade.

The rotor's in-plane (side and vertical) hub force under turbulence is the sum over the blades of each blade's
in-plane aerodynamic force, rotated by its azimuth. How strongly, and from which part of the span, a blade's
in-plane force answers the wind it meets is a property of the blade (chord, twist, airfoils) at the operating
point. This script computes it with a quasi-steady blade-element momentum model of AeroDyn's own blade
(``NRELOffshrBsline5MW_AeroDyn_blade.dat``, the airfoil polars of ``Airfoils/``; Prandtl tip and hub losses,
Buhl's high-induction correction, drag in the induction as in AeroDyn's defaults; the deck has no dynamic wake,
``DBEMT_Mod`` unused with ``WakeMod = 1``), at the surrogate's own steady operating points (rotor speed and
pitch of :func:`surrogates.aero.operating_point`), by central differences of each AeroDyn node's tangential
force per unit length with respect to a local change of the axial wind (a 0.1 m/s step).

It writes ``surrogates/data/blade_inplane_sensitivity.json``: the node radii (m from the rotor centre), their
span widths (m), the wind speeds (m/s) and per speed and node ``dFt/dU`` (N/m per m/s: force per unit span
along the direction of rotation, for the blade's own wind), with the sha256 of every deck file read.
:func:`surrogates.aero.blade_inplane_sensitivity` reads it.

Measured against OpenFAST (analysis of the shared runs, 0.4-0.6 Hz): fed with each run's TurbSim winds on the
polar rings, the lateral hub force of these weights is 0.97 / 0.84 / 0.85 of OpenFAST's aerodynamic side force
at 8 / 12 / 18 m/s, against 0.74 / 0.62 / 0.64 for the former model (the radius-weighted blade wind over a
52.5 m lever); per blade and unit uniform change of u the in-plane force is 6.8 / 9.2 / 11.9 kN/(m/s), peaking
mid-span.

Usage::

    python tools/blade_inplane_sensitivity.py [--deck ../shared/reference/openfast/decks/5MW_Baseline]
"""

from __future__ import annotations

import argparse
import hashlib
import json
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

REPO = Path(__file__).resolve().parents[1]
DEFAULT_DECK = REPO.parent / "shared" / "reference" / "openfast" / "decks" / "5MW_Baseline"
AIRFOILS = ["Cylinder1", "Cylinder2", "DU40_A17", "DU35_A17", "DU30_A17", "DU25_A17", "DU21_A17", "NACA64_A17"]
HUB_RADIUS, TIP_RADIUS, N_BLADES, RHO = 1.5, 63.0, 3, 1.225
SPEEDS = [3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 11.4, 12.0, 13.0, 14.0, 16.0, 18.0, 20.0, 22.0, 25.0]


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_polar(path: Path) -> np.ndarray:
    """(alpha deg, Cl, Cd) rows of an AeroDyn airfoil file."""
    lines = path.read_text().splitlines()
    i = next(k for k, line in enumerate(lines) if "NumAlf" in line)
    n = int(lines[i].split()[0])
    rows: list[list[float]] = []
    k = i + 1
    while len(rows) < n:
        parts = lines[k].split()
        k += 1
        if parts and not parts[0].startswith("!"):
            rows.append([float(x) for x in parts[:3]])
    return np.array(rows)


class Blade:
    def __init__(self, deck: Path):
        self.files = [deck / "NRELOffshrBsline5MW_AeroDyn_blade.dat"] + [deck / "Airfoils" / f"{a}.dat"
                                                                         for a in AIRFOILS]
        self.polars = [read_polar(p) for p in self.files[1:]]
        table = np.loadtxt(self.files[0], skiprows=6, max_rows=19)
        span = table[:, 0]
        self.r = HUB_RADIUS + span
        self.twist = np.deg2rad(table[:, 4])
        self.chord = table[:, 5]
        self.airfoil = table[:, 6].astype(int) - 1
        self.width = np.zeros_like(span)
        self.width[1:-1] = 0.5 * (span[2:] - span[:-2])
        self.width[0] = 0.5 * (span[1] - span[0])
        self.width[-1] = 0.5 * (span[-1] - span[-2])

    def coefficients(self, i: int, alpha: float) -> tuple[float, float]:
        p = self.polars[self.airfoil[i]]
        a = np.rad2deg(alpha)
        return float(np.interp(a, p[:, 0], p[:, 1])), float(np.interp(a, p[:, 0], p[:, 2]))

    def tangential_force(self, i: int, v_axial: float, v_tangential: float, pitch: float) -> float:
        """Quasi-steady BEM tangential force per unit span (N/m) at node i."""
        return self.node_forces(i, v_axial, v_tangential, pitch)[1]

    def node_forces(self, i: int, v_axial: float, v_tangential: float, pitch: float) -> tuple[float, float]:
        """Quasi-steady BEM normal (out of plane, downwind) and tangential (along the rotation) force per unit
        span (N/m) at node i (Ning's one-variable residual)."""
        r, c, theta = self.r[i], self.chord[i], self.twist[i] + pitch
        sigma = N_BLADES * c / (2.0 * np.pi * r)

        def state(phi: float) -> tuple[float, float, float]:
            s, co = np.sin(phi), np.cos(phi)
            cl, cd = self.coefficients(i, phi - theta)
            cn, ct = cl * co + cd * s, cl * s - cd * co
            f_tip = N_BLADES / 2.0 * (TIP_RADIUS - r) / (r * abs(s))
            f_hub = N_BLADES / 2.0 * (r - HUB_RADIUS) / (HUB_RADIUS * abs(s))
            loss = max((2.0 / np.pi * np.arccos(np.exp(-f_tip)) if f_tip < 50 else 1.0)
                       * (2.0 / np.pi * np.arccos(np.exp(-f_hub)) if f_hub < 50 else 1.0), 1e-4)
            k = sigma * cn / (4.0 * loss * s * s)
            kp = sigma * ct / (4.0 * loss * s * co)
            if k <= 2.0 / 3.0:
                a = k / (1.0 + k)
            else:  # Buhl's high-induction correction
                g1 = 2.0 * loss * k - (10.0 / 9.0 - loss)
                g2 = 2.0 * loss * k - loss * (4.0 / 3.0 - loss)
                g3 = 2.0 * loss * k - (25.0 / 9.0 - 2.0 * loss)
                a = (g1 - np.sqrt(abs(g2))) / g3 if abs(g3) > 1e-6 else 1.0 - 1.0 / (2.0 * np.sqrt(g2))
            ap = kp / (1.0 - kp)
            return s / (1.0 - a) - co * v_axial / (v_tangential * (1.0 + ap)), a, ap

        try:
            phi = brentq(lambda p: state(p)[0], 1e-6, np.pi / 2)
        except ValueError:
            phi = brentq(lambda p: state(p)[0], -np.pi / 4, -1e-6)
        _, a, ap = state(phi)
        w2 = (v_axial * (1.0 - a)) ** 2 + (v_tangential * (1.0 + ap)) ** 2
        cl, cd = self.coefficients(i, phi - theta)
        q = 0.5 * RHO * w2 * c
        return q * (cl * np.cos(phi) + cd * np.sin(phi)), q * (cl * np.sin(phi) - cd * np.cos(phi))

    def sensitivity(self, wind: float, rpm: float, pitch_rad: float, step: float = 0.1) -> np.ndarray:
        """dFt/dU (N/m per m/s) at every node (root and tip nodes 0: no lift there)."""
        omega = rpm * np.pi / 30.0
        out = np.zeros(self.r.size)
        for i in range(1, self.r.size - 1):
            vt = omega * self.r[i]
            out[i] = (self.tangential_force(i, wind + step, vt, pitch_rad)
                      - self.tangential_force(i, wind - step, vt, pitch_rad)) / (2.0 * step)
        return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--deck", type=Path, default=DEFAULT_DECK, help="the OC3 deck's 5MW_Baseline folder")
    ap.add_argument("--out", type=Path, default=REPO / "surrogates" / "data" / "blade_inplane_sensitivity.json")
    args = ap.parse_args(argv)
    from surrogates.aero import operating_point

    blade = Blade(args.deck)
    rows = []
    for v in SPEEDS:
        op = operating_point(v)
        rpm = op.rotor_speed * 30.0 / np.pi
        rows.append(blade.sensitivity(v, rpm, op.pitch))
        total = float(rows[-1] @ blade.width)
        print(f"{v:5.1f} m/s  {rpm:5.2f} rpm  pitch {np.rad2deg(op.pitch):5.2f} deg  "
              f"in-plane force per blade {total / 1e3:6.2f} kN/(m/s)")
    data = {
        "description": "Quasi-steady BEM sensitivity of the tangential (in-plane, along the rotation) force per "
                       "unit span of one blade of the NREL 5 MW (OC3 deck's AeroDyn blade and polars) to its "
                       "local axial wind, at the surrogate's steady operating points; made by "
                       "tools/blade_inplane_sensitivity.py",
        "units": {"radius": "m from the rotor centre", "width": "m of span per node",
                  "wind_speed": "m/s", "dFt_dU": "N/m per m/s"},
        "radius": blade.r.round(4).tolist(),
        "width": blade.width.round(4).tolist(),
        "wind_speed": SPEEDS,
        "dFt_dU": [np.round(r, 3).tolist() for r in rows],
        "sources": {p.name: sha256(p) for p in blade.files},
    }
    args.out.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
