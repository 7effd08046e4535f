"""The OC3 Hywind baseline controller (``DISCON_OC3Hywind``), reproduced: torque law by regions and the
gain-scheduled PI collective-pitch loop with its saturation and rate limits.

Source: the legacy NREL 5 MW Bladed-style controller in its OC3 Hywind variant (Jonkman 2010,
NREL/TP-500-47535, section 7), the ``DISCON_OC3Hywind.f90`` used by the OpenFAST reference runs. Every
constant below is that file's; nothing is re-derived. The OC3 Hywind variant differs from the land-based
baseline in two places: the pitch gains are detuned (``PC_KP``, ``PC_KI``, a loop near 0.2 rad/s below the
platform-pitch mode) and region 3 holds the generator torque constant (``VS_RtPwr / PC_RefSpd``) instead of the
power.

The controller acts on the high-speed-shaft (generator) speed ``N * Omega`` through a single-pole low-pass
filter, is called at every internal step of the simulation (the DLL's own intervals, 1.25 ms, are shorter than
any step used here, so it acts at every call exactly as in OpenFAST), and commands

- the generator torque (HSS, N·m) by region: 1 (zero below cut-in), 1½ (linear ramp), 2 (``K ω²``), 2½
  (induction-generator slope to rated), 3 (constant torque when the filtered speed reaches rated or the pitch
  exceeds 1°), saturated at ``VS_MaxTq`` and rate-limited to ``VS_MaxRat``;
- the collective blade pitch (rad): PI on the filtered speed error with gain-correction factor
  ``GK = 1 / (1 + pitch / PC_KK)``, the integrator clamped to the pitch limits, the command clamped to
  ``[PC_MinPit, PC_MaxPit]`` and its rate to ``PC_MaxRat`` (8 deg/s). The blade pitch follows the command
  directly (ElastoDyn's ``PitchDOF = False``).

State (a float array of :data:`N_CONTROLLER_STATE`): filtered generator speed (rad/s), integral of the speed
error (rad), blade pitch (rad), last generator torque (N·m, HSS).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from scipy.optimize import brentq

__all__ = ["DISCON", "N_CONTROLLER_STATE", "discon_step", "generator_torque_law", "steady_state", "SteadyState",
           "initial_controller_state"]

DISCON: dict[str, float] = {
    "CornerFreq": 1.570796,  # rad/s, generator-speed low-pass filter corner
    "PC_KI": 0.0008965149,  # -, integral gain at zero pitch (OC3 Hywind, detuned)
    "PC_KK": 0.1099965,  # rad, pitch at which dP/dpitch has doubled
    "PC_KP": 0.006275604,  # s, proportional gain at zero pitch (OC3 Hywind, detuned)
    "PC_MaxPit": 1.570796,  # rad
    "PC_MaxRat": 0.1396263,  # rad/s (8 deg/s)
    "PC_MinPit": 0.0,  # rad
    "PC_RefSpd": 122.9096,  # rad/s, HSS
    "VS_CtInSp": 70.16224,  # rad/s, HSS, region 1 / 1.5
    "VS_MaxRat": 15000.0,  # N·m/s
    "VS_MaxTq": 47402.91,  # N·m, HSS
    "VS_Rgn2K": 2.332287,  # N·m/(rad/s)^2, HSS
    "VS_Rgn2Sp": 91.21091,  # rad/s, HSS, region 1.5 / 2
    "VS_Rgn3MP": 0.01745329,  # rad, pitch above which region 3 torque applies
    "VS_RtGnSp": 121.6805,  # rad/s, HSS, rated generator speed
    "VS_RtPwr": 5296610.0,  # W, rated mechanical power (5 MW / 94.4 %)
    "VS_SlPc": 10.0,  # %, region 2.5 slip
    "GenEff": 0.944,  # -, ServoDyn generator efficiency (electrical power = torque * speed * GenEff)
}
N_CONTROLLER_STATE = 4

# derived constants of the torque law (as the DLL computes them on its first call)
_SYSP = DISCON["VS_RtGnSp"] / (1.0 + 0.01 * DISCON["VS_SlPc"])
_SLOPE15 = DISCON["VS_Rgn2K"] * DISCON["VS_Rgn2Sp"] ** 2 / (DISCON["VS_Rgn2Sp"] - DISCON["VS_CtInSp"])
_SLOPE25 = (DISCON["VS_RtPwr"] / DISCON["PC_RefSpd"]) / (DISCON["VS_RtGnSp"] - _SYSP)
_TRGNSP = (_SLOPE25 - math.sqrt(_SLOPE25 * (_SLOPE25 - 4.0 * DISCON["VS_Rgn2K"] * _SYSP))) / (2.0 * DISCON["VS_Rgn2K"])
_RGN3_TORQUE = DISCON["VS_RtPwr"] / DISCON["PC_RefSpd"]

# packed parameters for the compiled step
PARAMS = np.array([
    DISCON["CornerFreq"], DISCON["PC_KI"], DISCON["PC_KK"], DISCON["PC_KP"], DISCON["PC_MaxPit"],
    DISCON["PC_MaxRat"], DISCON["PC_MinPit"], DISCON["PC_RefSpd"], DISCON["VS_CtInSp"], DISCON["VS_MaxRat"],
    DISCON["VS_MaxTq"], DISCON["VS_Rgn2K"], DISCON["VS_Rgn2Sp"], DISCON["VS_Rgn3MP"], DISCON["VS_RtGnSp"],
    _SYSP, _SLOPE15, _SLOPE25, _TRGNSP, _RGN3_TORQUE,
])


@numba.njit(cache=True, nogil=True)
def _torque_law(p, gen_speed_f, pitch):
    if gen_speed_f >= p[14] or pitch >= p[13]:
        tq = p[19]
    elif gen_speed_f <= p[8]:
        tq = 0.0
    elif gen_speed_f < p[12]:
        tq = p[16] * (gen_speed_f - p[8])
    elif gen_speed_f < p[18]:
        tq = p[11] * gen_speed_f * gen_speed_f
    else:
        tq = p[17] * (gen_speed_f - p[15])
    return min(tq, p[10])


@numba.njit(cache=True, nogil=True)
def discon_step(p, state, gen_speed, dt):
    """One call of the controller: update ``state`` in place from the generator speed (rad/s, HSS) after
    ``dt`` seconds. Returns nothing; the new pitch is ``state[2]`` (rad), the torque ``state[3]`` (N·m HSS)."""
    alpha = math.exp(-dt * p[0])
    state[0] = (1.0 - alpha) * gen_speed + alpha * state[0]
    gsf = state[0]
    # torque controller (uses the pitch command of the previous call, as the DLL does)
    tq = _torque_law(p, gsf, state[2])
    rate = (tq - state[3]) / dt
    rate = min(max(rate, -p[9]), p[9])
    state[3] = state[3] + rate * dt
    # pitch controller
    gk = 1.0 / (1.0 + state[2] / p[2])
    err = gsf - p[7]
    state[1] = state[1] + err * dt
    state[1] = min(max(state[1], p[6] / (gk * p[1])), p[4] / (gk * p[1]))
    com = gk * p[3] * err + gk * p[1] * state[1]
    com = min(max(com, p[6]), p[4])
    prate = (com - state[2]) / dt
    prate = min(max(prate, -p[5]), p[5])
    state[2] = min(max(state[2] + prate * dt, p[6]), p[4])


def generator_torque_law(gen_speed: float, pitch: float = 0.0) -> float:
    """Steady generator torque (N·m, HSS) the controller commands at a filtered generator speed (rad/s, HSS)
    and pitch (rad), before rate limiting."""
    return float(_torque_law(PARAMS, float(gen_speed), float(pitch)))


@dataclass(frozen=True)
class SteadyState:
    """Steady operating point of rotor + controller at a constant rotor-effective wind (SI).

    Attributes
    ----------
    wind_speed : float
        Rotor-effective wind normal to the rotor (m/s).
    rotor_speed : float
        Rotor speed (rad/s).
    pitch : float
        Blade pitch (rad).
    generator_torque : float
        Generator torque, HSS (N·m).
    region : str
        ``"1"``, ``"1.5"``, ``"2"``, ``"2.5"`` or ``"3"``.
    """

    wind_speed: float
    rotor_speed: float
    pitch: float
    generator_torque: float
    region: str


def _region(gen_speed: float, pitch: float) -> str:
    if gen_speed >= DISCON["VS_RtGnSp"] * (1 - 1e-9) or pitch >= DISCON["VS_Rgn3MP"]:
        return "3"
    if gen_speed <= DISCON["VS_CtInSp"]:
        return "1"
    if gen_speed < DISCON["VS_Rgn2Sp"]:
        return "1.5"
    if gen_speed < _TRGNSP:
        return "2"
    return "2.5"


def steady_state(aero_torque, wind_speed: float, gearbox_ratio: float = 97.0) -> SteadyState:
    """Steady rotor speed and pitch under the controller at a constant wind.

    Parameters
    ----------
    aero_torque : callable
        ``aero_torque(wind, omega, pitch) -> N·m`` (low-speed shaft).
    wind_speed : float
        Rotor-effective wind (m/s), > 0.
    gearbox_ratio : float
        HSS / LSS speed ratio (-).

    Returns
    -------
    SteadyState
        Below rated: the speed where aerodynamic torque equals the torque law at fine pitch. Above rated: the
        pitch at which the aerodynamic torque balances the constant region-3 torque at the reference speed
        (the PI loop's integrator drives the speed error to zero).
    """
    n = gearbox_ratio
    fine = DISCON["PC_MinPit"]

    def net(omega: float) -> float:
        return aero_torque(wind_speed, omega, fine) - n * generator_torque_law(n * omega, fine)

    omega_ref = DISCON["PC_RefSpd"] / n
    if net(omega_ref) > 0.0:  # more power than rated at fine pitch: region 3, pitch to feather
        def excess(beta: float) -> float:
            return aero_torque(wind_speed, omega_ref, beta) - n * _RGN3_TORQUE

        pitch = brentq(excess, fine, np.deg2rad(45.0), xtol=1e-10)
        return SteadyState(float(wind_speed), float(omega_ref), float(pitch), float(_RGN3_TORQUE), "3")
    lo = DISCON["VS_CtInSp"] / n * 0.5
    if net(lo) <= 0.0:
        return SteadyState(float(wind_speed), float(lo), fine, 0.0, "1")
    omega = brentq(net, lo, omega_ref, xtol=1e-12)
    tq = generator_torque_law(n * omega, fine)
    return SteadyState(float(wind_speed), float(omega), fine, float(tq), _region(n * omega, fine))


def initial_controller_state(gen_speed: float, pitch: float, torque: float | None = None) -> np.ndarray:
    """Controller state as the DLL initialises it on its first call: filtered speed = ``gen_speed`` (rad/s, HSS),
    pitch = ``pitch`` (rad), the speed-error integrator set so that the PI command equals that pitch at the
    present speed error (its proportional part included, within the DLL's integrator limits; at the minimum
    pitch the integrator rests on its lower limit, as below rated), last torque =
    ``torque`` (N·m, HSS; default the torque law's value).

    Starting from a measured sample (pitch and torque of a record) the controller then continues as the
    record's did instead of from its steady state.
    """
    gk = 1.0 / (1.0 + pitch / DISCON["PC_KK"])
    err = gen_speed - DISCON["PC_RefSpd"]
    integ = (pitch / gk - DISCON["PC_KP"] * err) / DISCON["PC_KI"] if pitch > DISCON["PC_MinPit"] + 1e-9 else 0.0
    integ = min(max(integ, DISCON["PC_MinPit"] / (gk * DISCON["PC_KI"])), DISCON["PC_MaxPit"] / (gk * DISCON["PC_KI"]))
    tq = generator_torque_law(gen_speed, pitch) if torque is None else float(torque)
    return np.array([gen_speed, integ, pitch, tq])
