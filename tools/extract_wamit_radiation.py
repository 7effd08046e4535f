"""Write the OC3 Hywind spar's radiation damping table shipped with fowt-env (surrogates/data/).

Reads the WAMIT first-order file ``Spar.1`` of the OC3 Hywind deck (HydroDyn ``PotFile``; the FAST v8 CertTest
``HydroData/spar.1``, as in ``../shared/reference/openfast/decks/5MW_Baseline/HydroData/``) and writes the
dimensional radiation damping against frequency: ``B11`` (= B22), ``B15`` (= -B24), ``B33`` and ``B55``
(= B44), redimensionalised with rho = 1025 kg/m^3 and ULEN = 1 m (WAMIT: ``B_ij = rho omega L^k Bbar_ij``,
k = 3, 4, 5 for force-translation, force-rotation, moment-rotation). Rows of infinite (-1) and zero (0)
period are skipped.

Usage: python tools/extract_wamit_radiation.py [PATH/Spar.1] [OUT.csv]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

RHO = 1025.0
DEFAULT_IN = Path(__file__).resolve().parents[1] / "../shared/reference/openfast/decks/5MW_Baseline/HydroData/Spar.1"
DEFAULT_OUT = Path(__file__).resolve().parents[1] / "surrogates/data/oc3_spar_radiation.csv"


def main() -> None:
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_IN
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else DEFAULT_OUT
    rows: dict[float, dict[tuple[int, int], float]] = {}
    for line in src.read_text().splitlines():
        parts = line.split()
        if len(parts) < 5:
            continue
        period, i, j, _a, b = float(parts[0]), int(parts[1]), int(parts[2]), float(parts[3]), float(parts[4])
        if period <= 0:
            continue
        rows.setdefault(period, {})[(i, j)] = b
    table = []
    for period in sorted(rows, reverse=True):  # increasing frequency
        r = rows[period]
        w = 2.0 * np.pi / period
        table.append((w, RHO * w * r[(1, 1)], RHO * w * r[(1, 5)], RHO * w * r[(3, 3)], RHO * w * r[(5, 5)]))
    header = ("# OC3 Hywind spar radiation damping from WAMIT Spar.1 (OC3 deck, FAST v8 CertTest HydroData/spar.1), "
              "rho = 1025 kg/m^3; written by tools/extract_wamit_radiation.py\n"
              "omega_rad_s,B11_N_s_per_m,B15_N_s,B33_N_s_per_m,B55_N_m_s")
    np.savetxt(out, np.array(table), delimiter=",", header=header, comments="", fmt="%.6e")
    print(f"wrote {out} ({len(table)} frequencies, {table[0][0]:.3f}-{table[-1][0]:.3f} rad/s)")


if __name__ == "__main__":
    main()
