"""Make OpenFAST runs of the OC3 deck that the surrogate was never tuned on, and their compact copy.

What
    Four turbulent operating runs beside the shared ones, with new TurbSim and wave seeds and two new wind speeds:

    =============================  =========  =====  ======  ==========
    run                            wind       Hs     Tp      seeds
    =============================  =========  =====  ======  ==========
    c_op10_Hs2p5_Tp10_s1001        10 m/s     2.5 m  10 s    1001
    c_op12_Hs2p5_Tp10_s1203        12 m/s     2.5 m  10 s    1203
    c_op14_Hs3p0_Tp10p5_s1401      14 m/s     3.0 m  10.5 s  1401
    c_op18_Hs4p0_Tp11_s1802        18 m/s     4.0 m  11 s    1802
    =============================  =========  =====  ======  ==========

    Everything else is the shared runs' (``<shared>/reference/openfast``): the deck, IEC Kaimal NTM class B
    turbulence from TurbSim on the same 31 x 31 grid (the shared 18 m/s input with ``RandSeed1`` and ``URef``
    changed), SeaState's default peak shape, 600 s after a 100 s transient, 80 Hz output. For each run it writes the
    ``case.json`` sidecar and the ``inflow.npz`` (the shared folder's ``tools/bts_inflow.py``, shifted by the
    grid's convection time half a grid width over the mean wind as the shared files are, and checked against
    ``Wind1VelX``), then the compact copy ``fowt_env/data/openfast_heldout/`` with
    ``tools/compact_openfast_reference.py`` (records at 10 Hz, statistics at 80 Hz, the inflow fields at 5 Hz for
    ``fowt-env validate heldout --replay``).

Why
    The surrogate is checked on OpenFAST runs it has not seen (other seeds, other wind speeds); these are such
    runs made here, so that a user (and the tests) can see how it does on them: ``fowt-env validate heldout``.

Usage (maintainer tool, not run by the tests; TurbSim ~100 s per field and OpenFAST ~27 min per run on one core;
``--jobs 2`` runs two at a time)::

    python tools/openfast_heldout_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``:
``make openfast turbsim``; the DISCON controller is compiled into the working copy of the decks here).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SHARED = REPO.parent / "shared"
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_heldout"
GRID_HALF_WIDTH = 72.5  # m: half the TurbSim grid's 145 m width

RUNS = {
    # name: (wind m/s, Hs m, Tp s, seed, ElastoDyn initial conditions near the operating point)
    "c_op10_Hs2p5_Tp10_s1001": (10.0, 2.5, 10.0, 1001, dict(RotSpeed=11.4, BlPitch=0.0, PtfmSurge=17, PtfmPitch=3.8)),
    "c_op12_Hs2p5_Tp10_s1203": (12.0, 2.5, 10.0, 1203, dict(RotSpeed=12.1, BlPitch=0.0, PtfmSurge=20, PtfmPitch=4.5)),
    "c_op14_Hs3p0_Tp10p5_s1401": (14.0, 3.0, 10.5, 1401,
                                  dict(RotSpeed=12.1, BlPitch=8.0, PtfmSurge=17, PtfmPitch=3.4)),
    "c_op18_Hs4p0_Tp11_s1802": (18.0, 4.0, 11.0, 1802,
                                dict(RotSpeed=12.1, BlPitch=14.9, PtfmSurge=13, PtfmPitch=3.0)),
}


def ntm_b_intensity(v: float) -> float:
    """IEC 61400-1 ed. 3 NTM turbulence intensity, class B (I_ref 0.14): ``I_ref (0.75 V + 5.6) / V``."""
    return 0.14 * (0.75 * v + 5.6) / v


def turbsim_input(template: str, v: float, seed: int) -> str:
    lines = template.split("\n")
    for i, ln in enumerate(lines):
        tok = ln.split()
        if len(tok) > 1 and tok[1] == "RandSeed1":
            lines[i] = f"{seed:>11d}   RandSeed1" + ln.split("RandSeed1", 1)[1]
        elif len(tok) > 1 and tok[1] == "URef":
            lines[i] = f"{v:>11g}   URef" + ln.split("URef", 1)[1]
    return "\n".join(lines)


def working_copy(shared: Path, work: Path, openfast_build: Path) -> dict[str, str]:
    """Copy the shared decks and tools into `work` (once), compile the DISCON controller there (once) and return the
    environment for ``run_case.sh``: one BLAS thread, ``OPENFAST`` the build tree's executable."""
    ref = shared / "reference" / "openfast"
    for sub in ("decks", "tools"):
        if not (work / sub).is_dir():
            shutil.copytree(ref / sub, work / sub)
    (work / "runs").mkdir(exist_ok=True)
    servo = work / "decks" / "5MW_Baseline" / "ServoData"
    if not (servo / "DISCON_OC3Hywind.dll").is_file():
        subprocess.run(["gfortran", "-shared", "-fPIC", "-O2", "-cpp", "-ffree-line-length-none",
                        "DISCON_OC3Hywind.f90", "-o", "DISCON_OC3Hywind.dll"], cwd=servo, check=True)
    return {**os.environ, "OPENBLAS_NUM_THREADS": "1",
            "OPENFAST": str(openfast_build / "glue-codes" / "openfast" / "openfast")}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--openfast-build", required=True, type=Path, help="cmake build tree (openfast, turbsim)")
    ap.add_argument("--work", required=True, type=Path, help="working copy of the shared decks and the runs")
    ap.add_argument("--shared", default=DEFAULT_SHARED, type=Path)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=DEFAULT_OUT, type=Path)
    ap.add_argument("--runs", nargs="+", default=list(RUNS), choices=list(RUNS))
    args = ap.parse_args(argv)

    work: Path = args.work
    env = working_copy(args.shared, work, args.openfast_build)
    wind_dir = work / "decks" / "5MW_Baseline" / "Wind"
    template = (wind_dir / "NTM_B_18mps_s1801_700s.inp").read_text()

    sys.path.insert(0, str(work / "tools"))
    import make_runs  # the shared run generator (its deck paths resolve inside the working copy)

    sys.path.insert(0, str(REPO))
    from fowt_env.io import load_record

    def one(name: str) -> str:
        v, hs, tp, seed, ed = RUNS[name]
        stem = f"NTM_B_{int(v):02d}mps_s{seed}_700s"
        if not (wind_dir / f"{stem}.bts").is_file():
            (wind_dir / f"{stem}.inp").write_text(turbsim_input(template, v, seed))
            subprocess.run([str(args.openfast_build / "modules" / "turbsim" / "turbsim"), f"{stem}.inp"],
                           cwd=wind_dir, env=env, check=True, capture_output=True)
        make_runs.build(name, dict(TMax=700, TStart=100, wind=("bts", f"Wind/{stem}.bts"),
                                   sea=dict(WaveMod=2, WaveHs=hs, WaveTp=tp, WaveTMax=3600, WaveSeed1=seed), ed=ed))
        rd = work / "runs" / name
        if not (rd / f"{name}.outb").is_file():
            subprocess.run(["bash", str(work / "tools" / "run_case.sh"), name], env=env, check=True)
        raw = rd / f"{name}.inflow_raw.npz"
        subprocess.run([sys.executable, str(work / "tools" / "bts_inflow.py"), str(wind_dir / f"{stem}.bts"),
                        str(raw)], check=True, capture_output=True)
        with np.load(raw) as z:
            data = {k: z[k] for k in z.files}
        raw.unlink()
        data["t"] = data["t"] - GRID_HALF_WIDTH / float(data["uhub"])  # InflowWind's convection of the grid
        rec = load_record(rd / f"{name}.outb", unknown_channels="keep")
        err = float(np.max(np.abs(np.interp(rec.t, data["t"], data["hub_uvw"][:, 0]) - rec["Wind1VelX"])))
        if err > 0.01:
            raise RuntimeError(f"{name}: inflow hub wind differs from Wind1VelX by {err:.3f} m/s")
        np.savez_compressed(rd / f"{name}.inflow.npz", **data)
        case = {"name": name, "wave_dir_deg": 0.0, "shear_exponent": 0.2, "wind_speed": v,
                "turbulence_intensity": ntm_b_intensity(v), "turbulence_model": "IEC Kaimal NTM class B (TurbSim)",
                "turbulence_seed": seed, "hs": hs, "tp": tp, "gamma": 1.0, "wave_seed": seed, "transient_s": 100.0,
                "duration_s": 600.0,
                "gamma_note": "SeaState WavePkShp = DEFAULT (IEC 61400-3 rule from Tp/sqrt(Hs))",
                "source": "tools/openfast_heldout_runs.py: the shared OC3 deck (OpenFAST v5.0.0, 2895884d), new "
                          "seeds and wind speeds, not in the shared set"}
        (rd / f"{name}.case.json").write_text(json.dumps(case, indent=1) + "\n")
        return f"{name}: inflow hub wind within {err:.4f} m/s of Wind1VelX"

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for msg in pool.map(one, args.runs):
            print(msg, flush=True)
    subprocess.run([sys.executable, str(REPO / "tools" / "compact_openfast_reference.py"), "--source",
                    str(work / "runs"), "--out", str(args.out), "--runs", *RUNS,
                    "--readme", "tools/openfast_heldout_runs.py (OpenFAST v5.0.0, commit 2895884d, the shared OC3 "
                    "Hywind deck, new seeds and wind speeds)"], check=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
