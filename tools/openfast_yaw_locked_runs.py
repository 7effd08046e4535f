"""Make OpenFAST runs of the OC3 deck in waves with the platform's yaw held, for the yaw moment
that the platform's pitching puts on the rotor.

What
    Two 400 s runs of the shared OC3 Hywind deck in the shared ``d_steady12_Hs2p5_Tp10`` sea (irregular waves
    Hs 2.5 m, Tp 10 s, seed 1201), from the deck's initial conditions, with ElastoDyn's platform-yaw DOF off
    (``PtfmYDOF = False``): the yaw bearing's moment ``YawBrMzp`` is then the yaw moment the rotor and nacelle put
    on the platform, none of it spent on the platform's own yaw motion.

    ===========================  ===================================================================================
    run                          conditions
    ===========================  ===================================================================================
    ``yl_steady12_Hs2p5_Tp10``   the shared run's steady 12 m/s (the deck's power-law shear, exponent 0.2)
    ``yl_gyro_Hs2p5_Tp10``       no wind and no aerodynamics (``CompAero = 0``), the rotor turning at a fixed
                                 12.1 rpm (``GenDOF = False``), rigid blades (flap and edge DOFs off): the
                                 gyroscopic yaw moment alone
    ===========================  ===================================================================================

    For each it writes the ``case.json`` sidecar, then the compact copy ``fowt_env/data/openfast_yaw_locked/``:
    records at 10 Hz (anti-alias filtered, float32 precision; :func:`compact_openfast_reference.compact`), the case
    files with the ElastoDyn initial conditions (``start``) and ``summary.json`` with the sha256 of every source
    and input.

Why
    In steady wind, OpenFAST's platform yaw in the wave band answers the platform's pitch: the spinning rotor's
    gyroscopic moment (``J Omega`` times the tower top's pitch rate) less the aerodynamic yaw moment of the pitching
    disc. Held, the platform shows that moment alone. Over 0.08-0.14 Hz OpenFAST's ``YawBrMzp`` per unit platform
    pitch rate is 19.6 MN m s in phase and -13.7 MN m s in quadrature (means over the band); the gyroscopic part
    alone (``yl_gyro_Hs2p5_Tp10``) is 48.5 MN m s per unit platform pitch rate plus 1.20 MN m per m/s of the tower
    top's fore-aft deflection rate. :data:`surrogates.model.DISC_RATE_LAG_DEG` and
    ``tests/test_yaw_locked.py`` rest on these runs.

Usage (maintainer tool, not run by the tests; OpenFAST ~10 min per run on one core, two in parallel)::

    python tools/openfast_yaw_locked_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``;
the DISCON controller is compiled into the working copy of the decks here). A run whose ``.outb`` exists is not
run again.
"""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_yaw_locked"

SEA = dict(WaveMod=2, WaveHs=2.5, WaveTp=10, WaveTMax=3600, WaveSeed1=1201)
RUNS = {
    "yl_steady12_Hs2p5_Tp10": dict(TMax=400, TStart=0, wind=("steady", 12.0), sea=SEA,
                                   ed=dict(RotSpeed=12.1, BlPitch=0.0, PtfmSurge=20, PtfmPitch=4.5,
                                           PtfmYDOF="False")),
    "yl_gyro_Hs2p5_Tp10": dict(TMax=400, TStart=0, wind=None, sea=SEA,
                               ed=dict(GenDOF="False", RotSpeed=12.1, PtfmYDOF="False", FlapDOF1="False",
                                       FlapDOF2="False", EdgeDOF="False")),
}
CHANNELS = ("PtfmSurge", "PtfmHeave", "PtfmRoll", "PtfmPitch", "RotSpeed", "BldPitch1", "RotThrust", "LSShftTq",
            "YawBrMxp", "YawBrMyp", "YawBrMzp", "TTDspFA", "TTDspSS", "Wave1Elev")
"""Channels of the compact record (those the run has, constant ones dropped)."""


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(REPO / "tools"))
    from openfast_time_domain_runs import run_and_package

    def case_of(name: str) -> dict:
        sea = {"name": name, "wave_dir_deg": 0.0, "hs": 2.5, "tp": 10.0, "gamma": 1.0, "wave_seed": 1201,
               "gamma_note": "SeaState WavePkShp = DEFAULT (IEC 61400-3 rule from Tp/sqrt(Hs))",
               "transient_s": 0.0, "duration_s": float(RUNS[name]["TMax"])}
        source = ("tools/openfast_yaw_locked_runs.py: the shared OC3 deck (OpenFAST v5.0.0, 2895884d), "
                  "PtfmYDOF = False, output from t = 0")
        if RUNS[name]["wind"] is None:
            return {**sea, "wind_speed": 0.0, "locked_dofs": ["PtfmYDOF", "FlapDOF1", "FlapDOF2", "EdgeDOF"],
                    "rotor": "turning at a fixed 12.1 rpm (GenDOF off), rigid blades, no aerodynamics (CompAero 0, "
                             "CompInflow 0)",
                    "note": "the gyroscopic yaw moment alone: the spinning rotor on the pitching platform, yaw held",
                    "source": source + ", no aerodynamics"}
        return {**sea, "wind_speed": 12.0, "turbulence_intensity": 0.0, "shear_exponent": 0.2,
                "turbulence_model": "steady wind (InflowWind WindType 1), power-law shear exponent 0.2",
                "locked_dofs": ["PtfmYDOF"],
                "note": "the shared d_steady12_Hs2p5_Tp10 conditions from the deck's initial conditions, the "
                        "platform's yaw DOF off: YawBrMzp is the yaw moment on the held platform",
                "source": source}

    return run_and_package(argv, __doc__, RUNS, case_of, CHANNELS, DEFAULT_OUT, "tools/openfast_yaw_locked_runs.py")


if __name__ == "__main__":
    raise SystemExit(main())
