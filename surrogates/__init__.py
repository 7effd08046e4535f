"""Physics of the NREL 5 MW turbine on the OC3 Hywind spar: a reduced, fast, checkable surrogate.

Rigid platform (6 DOFs) + two fore-aft and two side-to-side tower modes + rotor speed with its baseline
pitch/torque controller, driven by JONSWAP waves, Kaimal turbulence and rotor 1P/3P/6P harmonics, with named
switchable nonlinear effects (:data:`EFFECTS`). Outputs are the 36 tower channels (accelerations and bending
moments at nine heights), platform motions, rotor speed, wave elevation and hub wind in OpenFAST names and
units. Knows nothing of Gymnasium or of the estimators.

Examples
--------
>>> import surrogates
>>> m = surrogates.FOWTModel()
>>> rec = surrogates.simulate(m, 7, duration=60.0, seed=1)
>>> rec.y.shape
(4800, 55)
"""

from .channels import ALL_CHANNELS, GAUGE_HEIGHTS, OPENFAST_GAUGE_HEIGHTS, UNITS, tower_channels
from .effects import EFFECTS, Effect
from .load_cases import LOAD_CASES, LoadCase, load_case, operating_case
from .model import FOWTModel, LinearSystem, ModalResult, RotorHarmonics, SensorNoise
from .record import Record
from .simulate import Simulator, simulate
from .stream import StreamingSimulator

__all__ = [
    "operating_case",
    "OPENFAST_GAUGE_HEIGHTS",
    "ALL_CHANNELS",
    "EFFECTS",
    "Effect",
    "FOWTModel",
    "GAUGE_HEIGHTS",
    "LOAD_CASES",
    "LinearSystem",
    "LoadCase",
    "ModalResult",
    "Record",
    "RotorHarmonics",
    "SensorNoise",
    "Simulator",
    "StreamingSimulator",
    "UNITS",
    "load_case",
    "simulate",
    "tower_channels",
]
