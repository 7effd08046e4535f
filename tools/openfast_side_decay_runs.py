"""Make OpenFAST yaw, roll and tower side-to-side free decays of the OC3 deck, parked and in operation.

What
    Seven runs of the shared OC3 Hywind deck in still water with output from t = 0:

    ====================  ======================================================================================
    run                   conditions
    ====================  ======================================================================================
    yd_parked_yaw5        still air, no aerodynamics, rotor parked (the free decays' settings), platform
                          released from 5 deg of yaw at the origin; 150 s
    yd_op12_yaw3          steady 12 m/s wind (shear 0.2), operating, released from 3 deg of yaw at the steady
                          state of the shared steady-wind deck in still water (its mean over 200-300 s: surge
                          23.9 m, heave -0.55 m, roll 0.23 deg, pitch 4.84 deg, tower top 0.45 m downwind,
                          blade pitch 1.28 deg, 12.1 rpm); 250 s
    rd_parked_roll3       as yd_parked_yaw5, released from 3 deg of roll; 200 s
    rd_op12_roll2         as yd_op12_yaw3, released from 2 deg more roll than the steady state's (2.23 deg); 250 s
    sd_parked_ss0p3       as yd_parked_yaw5, the tower top released from 0.3 m side-to-side; 60 s
    sd_op12_ss0p3         as yd_op12_yaw3, the tower top released from 0.3 m side-to-side; 80 s
    sd_op08_ss0p3         steady 8 m/s wind (shear 0.2), operating in region 2, from near the shared turbulent 8 m/s
                          run's mean state (9.24 rpm, surge 13.2 m, pitch 2.67 deg) with the tower top 0.3 m
                          side-to-side; 80 s
    ====================  ======================================================================================

    For each it writes the ``case.json`` sidecar (with the ElastoDyn initial conditions as ``start``), then the
    compact copy ``fowt_env/data/openfast_side_decays/``: records at 10 Hz (anti-alias filtered, float32 precision;
    :func:`compact_openfast_reference.compact`) and ``summary.json`` with the sha256 of every source and input.

Why
    The platform's yaw mode in operation is not the parked one. OpenFAST's parked spar yaws at 0.121 Hz; spinning
    without aerodynamics and upright at 0.130 Hz; spinning without aerodynamics but pitched 4.9 deg by a constant
    load (HydroDyn ``AddF0``) at 0.092 Hz -- HydroDyn applies its matrices to the fixed-axes angles, so the pitched
    spar's own yaw meets the roll added inertia (``hydro_fixed_axes``); and in operation at 0.094 Hz with a damping
    ratio of 0.19 (the rotor's aerodynamic yaw damping). The wave-band side-to-side response in steady wind (roll,
    sway, yaw at 0.1-0.15 Hz) sits on that mode. The roll decays give the roll mode (29.9 s parked, 29.5 s in
    operation) and how much the pitched platform yaws as it rolls. The tower's side-to-side decays give its first
    side-to-side mode parked (0.457 Hz, the rotor locked to the nacelle) and in operation, where the rotor turns
    free of the nacelle's roll (0.497-0.498 Hz at 8 and at 12 m/s, damping 1.0 %): on it sits the 3P resonance of a
    turbulent 12 m/s run whose rotor drops into region 2 (``tests/test_tower_side_decay.py``).
    ``tests/test_yaw_decay.py`` and ``tests/test_roll_decay.py`` hold the surrogate to the platform's decays.

Usage (maintainer tool, not run by the tests; OpenFAST 3-8 min per run on one core, two in parallel)::

    python tools/openfast_side_decay_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``;
the DISCON controller is compiled into the working copy of the decks here). A run whose ``.outb`` exists is not
run again.
"""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SHARED = REPO.parent / "shared"
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_side_decays"

STILL = dict(WaveMod=0)
STEADY_STATE = dict(RotSpeed=12.1, BlPitch=1.28, TTDspFA=0.45, PtfmSurge=23.9, PtfmHeave=-0.55, PtfmRoll=0.23,
                    PtfmPitch=4.84)
"""The shared steady-wind deck's state at 12 m/s in still water (mean over 200-300 s of a run from the deck's
initial conditions): the operating decay starts there, so that only the yaw is released."""
STEADY_STATE_8 = dict(RotSpeed=9.24, BlPitch=0.0, TTDspFA=0.25, PtfmSurge=13.2, PtfmHeave=-0.21, PtfmRoll=0.12,
                      PtfmPitch=2.67)
"""The 8 m/s operating state (means of the shared turbulent 8 m/s run): the region-2 tower decay starts near it;
the platform's slow settling is far below the tower mode and is filtered out of the decay."""
RUNS = {
    "yd_parked_yaw5": dict(TMax=150, TStart=0, wind=None, sea=STILL,
                           ed=dict(GenDOF="False", RotSpeed=0, PtfmYaw=5.0)),
    "yd_op12_yaw3": dict(TMax=250, TStart=0, wind=("steady", 12.0), sea=STILL, ed=dict(STEADY_STATE, PtfmYaw=3.0)),
    "rd_parked_roll3": dict(TMax=200, TStart=0, wind=None, sea=STILL,
                            ed=dict(GenDOF="False", RotSpeed=0, PtfmRoll=3.0)),
    "rd_op12_roll2": dict(TMax=250, TStart=0, wind=("steady", 12.0), sea=STILL,
                          ed=dict(STEADY_STATE, PtfmRoll=STEADY_STATE["PtfmRoll"] + 2.0)),
    "sd_parked_ss0p3": dict(TMax=60, TStart=0, wind=None, sea=STILL, ed=dict(GenDOF="False", RotSpeed=0, TTDspSS=0.3)),
    "sd_op12_ss0p3": dict(TMax=80, TStart=0, wind=("steady", 12.0), sea=STILL, ed=dict(STEADY_STATE, TTDspSS=0.3)),
    "sd_op08_ss0p3": dict(TMax=80, TStart=0, wind=("steady", 8.0), sea=STILL, ed=dict(STEADY_STATE_8, TTDspSS=0.3)),
}
PARKED_CASE = {"wind_speed": 0.0,
               "rotor": "parked (GenDOF off, RotSpeed 0), no aerodynamics (CompAero 0, CompInflow 0)"}
STEADY_12_CASE = {"wind_speed": 12.0, "turbulence_intensity": 0.0, "shear_exponent": 0.2,
                  "turbulence_model": "steady wind (InflowWind WindType 1), power-law shear exponent 0.2"}
CASES = {
    "yd_parked_yaw5": {**PARKED_CASE, "initial": {"PtfmYaw": 5.0}, "note": "yaw free decay, still water, no wind"},
    "yd_op12_yaw3": {**STEADY_12_CASE,
                     "note": "yaw free decay in operation, still water, from the steady state with 3 deg of yaw"},
    "rd_parked_roll3": {**PARKED_CASE, "initial": {"PtfmRoll": 3.0}, "note": "roll free decay, still water, no wind"},
    "rd_op12_roll2": {**STEADY_12_CASE, "note": "roll free decay in operation, still water, from the steady state "
                                                "with 2 deg more roll"},
    "sd_parked_ss0p3": {**PARKED_CASE, "initial": {"TTDspSS": 0.3},
                        "note": "tower side-to-side free decay, still water, no wind"},
    "sd_op12_ss0p3": {**STEADY_12_CASE, "note": "tower side-to-side free decay in operation (region 3), still water, "
                                                "from the steady state with 0.3 m of tower-top side-to-side"},
    "sd_op08_ss0p3": {**STEADY_12_CASE, "wind_speed": 8.0,
                      "turbulence_model": "steady wind (InflowWind WindType 1), power-law shear exponent 0.2",
                      "note": "tower side-to-side free decay in operation (region 2), still water, from near the "
                              "8 m/s operating state with 0.3 m of tower-top side-to-side"},
}
CHANNELS = ("PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw", "RotSpeed", "BldPitch1",
            "GenPwr", "GenTq", "RotThrust", "TwrBsMyt", "TwrBsMxt", "YawBrTAxp", "YawBrTAyp", "TTDspFA", "TTDspSS",
            "Wind1VelX")
"""Channels of the compact records (those the run has, constant ones dropped)."""


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(REPO / "tools"))
    from openfast_time_domain_runs import run_and_package

    def case_of(name: str) -> dict:
        return {"name": name, "wave_dir_deg": 0.0, "hs": 0.0, **CASES[name], "transient_s": 0.0,
                "duration_s": float(RUNS[name]["TMax"]),
                "source": "tools/openfast_side_decay_runs.py: the shared OC3 deck (OpenFAST v5.0.0, 2895884d), "
                          "still water, output from t = 0"}

    return run_and_package(argv, __doc__, RUNS, case_of, CHANNELS, DEFAULT_OUT, "tools/openfast_side_decay_runs.py")


if __name__ == "__main__":
    raise SystemExit(main())
