"""Make OpenFAST runs of the OC3 rotor in steady wind on a held platform, for the rotor's quasi-static operating
points near rated.

What
    Short runs (220 s, means over the last 60 s) of the shared OC3 Hywind deck with every platform DOF off, the
    platform held at 4.8 deg of pitch (the shared steady 12 m/s run's mean, so that the rotor is inclined as
    there: 5 deg of shaft tilt plus the platform's pitch) and at zero surge, no waves, no hydrodynamics and no
    mooring (``CompSeaSt = CompHydro = CompMooring = 0``), in steady wind with the deck's power-law shear
    (exponent 0.2), the tower, blades and drivetrain flexible and the controller the deck's DISCON:

    ===========================  ===================================================================================
    runs                         conditions
    ===========================  ===================================================================================
    ``qs_U11p8_p48`` ...         11.8, 12.0, 12.2 and 12.4 m/s: across rated (11.8 m/s is below it on this inclined
                                 rotor), flexible blades
    ``..._rigid``                12.0 and 12.4 m/s, blade flap and edge DOFs off
    ``..._noshear``              12.0 and 12.4 m/s, no shear (``PLExp = 0``)
    ===========================  ===================================================================================

    It writes ``fowt_env/data/openfast_quasi_static.json``: per run the conditions and the means of ``BldPitch1``,
    ``RotThrust``, ``GenPwr``, ``RotSpeed``, ``YawBrMzp``, ``OoPDefl1`` and ``TTDspFA`` over 160-220 s (the runs
    settle within ~100 s; the pitch's std over the window is below 0.01 deg), with the sha256 of every input.

Why
    The controller's pitch follows the wind through the rotor's aerodynamics near rated, which set how the platform
    surges and pitches slowly and how much the yaw moment of the inclined rotor moves with the pitch. The
    surrogate's rotor (AeroDyn's tables, the bent blades' blend, DISCON) is checked against these operating points
    in ``tests/test_quasi_static_rotor.py``: measured within 0.03 deg of pitch and 0.5 % of thrust. OpenFAST's held
    yaw moment along them (196 kN m at 12.0 m/s, 158 at 12.4; -475 and -488 without shear, 198 and 129 with rigid
    blades) says that the shear carries most of the inclined rotor's mean yaw moment and that the flexible blades
    halve its change with the pitch.

Usage (maintainer tool, not run by the tests; ~1.5 min of OpenFAST per run on one core, two in parallel)::

    python tools/openfast_quasi_static_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``); a run
whose ``.outb`` exists is not run again.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_quasi_static.json"
PLATFORM_PITCH_DEG = 4.8
WINDOW_S = (160.0, 220.0)
CHANNELS = ("BldPitch1", "RotThrust", "GenPwr", "RotSpeed", "YawBrMzp", "OoPDefl1", "TTDspFA")
HELD = ("PtfmSgDOF", "PtfmSwDOF", "PtfmHvDOF", "PtfmRDOF", "PtfmPDOF", "PtfmYDOF")


def _runs() -> dict[str, dict]:
    runs = {}
    for u in (11.8, 12.0, 12.2, 12.4):
        runs[f"qs_U{u:.1f}_p48".replace(".", "p", 1)] = dict(wind=u, rigid=False, shear=0.2)
    for u in (12.0, 12.4):
        runs[f"qs_U{u:.1f}_p48_rigid".replace(".", "p", 1)] = dict(wind=u, rigid=True, shear=0.2)
        runs[f"qs_U{u:.1f}_p48_noshear".replace(".", "p", 1)] = dict(wind=u, rigid=False, shear=0.0)
    return runs


def _set(text: str, key: str, value: object) -> str:
    """The value field of the first line whose key is ``key`` set to ``value``."""
    pat = re.compile(r"^(\s*)(\S+)(\s+)(" + re.escape(key) + r")(\s.*|$)", re.M)
    text, n = pat.subn(lambda m: f"{str(value):>11}   {key}{m.group(5)}", text, count=1)
    if n != 1:
        raise KeyError(key)
    return text


def _edit(path: Path, **values: object) -> None:
    text = path.read_text()
    for k, v in values.items():
        text = _set(text, k, v)
    path.write_text(text)


def _build(name: str) -> dict:
    """``make_runs.build``'s spec of run ``name``: every platform DOF off at PLATFORM_PITCH_DEG, steady wind."""
    spec = _runs()[name]
    ed = {**dict.fromkeys(HELD, "False"), "PtfmPitch": PLATFORM_PITCH_DEG, "PtfmSurge": 0, "RotSpeed": 12.1,
          "BlPitch": 0.0}
    if spec["rigid"]:
        ed.update(FlapDOF1="False", FlapDOF2="False", EdgeDOF="False")
    return dict(TMax=WINDOW_S[1], TStart=0, wind=("steady", spec["wind"]), sea=dict(WaveMod=0), ed=ed)


def _edit_run(rd: Path, name: str) -> None:
    """What the shared generator does not set: no sea, hydrodynamics or mooring, 20 Hz output, the run's shear."""
    _edit(rd / f"{name}.fst", CompSeaSt=0, CompHydro=0, CompMooring=0, DT_Out=0.05)
    _edit(rd / f"{name}_InflowWind.dat", PLExp=_runs()[name]["shear"])


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(REPO))
    sys.path.insert(0, str(REPO / "tools"))
    from compact_openfast_reference import sha256
    from openfast_time_domain_runs import build_and_run

    from fowt_env.io import load_record

    runs = _runs()
    args, work, names = build_and_run(argv, __doc__, {name: _build(name) for name in runs}, DEFAULT_OUT,
                                      edit=_edit_run)

    out: dict = {"created_by": "tools/openfast_quasi_static_runs.py",
                 "source": "the shared OC3 Hywind deck (OpenFAST v5.0.0, 2895884d), every platform DOF off at "
                           f"{PLATFORM_PITCH_DEG} deg of pitch, no sea, hydrodynamics or mooring, steady wind",
                 "platform_pitch_deg": PLATFORM_PITCH_DEG, "window_s": list(WINDOW_S), "runs": {}}
    for name in names:
        rd = work / "runs" / name
        rec = load_record(rd / f"{name}.outb", unknown_channels="keep")
        t = np.asarray(rec.t, float)
        keep = (t >= WINDOW_S[0] - 1e-9) & (t <= WINDOW_S[1] + 1e-9)
        spec = runs[name]
        out["runs"][name] = {
            "wind_speed": spec["wind"], "shear_exponent": spec["shear"], "rigid_blades": spec["rigid"],
            "mean": {c: round(float(np.mean(np.asarray(rec[c], float)[keep])), 4) for c in CHANNELS},
            "pitch_std_deg": round(float(np.std(np.asarray(rec["BldPitch1"], float)[keep])), 4),
            "inputs_sha256": {p.name: sha256(p) for p in sorted(rd.glob("*.dat")) + sorted(rd.glob("*.fst"))},
        }
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {args.out}")
    for name, r in out["runs"].items():
        print(name, r["mean"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
