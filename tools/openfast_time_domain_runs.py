"""Make OpenFAST runs of the OC3 deck that start from the deck's initial state, for time-domain checks.

What
    Two 400 s runs of the shared OC3 Hywind deck with output from t = 0 (the shared operating runs drop their
    first 100 s), in the steady-wind run's sea (JONSWAP Hs 2.5 m, Tp 10 s, SeaState's default peak shape, wave
    seed 1201, ``WaveTMax`` 3600 s: the same elevation as ``d_steady12_Hs2p5_Tp10``):

    ==============================  ================================================================
    run                             conditions
    ==============================  ================================================================
    t_steady12_Hs2p5_Tp10_from0     steady 12 m/s wind (shear 0.2), operating, from the deck's
                                    initial conditions (surge 20 m, pitch 4.5 deg, 12.1 rpm):
                                    the shared steady-wind run with its start-up kept
    t_parked_Hs2p5_Tp10             still air, no aerodynamics, rotor parked (the free decays'
                                    settings), platform at rest at the origin
    ==============================  ================================================================

    For each it writes the ``case.json`` sidecar, then the compact copy ``fowt_env/data/openfast_time_domain/``:
    records at 10 Hz (anti-alias filtered, float32 precision; :func:`compact_openfast_reference.compact`), the
    case files with the ElastoDyn initial conditions (``start``), and ``summary.json`` with the sha256 of every
    source file.

Why
    Starting where OpenFAST starts and driven by its own wave elevation, the surrogate must follow OpenFAST's time
    series, not only its statistics: ``fowt-env validate time-domain`` (:func:`fowt_env.validation.time_domain`)
    replays both runs and reports R^2 per channel. A replay that starts inside a record (the shared runs begin
    100 s in) rings at the platform's 30 s and 120 s periods while it forgets the sea before its start; these
    runs have no such start.

Usage (maintainer tool, not run by the tests; OpenFAST ~11 and ~8 min on one core, the two in parallel)::

    python tools/openfast_time_domain_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``;
the DISCON controller is compiled into the working copy of the decks here). A run whose ``.outb`` exists is not
run again.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from surrogates.record import Record

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SHARED = REPO.parent / "shared"
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_time_domain"

SEA = dict(WaveMod=2, WaveHs=2.5, WaveTp=10, WaveTMax=3600, WaveSeed1=1201)
RUNS = {
    "t_steady12_Hs2p5_Tp10_from0": dict(TMax=400, TStart=0, wind=("steady", 12.0), sea=SEA,
                                        ed=dict(RotSpeed=12.1, BlPitch=0.0, PtfmSurge=20, PtfmPitch=4.5)),
    "t_parked_Hs2p5_Tp10": dict(TMax=400, TStart=0, wind=None, sea=SEA, ed=dict(GenDOF="False", RotSpeed=0)),
}
CASES = {
    "t_steady12_Hs2p5_Tp10_from0": {
        "wind_speed": 12.0, "turbulence_intensity": 0.0, "shear_exponent": 0.2,
        "turbulence_model": "steady wind (InflowWind WindType 1), power-law shear exponent 0.2",
        "note": "the shared d_steady12_Hs2p5_Tp10 run with its output from t = 0 (the deck's initial conditions)"},
    "t_parked_Hs2p5_Tp10": {
        "wind_speed": 0.0, "rotor": "parked (GenDOF off, RotSpeed 0), no aerodynamics (CompAero 0, CompInflow 0)",
        "note": "the free decays' settings in the d_steady12_Hs2p5_Tp10 sea, platform at rest at the origin"},
}
CHANNELS = ("PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw", "RotSpeed", "BldPitch1",
            "GenPwr", "GenTq", "RotThrust", "TwrBsMyt", "TwrBsMxt", "YawBrTAxp", "YawBrTAyp", "TTDspFA", "TTDspSS",
            "Wave1Elev", "Wind1VelX", "TwHt1MLxt", "TwHt1MLyt", "TwHt9ALxt", "TwHt9ALyt", "TwHt9MLxt", "TwHt9MLyt")
"""Channels of the compact records (those the run has, constant ones dropped)."""
FS_OUT = 10.0


def main(argv: list[str] | None = None) -> int:
    def case_of(name: str) -> dict:
        return {"name": name, "wave_dir_deg": 0.0, "hs": 2.5, "tp": 10.0, "gamma": 1.0, "wave_seed": 1201,
                **CASES[name], "transient_s": 0.0, "duration_s": 400.0,
                "gamma_note": "SeaState WavePkShp = DEFAULT (IEC 61400-3 rule from Tp/sqrt(Hs))",
                "source": "tools/openfast_time_domain_runs.py: the shared OC3 deck (OpenFAST v5.0.0, 2895884d), "
                          "output from t = 0"}

    return run_and_package(argv, __doc__, RUNS, case_of, CHANNELS, DEFAULT_OUT, "tools/openfast_time_domain_runs.py")


def build_and_run(argv: list[str] | None, doc: str, runs: dict, default_out: Path,
                  edit: Callable[[Path, str], None] | None = None) -> tuple[argparse.Namespace, Path, list[str]]:
    """The command line shared by the OpenFAST run tools: a working copy of the shared decks (``--work``), each of
    ``runs`` built there by ``make_runs.build`` (then ``edit(run_dir, name)`` if given, for deck changes the shared
    generator does not make) and run with OpenFAST unless its ``.outb`` exists. Returns the parsed arguments, the
    working copy and the run names."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--openfast-build", required=True, type=Path, help="cmake build tree (openfast)")
    ap.add_argument("--work", required=True, type=Path, help="working copy of the shared decks and the runs")
    ap.add_argument("--shared", default=DEFAULT_SHARED, type=Path)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=default_out, type=Path)
    args = ap.parse_args(argv)

    sys.path.insert(0, str(REPO))
    sys.path.insert(0, str(REPO / "tools"))
    from openfast_heldout_runs import working_copy

    work: Path = args.work
    env = working_copy(args.shared, work, args.openfast_build)
    sys.path.insert(0, str(work / "tools"))
    import make_runs  # the shared run generator (its deck paths resolve inside the working copy)

    def one(name: str) -> str:
        rd = Path(make_runs.build(name, runs[name]))
        if edit is not None:
            edit(rd, name)
        if not (rd / f"{name}.outb").is_file():
            subprocess.run(["bash", str(work / "tools" / "run_case.sh"), name], env=env, check=True)
        return name

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        names = list(pool.map(one, runs))
    return args, work, names


def run_and_package(argv: list[str] | None, doc: str, runs: dict, case_of: Callable[[str], dict],
                    channels: tuple[str, ...], default_out: Path, created_by: str,
                    transform: Callable[[Record], Record] | None = None) -> int:
    """:func:`build_and_run` of ``runs``, then each run's ``case.json`` (``case_of(name)``) and :func:`package`
    of them, each record passed through ``transform`` first if given."""
    args, work, names = build_and_run(argv, doc, runs, default_out)
    for name in names:
        (work / "runs" / name / f"{name}.case.json").write_text(json.dumps(case_of(name), indent=1) + "\n")
    package(work, names, args.out, channels, created_by, transform)
    return 0


def package(work: Path, names: list[str], out: Path, channels: tuple[str, ...], created_by: str,
            transform: Callable[[Record], Record] | None = None) -> None:
    """Compact copies of the runs ``work/runs/<name>`` in ``out``: records at :data:`FS_OUT` of the ``channels``
    each run has (constant ones dropped), the case files with the ElastoDyn initial conditions (``start``) and
    ``summary.json`` with the sha256 of every source and input. ``transform(record)``, if given, returns the
    record to compact (e.g. with the rotor azimuth unwrapped, which the anti-alias filter would smear)."""
    sys.path.insert(0, str(REPO))
    sys.path.insert(0, str(REPO / "tools"))
    from compact_openfast_reference import compact, sha256

    from fowt_env import validation
    from fowt_env.io import load_record

    out.mkdir(parents=True, exist_ok=True)
    summary: dict = {"created_by": created_by, "fs_hz": FS_OUT, "runs": {}}
    for name in names:
        rd = work / "runs" / name
        outb = rd / f"{name}.outb"
        rec = load_record(outb, unknown_channels="keep")
        if transform is not None:
            rec = transform(rec)
        chans = [c for c in channels if c in rec and float(rec[c].std()) > 0.0]
        small = compact(rec, chans, FS_OUT, name, f"{name}/{outb.name}")
        small.save(out / f"{name}.npz")
        case = json.loads((rd / f"{name}.case.json").read_text())
        case["start"] = validation.elastodyn_initial_conditions(rd / f"{name}_ElastoDyn.dat")
        (out / f"{name}.case.json").write_text(json.dumps(case, indent=1) + "\n")
        summary["runs"][name] = {
            "source": {"path": str(outb), "bytes": outb.stat().st_size, "sha256": sha256(outb), "fs_hz": rec.fs},
            "inputs_sha256": {p.name: sha256(p) for p in sorted(rd.glob("*.dat")) + sorted(rd.glob("*.fst"))},
            "compact": {"file": f"{name}.npz", "fs_hz": FS_OUT, "channels": chans}}
        print(f"{name}: {len(chans)} channels, {(out / f'{name}.npz').stat().st_size / 1e3:.0f} kB")
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")


if __name__ == "__main__":
    raise SystemExit(main())
