"""Make OpenFAST runs of the OC3 deck in steady wind at 8-18 m/s, for the rotor's 3P loads across the operating range.

What
    Five 160 s runs of the shared OC3 Hywind deck, operating in steady wind with the deck's power-law shear
    (exponent 0.2) in still water, each from near its steady state (the platform's slow settling is over well
    before the last 60 s, over which the 3P lines are demodulated against the rotor azimuth):

    ===========  ==========================================================================================
    run          conditions
    ===========  ==========================================================================================
    h_st08       8 m/s (region 2, 8.9 rpm, blade pitch 0)
    h_st10       10 m/s (region 2, 10.9 rpm)
    h_st12       12 m/s (just above rated, 12.1 rpm)
    h_st14       14 m/s (region 3, blade pitch 7.4 deg)
    h_st18       18 m/s (region 3, blade pitch 14.1 deg)
    ===========  ==========================================================================================

    For each it writes the ``case.json`` sidecar, then the compact copy ``fowt_env/data/openfast_rotor_harmonics/``:
    records at 10 Hz (anti-alias filtered, float32 precision; :func:`compact_openfast_reference.compact`) with the
    rotor azimuth ``Azimuth`` *unwrapped* (deg, monotonic: the filter would smear the 360 deg wrap), the case files
    with the ElastoDyn initial conditions (``start``) and ``summary.json`` with the sha256 of every source and input.

Why
    The rotor's 3P loads on the tower (the blades passing the tower's shadow and sampling the shear) depend on the
    operating point, and the only steady-wind run of the shared reference is at 12 m/s. OpenFAST's side-to-side
    3P response of the tower base (``TwrBsMxt``, demodulated over the last 60 s of the compact records) is 198, 453,
    345, 378 and 646 kN m at 8, 10, 12, 14 and 18 m/s: it rises above rated, where the thrust falls and the
    torque's sensitivity to the wind grows with the blade pitch. :func:`surrogates.simulate.side_force_law` and
    ``tests/test_rotor_harmonics.py`` rest on these runs.

Usage (maintainer tool, not run by the tests; OpenFAST ~3.5 min per run on one core, two in parallel)::

    python tools/openfast_rotor_harmonics_runs.py --openfast-build /tmp/of/build --work /tmp/ofx [--shared ../shared]

``--openfast-build`` is the cmake build tree of the reference build (``<shared>/reference/openfast/build.sh``;
the DISCON controller is compiled into the working copy of the decks here). A run whose ``.outb`` exists is not
run again.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from surrogates.record import Record

REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "fowt_env" / "data" / "openfast_rotor_harmonics"

STILL = dict(WaveMod=0)
STATES = {
    8: dict(RotSpeed=9.24, BlPitch=0.0, TTDspFA=0.25, PtfmSurge=13.2, PtfmPitch=2.67),
    10: dict(RotSpeed=11.3, BlPitch=0.0, TTDspFA=0.35, PtfmSurge=18, PtfmPitch=3.9),
    12: dict(RotSpeed=12.1, BlPitch=1.28, TTDspFA=0.45, PtfmSurge=23.9, PtfmPitch=4.84),
    14: dict(RotSpeed=12.1, BlPitch=8.0, TTDspFA=0.3, PtfmSurge=17, PtfmPitch=3.4),
    18: dict(RotSpeed=12.1, BlPitch=14.9, TTDspFA=0.25, PtfmSurge=13, PtfmPitch=3.0),
}
"""Approximate steady states (ElastoDyn initial conditions) per wind speed (m/s)."""
RUNS = {f"h_st{u:02d}": dict(TMax=160, TStart=0, wind=("steady", float(u)), sea=STILL, ed=dict(ed))
        for u, ed in STATES.items()}
CHANNELS = ("Azimuth", "RotSpeed", "BldPitch1", "GenPwr", "RotThrust", "LSShftTq", "LSShftFya", "LSShftFza",
            "YawBrFyp", "YawBrMyp", "YawBrMzp", "YawBrTAxp", "YawBrTAyp", "TwrBsMxt", "TwrBsMyt", "TTDspFA", "TTDspSS",
            "PtfmSurge", "PtfmRoll", "PtfmPitch", "PtfmYaw", "Wind1VelX")
"""Channels of the compact records (those the run has, constant ones dropped)."""


def unwrap_azimuth(record: Record) -> Record:
    """The record with its ``Azimuth`` (deg) unwrapped, so that decimation keeps it.

    Parameters
    ----------
    record : surrogates.Record
        An OpenFAST output with the channel ``Azimuth`` (deg, wrapped to 0-360).

    Returns
    -------
    surrogates.Record
        The same record, ``Azimuth`` made monotonic (deg).
    """
    y = np.array(record.y, dtype=float)
    i = record.channels.index("Azimuth")
    y[:, i] = np.degrees(np.unwrap(np.radians(y[:, i])))
    return record.replace(y=y)


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(REPO / "tools"))
    from openfast_time_domain_runs import run_and_package

    def case_of(name: str) -> dict:
        u = float(RUNS[name]["wind"][1])
        return {"name": name, "wind_speed": u, "turbulence_intensity": 0.0, "shear_exponent": 0.2,
                "turbulence_model": "steady wind (InflowWind WindType 1), power-law shear exponent 0.2",
                "wave_dir_deg": 0.0, "hs": 0.0, "transient_s": 0.0, "duration_s": float(RUNS[name]["TMax"]),
                "note": f"steady {u:g} m/s, still water, operating from near its steady state; 3P lines over the "
                        "last 60 s (Azimuth unwrapped in the compact copy)",
                "source": "tools/openfast_rotor_harmonics_runs.py: the shared OC3 deck (OpenFAST v5.0.0, 2895884d), "
                          "still water, output from t = 0"}

    return run_and_package(argv, __doc__, RUNS, case_of, CHANNELS, DEFAULT_OUT,
                           "tools/openfast_rotor_harmonics_runs.py", transform=unwrap_azimuth)


if __name__ == "__main__":
    raise SystemExit(main())
