"""Quasi-steady rotor aerodynamics of the NREL 5 MW and its operating point under the OC3 Hywind controller.

The rotor is described by its steady power, thrust and torque coefficient surfaces ``Cp, Ct, Cq(lambda,
beta)``: by default the OC3 Hywind reference deck's rotor as OpenFAST's AeroDyn computes it
(``Cp_Ct_Cq.OC3_AeroDyn.txt``, made by ``tools/aerodyn_rotor_table.py`` with AeroDyn's standalone driver on the
deck's own AeroDyn input: its unsteady airfoil model ``UA_Mod = 3`` included, which lowers the mean lift of the
DU airfoils even in steady wind -- the airfoil files' lift slope for UA lies below their static polars -- by
3.6-5 % of thrust and torque near rated; steady, uniform inflow aligned with the shaft, rigid blades). The
surrogate applies the shaft tilt, the tower top's pitch and the disc-mean wind of the sheared, turbulent field
itself. ``rotor_table("ccblade")`` is NREL's ROSCO table (``Cp_Ct_Cq.NREL5MW.txt``, CCBlade, Apache-2.0), which
already contains a 5 deg tilt and a 0.2 shear exponent and no unsteady aerodynamics: against OpenFAST it made the
rotor 4-5 % too strong at 12 m/s (steady wind: blade pitch 2.06 deg against OpenFAST's 1.32; 1.69 now). The
simulation evaluates them at every step with the wind relative to the moving hub (the ``rotor_nonlinear`` effect,
with the controller of :mod:`surrogates.controller`). For
the linear model (``linearize()``, modal analysis, ``rotor_nonlinear=0``) thrust and torque are linearised
about the steady operating point that the same controller reaches at the mean wind:

    dT = T_V (V - v_hub) + T_Omega dOmega + T_beta dbeta
    dQ = Q_V (V - v_hub) + Q_Omega dOmega + Q_beta dbeta

with ``v_hub`` the hub velocity along the shaft (the ``aero_damping`` effect), and the controller is linearised
too: the generator-torque law's slope about the operating point (zero in region 3: constant torque) and the
gain-scheduled PI pitch loop of ``DISCON_OC3Hywind`` on rotor speed (``GK N PC_KP``, ``GK N PC_KI``; the
generator-speed filter, the saturations and the rate limits are what the linearisation leaves out).

Beside the disc's coefficients, two blade-element tables of the deck's blade (quasi-steady BEM, its polars):
:func:`blade_inplane_sensitivity`, each blade's in-plane force against the wind along it (the rotor's side force
under turbulence), and :func:`blade_skew_table`, each blade's thrust, moment and in-plane force against its
tangential airspeed (the advancing and retreating blades of a rotor inclined or yawed in the wind: the
``rotor_skew`` effect, with :func:`skew_gains` at an operating point). And :func:`blade_deflection_table`: the
rotor's coefficients with its blades bent downwind by their flap deflection (the ``blade_deflection`` effect):
OpenFAST's flexible blades make the same deck's rotor 3-4 % weaker in torque at rated than its rigid blades do.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numba
import numpy as np
from scipy.optimize import brentq

from .oc3 import RHO_AIR
from .validation import check_number

__all__ = ["ROTOR_TABLES", "RotorTable", "rotor_table", "OperatingPoint", "operating_point", "RATED",
           "blade_inplane_sensitivity", "blade_inplane_gain", "inplane_ring_weights", "BladeSkewTable",
           "blade_skew_table", "skew_gains", "inclined_rotor_moment", "inclined_rotor_moment_by_pitch",
           "inplane_wind_loads",
           "BladeDeflectionTable", "blade_deflection_table"]

RATED = {
    "electrical_power": 5.0e6,  # W (Jonkman et al. 2009, Table 1-1)
    "generator_efficiency": 0.944,  # -
    "rotor_speed_rpm": 12.1,  # rpm
    "wind_speed": 11.4,  # m/s
    "min_pitch_rad": 0.0,
    # gain scheduling of the NREL 5 MW baseline controller (Jonkman et al. 2009, section 7.4): sensitivity of
    # aerodynamic power to pitch at rated, and the pitch angle at which it has doubled (DISCON's PC_KK)
    "dP_dpitch_rated": -25.52e6,  # W/rad
    "pitch_doubling_rad": 0.1099965,
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

    def coefficients(self, tsr: float, pitch_rad: float) -> tuple[float, float]:
        """Power and thrust coefficients at one point (bilinear, clamped to the table's edges)."""
        ct, cq = rotor_coefficients(self.tsr, self.pitch_rad, self.ct, self.cq, float(tsr), float(pitch_rad))
        return cq * float(tsr), ct

    def loads(self, wind: float, omega: float, pitch_rad: float) -> tuple[float, float]:
        """Aerodynamic thrust (N) and torque (N·m) for wind (m/s), rotor speed (rad/s) and pitch (rad)."""
        v = max(wind, 1e-6)
        lam = omega * self.radius / v
        ct, cq = rotor_coefficients(self.tsr, self.pitch_rad, self.ct, self.cq, lam, float(pitch_rad))
        q = 0.5 * RHO_AIR * np.pi * self.radius**2 * v * v
        return q * ct, q * self.radius * cq


@numba.njit(cache=True, nogil=True)
def rotor_coefficients(tsr, pitch, ct, cq, lam, beta):
    """Thrust and torque coefficients ``(Ct, Cq)`` at tip-speed ratio ``lam`` and pitch ``beta`` (rad) by
    bilinear interpolation on the table's uniform grid, clamped at its edges. Used by the simulation kernel
    and by the operating-point solver alike, so both see the same rotor."""
    nl, nb = tsr.shape[0], pitch.shape[0]
    fl = (lam - tsr[0]) / (tsr[1] - tsr[0])
    fb = (beta - pitch[0]) / (pitch[1] - pitch[0])
    fl = min(max(fl, 0.0), nl - 1.000001)
    fb = min(max(fb, 0.0), nb - 1.000001)
    i = int(fl)
    j = int(fb)
    wl = fl - i
    wb = fb - j
    c00 = (1 - wl) * (1 - wb)
    c10 = wl * (1 - wb)
    c01 = (1 - wl) * wb
    c11 = wl * wb
    t = c00 * ct[i, j] + c10 * ct[i + 1, j] + c01 * ct[i, j + 1] + c11 * ct[i + 1, j + 1]
    q = c00 * cq[i, j] + c10 * cq[i + 1, j] + c01 * cq[i, j + 1] + c11 * cq[i + 1, j + 1]
    return t, q


def _read_block(lines: list[str], start: int, n_rows: int) -> np.ndarray:
    rows = []
    i = start
    while len(rows) < n_rows:
        parts = lines[i].split()
        if parts and not lines[i].lstrip().startswith("#"):
            rows.append([float(p) for p in parts])
        i += 1
    return np.array(rows)


ROTOR_TABLES = {"aerodyn": "data/Cp_Ct_Cq.OC3_AeroDyn.txt", "ccblade": "data/Cp_Ct_Cq.NREL5MW.txt"}
"""The rotor coefficient tables shipped (see the module docstring): the default, and ROSCO's for comparison."""


@lru_cache(maxsize=2)
def rotor_table(source: str = "aerodyn") -> RotorTable:
    """The NREL 5 MW rotor performance table, cached.

    Parameters
    ----------
    source : {"aerodyn", "ccblade"}
        ``"aerodyn"`` (default): the OC3 deck's rotor by AeroDyn (unsteady airfoil model on; aligned, uniform,
        steady inflow); ``"ccblade"``: NREL's ROSCO table (CCBlade; 5 deg tilt and 0.2 shear inside).

    Returns
    -------
    RotorTable
    """
    if source not in ROTOR_TABLES:
        raise ValueError(f"source must be one of {sorted(ROTOR_TABLES)}, got {source!r}")
    text = resources.files("surrogates").joinpath(ROTOR_TABLES[source]).read_text()
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
    from .controller import DISCON, generator_torque_law, steady_state

    table = rotor_table()
    n_gear = 97.0
    if rotor_rpm is None:
        ss = steady_state(lambda v, w, b: table.loads(v, w, b)[1], wind_speed, n_gear)
        omega, pitch = ss.rotor_speed, ss.pitch
        above = ss.region == "3"
    else:
        if not np.isfinite(rotor_rpm) or rotor_rpm <= 0:
            raise ValueError(f"rotor_rpm must be a positive finite number (rpm), got {rotor_rpm!r}")
        omega = rotor_rpm * np.pi / 30.0
        # the pitch that balances the torque law at this speed (fine pitch if the rotor cannot reach it)
        q_gen = n_gear * generator_torque_law(n_gear * omega, 0.0)
        above = bool(n_gear * omega >= DISCON["VS_RtGnSp"] * (1 - 1e-6)
                     and table.loads(wind_speed, omega, 0.0)[1] > q_gen)
        if above:
            q_gen = n_gear * generator_torque_law(n_gear * omega, 1.0)
            pitch = brentq(lambda b: table.loads(wind_speed, omega, b)[1] - q_gen, 0.0, np.deg2rad(45.0))
        else:
            pitch = 0.0
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
        # DISCON_OC3Hywind: constant generator torque, PI pitch on the HSS speed error with GK = 1/(1+beta/KK)
        gk = 1.0 / (1.0 + pitch / DISCON["PC_KK"])
        kp = gk * DISCON["PC_KP"] * n_gear
        ki = gk * DISCON["PC_KI"] * n_gear
        dqgen = 0.0
    else:
        kp = ki = 0.0
        # slope of the torque law (regions 1.5, 2, 2.5), referred to the LSS: N^2 dQ_hss/dw_hss
        w_g, h = n_gear * omega, 1e-3
        dqgen = n_gear**2 * (generator_torque_law(w_g + h) - generator_torque_law(w_g - h)) / (2 * h)
    del drivetrain_inertia  # the gains are DISCON's, not placed for an inertia
    return OperatingPoint(
        wind_speed=float(wind_speed), rotor_speed=float(omega), pitch=float(pitch), thrust=float(thrust),
        aero_torque=float(torque), generator_torque_lss=float(torque), kp=float(kp), ki=float(ki),
        dQgen_dOmega=float(dqgen), above_rated=bool(above), **{k: float(v) for k, v in sens.items()},
    )


@lru_cache(maxsize=1)
def _inplane_table() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    import json

    data = json.loads(resources.files("surrogates").joinpath("data/blade_inplane_sensitivity.json").read_text())
    width = np.asarray(data["width"], dtype=float)
    per_node = np.asarray(data["dFt_dU"], dtype=float) * width[None, :]
    return np.asarray(data["radius"], dtype=float), np.asarray(data["wind_speed"], dtype=float), per_node


def blade_inplane_sensitivity(wind_speed: float) -> tuple[np.ndarray, np.ndarray]:
    """How one blade's in-plane aerodynamic force answers the streamwise wind along its span.

    At the steady operating point of ``wind_speed`` the tangential force (in the rotor plane, along the
    rotation) of each AeroDyn node of the NREL 5 MW blade changes by ``s_i`` per m/s of axial wind at that
    node: a quasi-steady blade-element momentum model of the OC3 deck's AeroDyn blade and polars
    (``tools/blade_inplane_sensitivity.py``, tabulated at 3-25 m/s in ``surrogates/data``; linear in the
    wind speed between, held outside). The sum, one blade's in-plane force per m/s of uniform wind, is 6.6,
    9.2 and 11.9 kN/(m/s) at 8, 12 and 18 m/s, weighted towards mid-span (unlike the torque, whose lever puts
    its weight outboard). A turbulent field that differs from blade to blade leaves these forces unbalanced:
    the rotor's in-plane side and vertical force, the side-to-side excitation of the tower.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s), > 0.

    Returns
    -------
    radius : ndarray (n_nodes,)
        Node radii from the rotor centre (m).
    force_per_wind : ndarray (n_nodes,)
        Change of each node's in-plane force (N per m/s of wind at the node), span width included.

    Examples
    --------
    >>> r, s = blade_inplane_sensitivity(12.0)
    >>> round(float(s.sum()) / 1e3, 1), round(float(np.sum(s * r) / s.sum()), 1)  # kN/(m/s), mean radius (m)
    (9.2, 35.7)
    """
    if not np.isfinite(wind_speed) or wind_speed <= 0:
        raise ValueError(f"wind_speed must be a positive finite number (m/s), got {wind_speed!r}")
    radius, speeds, per_node = _inplane_table()
    v = float(np.clip(wind_speed, speeds[0], speeds[-1]))
    j = int(np.clip(np.searchsorted(speeds, v) - 1, 0, speeds.size - 2))
    frac = (v - speeds[j]) / (speeds[j + 1] - speeds[j])
    return radius.copy(), (1.0 - frac) * per_node[j] + frac * per_node[j + 1]


def blade_inplane_gain(wind_speed: float) -> float:
    """One blade's in-plane force per m/s of uniform axial wind (N·s/m) at the operating point of `wind_speed`.

    The sum over the span of :func:`blade_inplane_sensitivity`, with the wind speed taken to 0.01 m/s (as
    :func:`inplane_ring_weights` does), so the linear model, the simulation and the replay use one number.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s), > 0.

    Returns
    -------
    float
        N per m/s.

    Examples
    --------
    >>> round(blade_inplane_gain(12.0) / 1e3, 1)
    9.2
    """
    return float(blade_inplane_sensitivity(round(float(wind_speed), 2))[1].sum())


def inplane_ring_weights(ring_radii: np.ndarray, wind_speed: float) -> tuple[np.ndarray, float]:
    """Weights of a polar field's rings for one blade's in-plane force, and its gain.

    The nodes' sensitivities of :func:`blade_inplane_sensitivity` are shared between the two rings around
    each node in proportion to its distance from them (linear interpolation of the wind between rings, as the
    field is read); nodes beyond the outermost ring load it. Then a blade's in-plane force changes by
    ``gain * sum_k weights_k (u_k - U)`` for ring winds ``u_k`` along it.

    Parameters
    ----------
    ring_radii : array_like (n_rings,)
        Ring radii (m), increasing, >= 0.
    wind_speed : float
        Mean wind speed (m/s), > 0; taken to 0.01 m/s.

    Returns
    -------
    weights : ndarray (n_rings,)
        Non-negative, summing to 1.
    gain : float
        One blade's in-plane force per m/s of uniform wind change (N·s/m).

    Examples
    --------
    >>> w, g = inplane_ring_weights([0.0, 15.75, 31.5, 47.25, 63.0], 12.0)
    >>> round(float(w.sum()), 12), int(np.argmax(w)), round(g / 1e3, 1)
    (1.0, 2, 9.2)
    """
    rings = np.asarray(ring_radii, dtype=float)
    wind_speed = round(float(wind_speed), 2)  # to 0.01 m/s: a record's mean computed two ways gives one answer
    if rings.ndim != 1 or rings.size < 1 or not np.all(np.isfinite(rings)) or np.any(np.diff(rings) <= 0):
        raise ValueError(f"ring_radii must be finite and increasing (m), got {ring_radii!r}")
    radius, sens = blade_inplane_sensitivity(wind_speed)
    weights = np.zeros(rings.size)
    for r, s in zip(radius, sens, strict=True):
        if rings.size == 1 or r >= rings[-1]:
            weights[-1] += s
        elif r <= rings[0]:
            weights[0] += s
        else:
            k = int(np.searchsorted(rings, r) - 1)
            frac = (r - rings[k]) / (rings[k + 1] - rings[k])
            weights[k] += (1.0 - frac) * s
            weights[k + 1] += frac * s
    gain = float(sens.sum())
    return weights / gain, gain


@dataclass(frozen=True)
class BladeSkewTable:
    """How one blade's loads answer its tangential airspeed, on the rotor table's (tip-speed ratio, pitch) grid.

    A wind component in the rotor plane adds ``w_y cos(psi) + w_z sin(psi)`` to the airspeed of the blade at
    azimuth ``psi`` (from the top, turning towards -y; ``w_y`` lateral, ``w_z`` up the disc): the advancing and
    retreating blades. Per m/s of that airspeed, at axial wind ``V`` (m/s), one blade's thrust changes by
    ``q k_thrust``, its moment about the rotor centre by ``q R k_moment`` and its in-plane force (along the rotation)
    by ``q k_inplane``, ``q = 0.5 rho pi R^2 V`` (N per m/s). Quasi-steady blade-element momentum model of the OC3
    deck's AeroDyn blade and polars (``tools/blade_skew_table.py``).

    Attributes
    ----------
    tsr : ndarray (n_tsr,)
        Tip-speed ratios (-), the grid of :func:`rotor_table`.
    pitch_rad : ndarray (n_pitch,)
        Collective pitch angles (rad).
    k_thrust, k_moment, k_inplane : ndarray (n_tsr, n_pitch)
        Non-dimensional sensitivities (-).
    radius : float
        Rotor radius R (m).
    """

    tsr: np.ndarray
    pitch_rad: np.ndarray
    k_thrust: np.ndarray
    k_moment: np.ndarray
    k_inplane: np.ndarray
    radius: float

    def sensitivities(self, wind: float, omega: float, pitch_rad: float) -> tuple[float, float, float]:
        """One blade's thrust (N), moment about the rotor centre (N m) and in-plane force (N) per m/s of tangential
        airspeed, at axial wind ``wind`` (m/s, > 0), rotor speed ``omega`` (rad/s) and pitch (rad); bilinear in the
        table, clamped at its edges.

        Examples
        --------
        >>> t = blade_skew_table()
        >>> _, m8, _ = t.sensitivities(8.0, 9.04 * np.pi / 30, 0.0)
        >>> _, m18, _ = t.sensitivities(18.0, 12.1 * np.pi / 30, np.deg2rad(14.6))
        >>> bool(m8 > 0 > m18)  # more airspeed: more thrust at fine pitch, less at high pitch
        True
        """
        v = float(wind)
        if not np.isfinite(v) or v <= 0:
            raise ValueError(f"wind must be a positive finite number (m/s), got {wind!r}")
        lam = float(omega) * self.radius / v
        k_t, k_m = rotor_coefficients(self.tsr, self.pitch_rad, self.k_thrust, self.k_moment, lam, float(pitch_rad))
        k_f, _ = rotor_coefficients(self.tsr, self.pitch_rad, self.k_inplane, self.k_inplane, lam, float(pitch_rad))
        q = 0.5 * RHO_AIR * np.pi * self.radius**2 * v
        return q * k_t, q * self.radius * k_m, q * k_f


@lru_cache(maxsize=1)
def blade_skew_table() -> BladeSkewTable:
    """The blade's tangential-airspeed sensitivities (:class:`BladeSkewTable`), read from ``surrogates/data``."""
    import json

    data = json.loads(resources.files("surrogates").joinpath("data/blade_skew_table.json").read_text())
    rt = rotor_table()
    tsr, pitch = np.asarray(data["tsr"], dtype=float), np.asarray(data["pitch"], dtype=float)
    if not (np.allclose(tsr, rt.tsr) and np.allclose(pitch, rt.pitch_rad)):
        raise RuntimeError("surrogates/data/blade_skew_table.json is not on the rotor table's grid: rerun "
                           "tools/blade_skew_table.py")
    tables = [np.ascontiguousarray(data[k], dtype=float) for k in ("k_thrust", "k_moment", "k_inplane")]
    for t in tables:
        t.setflags(write=False)
    return BladeSkewTable(rt.tsr, rt.pitch_rad, *tables, radius=float(data["radius"]))


def skew_gains(wind_speed: float, inclination_rad: float) -> tuple[float, float, float]:
    """One blade's thrust (N), moment about the rotor centre (N m) and in-plane force (N) per m/s of tangential
    airspeed at the steady operating point of a rotor inclined by ``inclination_rad`` (nose up: the shaft's tilt
    plus the platform's pitch) in the mean wind ``wind_speed``: :class:`BladeSkewTable` at the controller's steady
    rotor speed and pitch for the axial wind ``wind_speed cos(inclination)``.

    The advancing-blade loads are linearised about that point, as the rotor's other asymmetric loads are; the
    table's pitch dependence is steep near rated (the moment gain halves between 1 and 4 deg of pitch at 12 m/s),
    and letting the gains follow each step's pitch degraded the agreement with OpenFAST's steady-wind run (its
    wave-band yaw R^2 0.78 with constant gains, -0.19 with the step's own).

    Examples
    --------
    >>> [round(skew_gains(v, np.deg2rad(9.0))[1] / 1e3) for v in (8.0, 18.0)]  # kN m per m/s
    [83, -163]
    """
    v = float(wind_speed) * float(np.cos(inclination_rad))
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"wind_speed must be a positive finite number (m/s), got {wind_speed!r}")
    op = operating_point(v)
    return blade_skew_table().sensitivities(v, op.rotor_speed, op.pitch)


@lru_cache(maxsize=1)
def _inclined_rotor_json() -> dict:
    import json

    return json.loads(resources.files("surrogates").joinpath("data/inclined_rotor_inplane.json").read_text())


@lru_cache(maxsize=1)
def _inclined_rotor_data() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    data = _inclined_rotor_json()
    return tuple(np.asarray(data[k], dtype=float) for k in ("wind_speed", "eps_straight", "eps_per_m"))


def inclined_rotor_moment(wind_speed: float) -> tuple[float, float]:
    """One blade's share of the inclined rotor's moment per m/s of in-plane wind, from AeroDyn (N m per m/s).

    The rotor inclined under the wind meets its component ``W = V sin(inclination)`` up the disc: the blade going up
    on one side and the one going down on the other see different airspeeds, and AeroDyn's skewed wake and the
    blades' cone shift the induction across the disc. The moment about the rotor plane's vertical axis (a yaw
    moment; a lateral ``W``, under a yaw misalignment, gives the tilt moment) changes by ``1.5 k W`` with
    ``k = k_straight + k_per_m d`` for blades bent ``d`` m at the tip: the driver's change between the shaft inclined
    5 and 10 deg at the operating point (``tools/inclined_rotor_inplane_table.py``, hub axes, in the table's
    ``yaw_moment_change_Nm``), per ``1.5 dW``. The quasi-steady blade-element skew table
    (:func:`skew_gains`) gives 1.4-1.8x this below rated, where the skewed wake's induction carries most of the
    answer, and the same at 16-18 m/s; OpenFAST's held-platform runs follow AeroDyn (``YawBrMzp`` -233 kN m at 5 deg
    in uniform 12 m/s wind with rigid blades: +130 kN m of the rotor's own less the 5 deg shaft's torque
    projection).

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s), > 0; linear between the tabulated 4-25 m/s, held outside.

    Returns
    -------
    (float, float)
        ``k_straight`` (N m per m/s) and ``k_per_m`` (N m per m/s per m of tip deflection).

    Examples
    --------
    >>> k0, k1 = inclined_rotor_moment(12.0)
    >>> round(1.5 * k0 / 1e3), round(1.5 * (k0 + 5.0 * k1) / 1e3)  # kN m per m/s: straight, bent 5 m
    (87, 62)
    """
    wind_speed = check_number("wind_speed", wind_speed, positive=True)
    data = _inclined_rotor_json()
    v = np.asarray(data["wind_speed"], dtype=float)
    t0, t1 = (np.deg2rad(float(a)) for a in data["inclinations_deg"])
    dw = 1.5 * v * (np.sin(t1) - np.sin(t0))
    straight = np.asarray(data["yaw_moment_change_Nm"]["straight"], dtype=float) / dw
    bent = np.asarray(data["yaw_moment_change_Nm"]["bent"], dtype=float) / dw
    per_m = (bent - straight) / float(data["tip_deflection_m"])
    return float(np.interp(wind_speed, v, straight)), float(np.interp(wind_speed, v, per_m))


def inclined_rotor_moment_by_pitch() -> tuple[np.ndarray, np.ndarray]:
    """The straight-bladed inclined rotor's moment per m/s of in-plane wind along the pitch-regulated operating
    points, indexed by their blade pitch (rad; N m per m/s, one blade's share as :func:`inclined_rotor_moment`).

    Above rated the blade pitch is what sets how the blades meet the in-plane wind: AeroDyn's moment per m/s of it
    falls from +88 kN m per m/s (one blade) at fine pitch to -213 at 17 deg (``tools/inclined_rotor_inplane_table.py``).
    A rotor whose pitch moves (the controller answering the platform's slow surge and pitch in steady wind, or the
    turbulence) moves along this curve: the simulation's nonlinear rotor reads it at the blade's instantaneous
    pitch, relative to the equilibrium's, and the linear model takes its slope there. The nodes are the table's
    operating points from the last fine-pitch one (11 m/s) up; the curve is linear in pitch between them and held
    beyond them. In OpenFAST's steady 12 m/s run with the platform's yaw held the slow (< 0.05 Hz) yaw-bearing
    moment follows the blade pitch at -36 kN m/deg (correlation -0.88); this curve's slope there, times 1.5 and the
    run's in-plane wind (2.1 m/s), is -30 kN m/deg.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Blade pitch of the nodes (rad, increasing from 0) and ``k_straight`` there (N m per m/s).

    Examples
    --------
    >>> beta, k = inclined_rotor_moment_by_pitch()
    >>> float(beta[0]), round(1.5 * float(np.interp(np.deg2rad(3.12), beta, k)) / 1e3)  # at 12 m/s's pitch
    (0.0, 87)
    """
    data = _inclined_rotor_json()
    v = np.asarray(data["wind_speed"], dtype=float)
    pitch = np.deg2rad(np.asarray(data["pitch_deg"], dtype=float))
    t0, t1 = (np.deg2rad(float(a)) for a in data["inclinations_deg"])
    straight = np.asarray(data["yaw_moment_change_Nm"]["straight"], dtype=float) / (1.5 * v * (np.sin(t1) - np.sin(t0)))
    first = int(np.flatnonzero(pitch <= 0.0)[-1])
    return pitch[first:].copy(), straight[first:].copy()


def inclined_rotor_inplane(wind_speed: float) -> tuple[float, float]:
    """How the inclined (or yawed) rotor's blades meet its in-plane wind in their in-plane force (-, 1/m).

    The wind's component in the rotor plane ``W`` (up the disc ``V sin(inclination)`` when the shaft is inclined
    nose up by its tilt and the platform's pitch; sideways when the rotor is yawed; less the hub's own in-plane
    velocity) is met differently by a blade on the side it blows towards and one on the other side: a blade coned
    downwind (its flap deflection, less the deck's 2.5 deg of upwind precone) takes part of ``W`` as axial wind,
    and AeroDyn's skewed-wake model (Pitt and Peters) raises the induction on the side ``W`` blows towards. Each
    blade's in-plane force then sees its axial wind change by ``-eps (W . e_r)`` (``e_r`` its radial direction),
    ``eps = eps_straight + eps_per_m * d`` for blades bent ``d`` m at the tip, and three blades give the in-plane
    force ``1.5 G eps W`` (``G`` one blade's gain of :func:`blade_inplane_sensitivity`): a side force that takes
    back part of the shear's.

    Measured with OpenFAST's AeroDyn driver on the deck's rotor at the steady operating points, inclined 5 and
    10 deg, straight and bent 5 m (``tools/inclined_rotor_inplane_table.py``, table in ``surrogates/data``);
    linear in the wind speed between the tabulated 4-25 m/s, held outside. Inclined 10 deg at 12 m/s, 5 m of tip
    deflection move the side force by +2.7 kN, a fifth of the shear's (-14 kN, AeroDyn); OpenFAST's own
    flexible rotor in the steady-wind run's conditions puts -10.1 kN on its yaw bearing where its rigid one puts
    -19.0 kN.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s), > 0.

    Returns
    -------
    (float, float)
        ``eps_straight`` (-) and ``eps_per_m`` (1/m).

    Examples
    --------
    >>> e0, e1 = inclined_rotor_inplane(12.0)
    >>> bool(abs(e0) < 0.05 and 0.01 < e1 < 0.03)  # the bent blades carry most of it near rated
    True
    """
    wind_speed = check_number("wind_speed", wind_speed, positive=True)
    v, e0, e1 = _inclined_rotor_data()
    return float(np.interp(wind_speed, v, e0)), float(np.interp(wind_speed, v, e1))


@lru_cache(maxsize=1)
def _inplane_wind_data() -> tuple[np.ndarray, ...]:
    data = _inclined_rotor_json()
    if "lateral" not in data:
        raise RuntimeError("surrogates/data/inclined_rotor_inplane.json has no 'lateral' block: rerun "
                           "tools/inclined_rotor_inplane_table.py")
    lat = data["lateral"]
    return tuple(np.asarray(x, dtype=float) for x in (
        data["wind_speed"], lat["side_force_per_w"]["straight"], lat["side_force_per_w"]["per_m"],
        lat["cross_moment_per_w"]["straight"], lat["cross_moment_per_w"]["per_m"]))


def inplane_wind_loads(wind_speed: float) -> tuple[float, float, float, float]:
    """The rotor's force along its in-plane wind and its moment across it, one blade's share per m/s (AeroDyn).

    The wind's component in the rotor plane ``w`` (up the disc from the shaft's inclination, sideways from a yaw
    misalignment, less the hub's own in-plane velocity, which is how a rolling or swaying platform meets it) pushes
    the rotor along itself, ``F = 1.5 f w``, and turns it about the in-plane axis across itself,
    ``M = 1.5 k e_x x w`` (``e_x`` down the shaft): a lateral ``w`` yaws the rotor, one up the disc tilts it. The
    moment is AeroDyn's skewed wake (Pitt and Peters: more induction on the side ``w`` blows towards) and the
    blades' cone (a blade coned downwind takes part of ``w`` as axial wind, less on the side it blows towards);
    the force grows with the cone as well. Both are linear in the tip deflection ``d`` of the blades bent downwind:
    ``f = f_straight + f_per_m d``, ``k = k_straight + k_per_m d``. These come beside the advancing blades' moment
    about the axis along ``w`` (:func:`inclined_rotor_moment`) and the in-plane force across it
    (:func:`inclined_rotor_inplane`). The simulation and the linear model apply the force in both directions and
    the moment as a yaw moment only: the inclined rotor's tilt moment is held by the shear's calibrated tilt gain
    (:data:`surrogates.model.ROTOR_ASYMMETRY`, which gives OpenFAST's mean tower-base moment; counted twice it
    lowered the steady 12 m/s run's mean platform pitch by 0.026 deg, away from OpenFAST's).

    Measured with OpenFAST's AeroDyn driver on the deck's rotor at the steady operating points, inclined 10 deg and
    yawed +/-3 deg in the wind, straight and bent 5 m (``tools/inclined_rotor_inplane_table.py``, the table's
    ``lateral`` block); linear in the wind speed between the tabulated 4-25 m/s, held outside. The moment across the
    wind up the disc, from the same tool's inclined runs, is within 10 % of the lateral one's at 4-25 m/s (the rotor
    is axisymmetric to that extent). At 12 m/s, one blade: 860 N and 50 kN m per m/s straight, +112 N and +24.7 kN m
    per m of bend. A rotor translating sideways in the driver (prescribed sway at 0.034 Hz, inclined 9.8 deg,
    1.28 deg of pitch) meets -1.4 kN and -123 kN m per m/s of its velocity straight, -2.4 kN and -323 kN m bent 5 m:
    the bend doubles the force and nearly triples the moment. Without them the operating platform's roll was damped
    too little and yawed too much with the roll's rate (``tests/test_roll_decay.py``): OpenFAST's rigid-bladed rotor
    (by hand) damps the roll as the surrogate without them did.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s), > 0.

    Returns
    -------
    (float, float, float, float)
        ``f_straight`` (N per m/s), ``f_per_m`` (N per m/s per m), ``k_straight`` (N m per m/s) and ``k_per_m``
        (N m per m/s per m).

    Examples
    --------
    >>> f0, f1, k0, k1 = inplane_wind_loads(12.0)
    >>> bool(f0 > 0 and f1 > 0 and k0 > 0 and k1 > 0)  # along the wind; the bent blades add to both
    True
    """
    wind_speed = check_number("wind_speed", wind_speed, positive=True)
    v, f0, f1, k0, k1 = _inplane_wind_data()
    return tuple(float(np.interp(wind_speed, v, y)) for y in (f0, f1, k0, k1))


@dataclass(frozen=True)
class BladeDeflectionTable:
    """The rotor's thrust and torque coefficients with its blades bent downwind, on :func:`rotor_table`'s grid.

    A blade bent by its flap deflection is coned downwind, turned by its slope and shorter in radius (it bends at
    constant length): it meets less of the wind and sweeps a smaller disc. OpenFAST's AeroDyn driver on the deck's
    blade bent along its first flap mode (ElastoDyn's ``BldFl1Sh``) with a tip deflection ``tip_deflection``
    (``tools/blade_deflection_table.py``) gives the change from the straight blades' coefficients, at the deck's
    operating conditions near rated (the shaft inclined 9 deg, shear 0.2: the bent blades lose more there than in
    an aligned uniform wind, 3.2 % of the torque against 2.4 % at rated pitch), on a coarser grid interpolated
    bilinearly; here it is added to :func:`rotor_table`. Between the straight and the tabulated blade the
    coefficients are taken quadratic in the tip deflection ``d`` (the cone, slope and shortening effects all are,
    to leading order)::

        C(d) = C + (C_bent - C) (d / tip_deflection)^2

    Measured on the deck (``tools/openfast_blade_flex_runs.py``, platform held, steady 12 m/s): in uniform wind
    OpenFAST's rotor settles 0.455 deg of pitch lower with flexible blades (4.7 m at the tip) than with rigid ones,
    and this table gives 0.471 deg; at the steady-wind run's mean position (shear 0.2, 10.3 deg inclination)
    the difference is 1.05 deg (5.26 m) and the simulation's rotor gives 0.80 deg
    (``tests/test_blade_deflection.py``).

    Attributes
    ----------
    tsr : ndarray (n_tsr,)
        Tip-speed ratios (-), the grid of :func:`rotor_table`.
    pitch_rad : ndarray (n_pitch,)
        Collective pitch angles (rad).
    ct, cq : ndarray (n_tsr, n_pitch)
        Thrust and torque coefficients of the bent rotor (-), normalised as :class:`RotorTable`'s.
    tip_deflection : float
        Tip deflection of the tabulated bent blades (m).
    """

    tsr: np.ndarray
    pitch_rad: np.ndarray
    ct: np.ndarray
    cq: np.ndarray
    tip_deflection: float

    def coefficients(self, tsr: float, pitch_rad: float, tip_deflection: float) -> tuple[float, float]:
        """Thrust and torque coefficients ``(Ct, Cq)`` of the rotor whose blades' tips are deflected downwind by
        ``tip_deflection`` (m), at one tip-speed ratio and pitch (rad).

        Examples
        --------
        >>> t = blade_deflection_table()
        >>> ct0, cq0 = t.coefficients(6.65, np.deg2rad(1.0), 0.0)
        >>> ct5, cq5 = t.coefficients(6.65, np.deg2rad(1.0), 5.0)
        >>> bool(0.9 < cq5 / cq0 < 0.99 and 0.95 < ct5 / ct0 < 1.0)
        True
        """
        rt = rotor_table()
        ct0, cq0 = rotor_coefficients(rt.tsr, rt.pitch_rad, rt.ct, rt.cq, float(tsr), float(pitch_rad))
        ct1, cq1 = rotor_coefficients(self.tsr, self.pitch_rad, self.ct, self.cq, float(tsr), float(pitch_rad))
        f = (float(tip_deflection) / self.tip_deflection) ** 2
        return ct0 + f * (ct1 - ct0), cq0 + f * (cq1 - cq0)


@lru_cache(maxsize=1)
def blade_deflection_table() -> BladeDeflectionTable:
    """The bent rotor's coefficients (:class:`BladeDeflectionTable`), from ``surrogates/data`` on the rotor table."""
    import json

    from scipy.interpolate import RegularGridInterpolator

    data = json.loads(resources.files("surrogates").joinpath("data/blade_deflection_table.json").read_text())
    rt = rotor_table()
    tsr = np.asarray(data["tsr"], dtype=float)
    pitch = np.deg2rad(np.asarray(data["pitch_deg"], dtype=float))
    lam = np.clip(rt.tsr, tsr[0], tsr[-1])
    beta = np.clip(rt.pitch_rad, pitch[0], pitch[-1])
    pts = np.stack(np.meshgrid(lam, beta, indexing="ij"), axis=-1)
    out = []
    for key, base in (("ct_delta", rt.ct), ("cq_delta", rt.cq)):
        delta = RegularGridInterpolator((tsr, pitch), np.asarray(data[key], dtype=float))(pts)
        arr = np.ascontiguousarray(base + delta, dtype=float)
        arr.setflags(write=False)
        out.append(arr)
    return BladeDeflectionTable(rt.tsr, rt.pitch_rad, out[0], out[1], float(data["tip_deflection_m"]))
