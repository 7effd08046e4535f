"""Quasi-steady rotor aerodynamics of the NREL 5 MW and its baseline pitch/torque controller.

The rotor is described by its steady power, thrust and torque coefficient surfaces ``Cp, Ct, Cq(lambda,
beta)`` (NREL's ROSCO table ``Cp_Ct_Cq.NREL5MW.txt``, computed with CCBlade from the NREL 5 MW blade; shipped
in ``surrogates/data`` under Apache-2.0). For a load case the operating point (rotor speed, blade pitch,
thrust, torque) is solved from the table and the controller's design rules, and thrust and torque are
linearised about it:

    dT = T_V (V - v_hub) + T_Omega dOmega + T_beta dbeta
    dQ = Q_V (V - v_hub) + Q_Omega dOmega + Q_beta dbeta

with ``v_hub`` the fore-aft velocity of the hub (the ``aero_damping`` effect). The baseline controller is
the one Jonkman (2010) used for OC3 Hywind: constant generator torque above rated and the NREL 5 MW
gain-scheduled PI collective-pitch loop on rotor speed, with its natural frequency lowered well below the
platform pitch frequency so that the platform pitch mode is not destabilised (Jonkman used 0.2 rad/s; this
surrogate uses 0.1 rad/s, see ``RATED``). The gains follow the
published design rule (Jonkman et al. 2009, section 7.4: dP/dbeta = -25.52 MW/rad at rated, gain-correction
factor 1 / (1 + beta / 6.302336 deg)). Below rated the generator torque follows the optimal-tip-speed law and
the pitch stays at fine pitch.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np
from scipy.interpolate import RegularGridInterpolator
from scipy.optimize import brentq

from .oc3 import RHO_AIR

__all__ = ["RotorTable", "rotor_table", "OperatingPoint", "operating_point", "RATED"]

RATED = {
    "electrical_power": 5.0e6,  # W (Jonkman et al. 2009, Table 1-1)
    "generator_efficiency": 0.944,  # -
    "rotor_speed_rpm": 12.1,  # rpm
    "wind_speed": 11.4,  # m/s
    "min_pitch_rad": 0.0,
    # rad/s. Jonkman (2010, section 7.2) detuned the OC3 Hywind loop from 0.6 to 0.2 rad/s, just below the
    # platform pitch frequency (0.21 rad/s). In this surrogate (no radiation damping) 0.2 rad/s still leaves a
    # coupled pitch-controller mode with negative damping between 11.4 and 13 m/s, so the loop is placed at
    # half the platform pitch frequency, the rule of Larsen & Hanson (2007); every mode is then damped.
    "pitch_controller_frequency": 0.1,
    "pitch_controller_damping": 0.7,  # -
    # gain scheduling of the NREL 5 MW baseline controller (Jonkman et al. 2009, section 7.4): sensitivity of
    # aerodynamic power to pitch at rated, and the pitch angle at which it has doubled
    "dP_dpitch_rated": -25.52e6,  # W/rad
    "pitch_doubling_rad": float(np.deg2rad(6.302336)),
}


@dataclass(frozen=True)
class RotorTable:
    """Steady rotor coefficients on a (tip-speed ratio, pitch) grid.

    Attributes
    ----------
    tsr : ndarray
        Tip-speed ratios (-).
    pitch_rad : ndarray
        Collective blade pitch angles (rad).
    cp, ct, cq : ndarray, shape (len(tsr), len(pitch_rad))
        Power, thrust and torque coefficients (-).
    radius : float
        Rotor radius used to normalise (m).
    """

    tsr: np.ndarray
    pitch_rad: np.ndarray
    cp: np.ndarray
    ct: np.ndarray
    cq: np.ndarray
    radius: float

    def _interp(self, name: str):
        return RegularGridInterpolator((self.tsr, self.pitch_rad), getattr(self, name), method="cubic")

    def coefficients(self, tsr: float, pitch_rad: float) -> tuple[float, float]:
        """Power and thrust coefficients at one point (cubic interpolation)."""
        pt = np.array([[tsr, pitch_rad]])
        return float(_interp_cache(self, "cp")(pt)[0]), float(_interp_cache(self, "ct")(pt)[0])

    def loads(self, wind: float, omega: float, pitch_rad: float) -> tuple[float, float]:
        """Aerodynamic thrust (N) and torque (N·m) for wind (m/s), rotor speed (rad/s) and pitch (rad)."""
        lam = omega * self.radius / max(wind, 1e-6)
        cp, ct = self.coefficients(lam, pitch_rad)
        area = np.pi * self.radius**2
        thrust = 0.5 * RHO_AIR * area * wind**2 * ct
        torque = 0.5 * RHO_AIR * area * wind**3 * cp / max(omega, 1e-6)
        return thrust, torque


_INTERPS: dict[tuple[int, str], RegularGridInterpolator] = {}


def _interp_cache(table: RotorTable, name: str) -> RegularGridInterpolator:
    key = (id(table), name)
    if key not in _INTERPS:
        _INTERPS[key] = table._interp(name)
    return _INTERPS[key]


def _read_block(lines: list[str], start: int, n_rows: int) -> np.ndarray:
    rows = []
    i = start
    while len(rows) < n_rows:
        parts = lines[i].split()
        if parts and not lines[i].lstrip().startswith("#"):
            rows.append([float(p) for p in parts])
        i += 1
    return np.array(rows)


@lru_cache(maxsize=1)
def rotor_table() -> RotorTable:
    """The NREL 5 MW rotor performance table (ROSCO, CCBlade), cached.

    Returns
    -------
    RotorTable
    """
    text = resources.files("surrogates").joinpath("data/Cp_Ct_Cq.NREL5MW.txt").read_text()
    lines = text.splitlines()

    def after(marker: str) -> int:
        return next(i for i, ln in enumerate(lines) if marker in ln) + 1

    pitch = np.array([float(v) for v in lines[after("Pitch angle vector")].split()])
    tsr = np.array([float(v) for v in lines[after("TSR vector")].split()])
    cp = _read_block(lines, after("Power coefficient"), tsr.size)
    ct = _read_block(lines, after("Thrust coefficient"), tsr.size)
    cq = _read_block(lines, after("Torque coefficient"), tsr.size)
    return RotorTable(tsr, np.deg2rad(pitch), cp, ct, cq, radius=63.0)


@dataclass(frozen=True)
class OperatingPoint:
    """Steady operating point and linear sensitivities of the rotor at one mean wind speed (SI units).

    Attributes
    ----------
    wind_speed : float
        Mean rotor-effective wind (m/s).
    rotor_speed : float
        Rotor speed (rad/s).
    pitch : float
        Collective blade pitch (rad).
    thrust, aero_torque : float
        Mean aerodynamic thrust (N) and torque (N·m).
    generator_torque_lss : float
        Generator torque referred to the low-speed shaft (N·m).
    dT_dV, dT_dOmega, dT_dpitch : float
        Thrust sensitivities (N·s/m, N·s/rad, N/rad).
    dQ_dV, dQ_dOmega, dQ_dpitch : float
        Aerodynamic-torque sensitivities (N·s, N·m·s/rad, N·m/rad).
    dQgen_dOmega : float
        Generator-torque law slope about the operating point, LSS (N·m·s/rad); 0 above rated (constant torque).
    kp, ki : float
        PI gains of the pitch controller on rotor-speed error (s, -); 0 below rated.
    above_rated : bool
    """

    wind_speed: float
    rotor_speed: float
    pitch: float
    thrust: float
    aero_torque: float
    generator_torque_lss: float
    dT_dV: float
    dT_dOmega: float
    dT_dpitch: float
    dQ_dV: float
    dQ_dOmega: float
    dQ_dpitch: float
    dQgen_dOmega: float
    kp: float
    ki: float
    above_rated: bool

    @property
    def power(self) -> float:
        """Aerodynamic power (W)."""
        return self.aero_torque * self.rotor_speed


@lru_cache(maxsize=128)
def operating_point(
    wind_speed: float, rotor_rpm: float | None = None, drivetrain_inertia: float = 4.35e7
) -> OperatingPoint:
    """Steady operating point of the NREL 5 MW with its baseline controller at a mean wind speed.

    Parameters
    ----------
    wind_speed : float
        Mean (rotor-effective) wind speed (m/s), > 0.
    rotor_rpm : float, optional
        Rotor speed (rpm). Default: the controller's steady value (rated 12.1 rpm above rated wind, the
        optimal tip-speed ratio below it).
    drivetrain_inertia : float
        Rotor + generator inertia about the low-speed shaft (kg·m²), for the pitch-controller gains.

    Returns
    -------
    OperatingPoint
    """
    if not np.isfinite(wind_speed) or wind_speed <= 0:
        raise ValueError(f"wind_speed must be a positive finite number (m/s), got {wind_speed!r}")
    table = rotor_table()
    rated_aero_power = RATED["electrical_power"] / RATED["generator_efficiency"]
    omega_rated = RATED["rotor_speed_rpm"] * np.pi / 30.0
    fine = RATED["min_pitch_rad"]
    # optimal tip-speed ratio at fine pitch
    lam_grid = np.linspace(table.tsr[0], table.tsr[-1], 400)
    cp_fine = [table.coefficients(lam, fine)[0] for lam in lam_grid]
    lam_opt = lam_grid[int(np.argmax(cp_fine))]
    if rotor_rpm is None:
        omega = min(omega_rated, lam_opt * wind_speed / table.radius)
    else:
        if not np.isfinite(rotor_rpm) or rotor_rpm <= 0:
            raise ValueError(f"rotor_rpm must be a positive finite number (rpm), got {rotor_rpm!r}")
        omega = rotor_rpm * np.pi / 30.0
    power_fine = table.loads(wind_speed, omega, fine)[1] * omega
    above = power_fine > rated_aero_power and omega >= 0.999 * omega_rated
    if above:
        def excess(beta: float) -> float:
            return table.loads(wind_speed, omega, beta)[1] * omega - rated_aero_power

        pitch = brentq(excess, fine, np.deg2rad(25.0))
    else:
        pitch = fine
    thrust, torque = table.loads(wind_speed, omega, pitch)

    def d(fun_idx: int, dv: float, dw: float, db: float) -> float:
        hi = table.loads(wind_speed + dv, omega + dw, pitch + db)[fun_idx]
        lo = table.loads(wind_speed - dv, omega - dw, pitch - db)[fun_idx]
        return (hi - lo) / (2.0 * (dv + dw + db))

    dv, dw, db = 0.05, 0.005, np.deg2rad(0.05)
    sens = {
        "dT_dV": d(0, dv, 0, 0), "dT_dOmega": d(0, 0, dw, 0), "dT_dpitch": d(0, 0, 0, db),
        "dQ_dV": d(1, dv, 0, 0), "dQ_dOmega": d(1, 0, dw, 0), "dQ_dpitch": d(1, 0, 0, db),
    }
    if above:
        # constant generator torque (OC3 Hywind); gain-scheduled PI pitch loop of the NREL 5 MW baseline
        # controller: gains placed for (omega_n, zeta) with the *published* dP/dbeta at rated, scheduled by
        # GK = 1 / (1 + beta / beta_K) (Jonkman et al. 2009, eqs. 7-? "gain-correction factor").
        wn, zeta = RATED["pitch_controller_frequency"], RATED["pitch_controller_damping"]
        dp_db0 = RATED["dP_dpitch_rated"]
        gk = 1.0 / (1.0 + pitch / RATED["pitch_doubling_rad"])
        kp = 2.0 * drivetrain_inertia * omega_rated * zeta * wn / (-dp_db0) * gk
        ki = drivetrain_inertia * omega_rated * wn**2 / (-dp_db0) * gk
        dqgen = 0.0
    else:
        kp = ki = 0.0
        # optimal-mode torque law Q = k omega^2 (referred to the LSS) balances the aerodynamic torque
        dqgen = 2.0 * torque / omega
    return OperatingPoint(
        wind_speed=float(wind_speed), rotor_speed=float(omega), pitch=float(pitch), thrust=float(thrust),
        aero_torque=float(torque), generator_torque_lss=float(torque), kp=float(kp), ki=float(ki),
        dQgen_dOmega=float(dqgen), above_rated=bool(above), **{k: float(v) for k, v in sens.items()},
    )
