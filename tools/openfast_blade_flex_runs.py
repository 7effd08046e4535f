"""OpenFAST's own measure of what its flexible blades do to the rotor: the OC3 deck at steady wind, platform held,
with and without the blade DOFs.

What
    Four variants of the shared steady-wind run ``d_steady12_Hs2p5_Tp10`` (OpenFAST v5.0.0, the reference build),
    each settled for 160 s with the platform DOFs off (ElastoDyn ``Ptfm*DOF = False``: the platform held where its
    initial conditions put it), still water, and the mean of 100-160 s written to
    ``fowt_env/data/openfast_reference/blade_flex_runs.json``:

    ===============  =============================================  ==========================
    name             platform held at                               wind
    ===============  =============================================  ==========================
    sheared_flex     surge 24 m, pitch 4.77 deg (the run's mean)    12 m/s, shear 0.2 (as run)
    sheared_rigid    same, FlapDOF1/2 and EdgeDOF False             same
    uniform_flex     surge 0, pitch 0                               12 m/s, no shear
    uniform_rigid    same, blade DOFs off                           same
    ===============  =============================================  ==========================

    Everything else is the shared run's input (tower DOFs, drivetrain, DISCON OC3 Hywind controller, AeroDyn).

Why
    The surrogate's rotor table is AeroDyn's with rigid blades; these runs say how far OpenFAST's flexible rotor
    departs from it at rated (the ``blade_deflection`` effect and its test, ``tests/test_blade_deflection.py``).

Usage (maintainer tool; ~2.5 min of one core per variant)::

    python tools/openfast_blade_flex_runs.py --openfast /tmp/of/build/glue-codes/openfast/openfast \\
        [--shared ../shared] [--workdir /tmp/blade_flex_runs] [--reuse]

The deck's DISCON controller is compiled from ``decks/5MW_Baseline/ServoData/DISCON_OC3Hywind.f90`` with
``gfortran -shared -fPIC -O2 -cpp`` into a copy of the decks folder (as ``build.sh`` of the shared folder does).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SHARED = REPO.parent / "shared"
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_reference" / "blade_flex_runs.json"
BASE_RUN = "d_steady12_Hs2p5_Tp10"
CHANNELS = ("BldPitch1", "RotSpeed", "GenTq", "RotThrust", "LSShftTq", "OoPDefl1", "TTDspFA", "PtfmPitch",
            "PtfmSurge")
VARIANTS = {
    "sheared_flex": dict(surge=24.0, pitch=4.77, shear=None, rigid=False),
    "sheared_rigid": dict(surge=24.0, pitch=4.77, shear=None, rigid=True),
    "uniform_flex": dict(surge=0.0, pitch=0.0, shear=0.0, rigid=False),
    "uniform_rigid": dict(surge=0.0, pitch=0.0, shear=0.0, rigid=True),
}
TMAX_S, MEAN_FROM_S = 160.0, 100.0


def _set(text: str, name: str, value: str) -> str:
    new, n = re.subn(rf"^(\s*)\S+(\s+{re.escape(name)}\s)", lambda m: m.group(1) + value + m.group(2), text,
                     count=1, flags=re.M)
    if n != 1:
        raise ValueError(f"{name} not found")
    return new


def prepare(shared: Path, work: Path) -> None:
    """Copy the decks (with a compiled controller) and write the four variants' input folders under ``work``."""
    decks = work / "decks"
    if not decks.exists():
        shutil.copytree(shared / "reference" / "openfast" / "decks", decks)
        for p in decks.rglob("*"):
            p.chmod(p.stat().st_mode | 0o200)
    dll = decks / "5MW_Baseline" / "ServoData" / "DISCON_OC3Hywind.dll"
    if not dll.exists():
        subprocess.run(["gfortran", "-shared", "-fPIC", "-O2", "-cpp", "DISCON_OC3Hywind.f90", "-o", dll.name],
                       cwd=dll.parent, check=True)
    src = shared / "reference" / "openfast" / "runs" / BASE_RUN
    for name, v in VARIANTS.items():
        d = work / "runs" / name
        d.mkdir(parents=True, exist_ok=True)
        for f in list(src.glob("*.fst")) + list(src.glob("*.dat")):
            text = f.read_text()
            if f.name.endswith("_ElastoDyn.dat"):
                for dof in ("PtfmSgDOF", "PtfmSwDOF", "PtfmHvDOF", "PtfmRDOF", "PtfmPDOF", "PtfmYDOF"):
                    text = _set(text, dof, "False")
                if v["rigid"]:
                    for dof in ("FlapDOF1", "FlapDOF2", "EdgeDOF"):
                        text = _set(text, dof, "False")
                text = _set(text, "PtfmSurge", f"{v['surge']:g}")
                text = _set(text, "PtfmPitch", f"{v['pitch']:g}")
            elif f.name.endswith("_SeaState.dat"):
                text = _set(text, "WaveMod", "0")
            elif f.name.endswith("_InflowWind.dat") and v["shear"] is not None:
                text = _set(text, "PLExp", f"{v['shear']:g}")
            elif f.suffix == ".fst":
                text = _set(text, "TMax", f"{TMAX_S:g}")
                text = _set(text, "TStart", "60")
            (d / f.name).write_text(text)


def run_one(openfast: str, folder: Path, reuse: bool) -> Path:
    out = folder / f"{BASE_RUN}.outb"
    if reuse and out.exists():
        return out
    proc = subprocess.run([openfast, f"{BASE_RUN}.fst"], cwd=folder, capture_output=True, text=True,
                          env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    (folder / "run.log").write_text(proc.stdout + proc.stderr)
    if proc.returncode != 0 or not out.exists():
        raise RuntimeError(f"OpenFAST failed in {folder} (see run.log)")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--openfast", required=True, help="OpenFAST v5.0.0 binary (the reference build)")
    ap.add_argument("--shared", default=str(DEFAULT_SHARED))
    ap.add_argument("--workdir", default="/tmp/blade_flex_runs")
    ap.add_argument("--reuse", action="store_true", help="keep a variant's existing .outb")
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    args = ap.parse_args(argv)
    shared, work = Path(args.shared).resolve(), Path(args.workdir)
    sys.path.insert(0, str(shared / "reference" / "openfast" / "tools"))
    from analyze import read_outb  # the shared folder's reader of OpenFAST's binary output

    prepare(shared, work)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        outs = dict(zip(VARIANTS, pool.map(lambda n: run_one(args.openfast, work / "runs" / n, args.reuse),
                                           VARIANTS), strict=True))
    result = {}
    for name, path in outs.items():
        t, d, _ = read_outb(str(path))
        k = t >= MEAN_FROM_S
        result[name] = {**VARIANTS[name], **{c: round(float(np.mean(d[c][k])), 4) for c in CHANNELS}}
    doc = {
        "description": "OpenFAST v5.0.0 (the reference build), the shared run d_steady12_Hs2p5_Tp10's inputs with "
                       "the platform DOFs off (held at surge/pitch), still water, 160 s; means over 100-160 s. "
                       "'rigid': ElastoDyn FlapDOF1, FlapDOF2, EdgeDOF False. shear None = the run's 0.2.",
        "written_by": "tools/openfast_blade_flex_runs.py",
        "written_on": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "units": {"BldPitch1": "deg", "RotSpeed": "rpm", "GenTq": "kN m", "RotThrust": "kN", "LSShftTq": "kN m",
                  "OoPDefl1": "m", "TTDspFA": "m", "PtfmPitch": "deg", "PtfmSurge": "m", "surge": "m",
                  "pitch": "deg"},
        "runs": result,
    }
    Path(args.out).write_text(json.dumps(doc, indent=1) + "\n")
    for name, r in result.items():
        print(f"{name:14s} pitch {r['BldPitch1']:.3f} deg  thrust {r['RotThrust']:.1f} kN  tip {r['OoPDefl1']:.2f} m")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
