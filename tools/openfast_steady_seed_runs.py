"""Make OpenFAST runs of the shared steady-wind case in other seas of the same spectrum (other wave seeds).

What
    Four runs of the shared OC3 Hywind deck exactly as ``d_steady12_Hs2p5_Tp10`` (steady 12 m/s wind with the
    deck's power-law shear 0.2, JONSWAP Hs 2.5 m, Tp 10 s with SeaState's default peak shape, ``WaveTMax`` 3600 s,
    the deck's initial conditions, 400 s with the first 100 s dropped) except the wave seed: ``WaveSeed(1)`` =
    1202, 1203, 1204 and 1205 (the shared run has 1201). Each run folder gets its ``case.json`` sidecar. The four
    and the shared run are then packaged like the default reference data by ``tools/compact_openfast_reference.py``
    (records at 10 Hz, statistics at the full 80 Hz in ``summary.json``) in ``fowt_env/data/openfast_steady_seas/``:
    the steady-wind case in five seas of one spectrum (``fowt-env validate steady-seas``).

Why
    Near rated the platform's slow surge is a limit cycle in OpenFAST as in the surrogate (the blade pitch touches
    fine pitch every cycle), and the shared steady run has one 300 s realisation of it: two or three cycles. Its
    slow statistics (surge, pitch and yaw below 0.05 Hz) therefore carry the chance of one sea. These runs measure
    how much OpenFAST's own statistics move from sea to sea, which the check of the surrogate against the shared
    run cannot know (README "Fidelity against OpenFAST"; ``tests/test_steady_seas.py``). Measured: OpenFAST's
    slow (< 0.05 Hz) std of surge is 1.99-3.20 m over the five seas, of the blade pitch 0.60-0.92 deg and of the
    yaw 0.0136-0.0180 deg, the shared sea giving the least of each.

Usage (maintainer tool, not run by the tests; ~11 min of OpenFAST per run on one core, two in parallel)::

    python tools/openfast_steady_seed_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``); a run
whose ``.outb`` exists is not run again.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))

from openfast_time_domain_runs import build_and_run  # noqa: E402

DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_steady_seas"
SHARED_RUN = "d_steady12_Hs2p5_Tp10"
SEEDS = (1202, 1203, 1204, 1205)
START = dict(RotSpeed=12.1, BlPitch=0.0, PtfmSurge=20, PtfmPitch=4.5)
RUNS = {f"{SHARED_RUN}_s{seed}": dict(
    TMax=400, TStart=100, wind=("steady", 12.0),
    sea=dict(WaveMod=2, WaveHs=2.5, WaveTp=10, WaveTMax=3600, WaveSeed1=seed), ed=dict(START))
    for seed in SEEDS}


def main(argv: list[str] | None = None) -> int:
    args, work, names = build_and_run(argv, __doc__, RUNS, DEFAULT_OUT)
    shared_run = args.shared / "reference" / "openfast" / "runs" / SHARED_RUN
    shared_case = json.loads((shared_run / f"{SHARED_RUN}.case.json").read_text())

    def case_of(name: str) -> dict:  # the shared run's conditions, another sea
        seed = RUNS[name]["sea"]["WaveSeed1"]
        return {**shared_case, "name": name, "wave_seed": seed,
                "source": f"tools/openfast_steady_seed_runs.py: the shared {SHARED_RUN} run with WaveSeed(1) = {seed} "
                          "(OpenFAST v5.0.0, 2895884d)"}

    seas = work / "steady_seas"  # the four runs and the shared one, side by side for the packaging tool
    seas.mkdir(exist_ok=True)
    for name in names:
        (work / "runs" / name / f"{name}.case.json").write_text(json.dumps(case_of(name), indent=1) + "\n")
    sources = {name: work / "runs" / name for name in names}
    sources[SHARED_RUN] = shared_run
    for name, folder in sources.items():
        link = seas / name
        if not link.exists():
            link.symlink_to(folder.resolve(), target_is_directory=True)
    subprocess.run([sys.executable, str(REPO / "tools" / "compact_openfast_reference.py"), "--source", str(seas),
                    "--out", str(args.out), "--no-inflow",
                    "--readme", "tools/openfast_steady_seed_runs.py (OpenFAST v5.0.0, commit 2895884d, the shared "
                    "OC3 Hywind deck's steady-wind run and four more wave seeds)"], check=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
