"""Time-domain simulation of :class:`~surrogates.model.FOWTModel`: forcing synthesis and a compiled stepper.

The linear part is integrated exactly: the continuous system is discretised once per (model, case, step) with
the matrix exponential, with a first-order hold on the precomputed forcing (waves, wind: piecewise linear
between samples, exact for it) and a zero-order hold on what is evaluated per step (nonlinear effects, rotor
harmonics, actions). The nonlinear and harmonic loads are evaluated explicitly from the state at the start of
each step in a numba kernel; with the internal step at most 0.025 s this is accurate and stable (their time
scales are the wave and platform periods). Forcing is synthesised in the frequency domain (FFT), see
:mod:`surrogates.waves` and :mod:`surrogates.wind`.

Randomness: the integer ``seed`` feeds a ``numpy.random.SeedSequence`` whose children seed the waves, the wind,
the rotor's initial azimuth and the sensor noise -- the same seed gives the same bytes.
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numba
import numpy as np
import scipy.linalg as sla

from .aero import (
    blade_deflection_table,
    blade_inplane_gain,
    blade_inplane_sensitivity,
    inclined_rotor_inplane,
    inclined_rotor_moment,
    inclined_rotor_moment_by_pitch,
    inplane_ring_weights,
    inplane_wind_loads,
    operating_point,
    rotor_coefficients,
    rotor_table,
    skew_gains,
)
from .channels import ALL_CHANNELS, UNITS
from .controller import DISCON, N_CONTROLLER_STATE, discon_step, initial_controller_state, steady_state
from .controller import PARAMS as DISCON_PARAMS
from .drag import N_STRIPS, drag_strips
from .load_cases import LoadCase
from .model import (
    BLADE_SAMPLING_RADIUS,
    DISC_RATE_LAG,
    INPUT_BLOCKS,
    N_INPUT,
    N_STATE,
    FOWTModel,
    LinearSystem,
    _as_case,
    blade_load_radii,
    cyclic_flap_aero_shares,
    rotor_free_inertia,
)
from .mooring import mooring_loads, mooring_table
from .oc3 import RHO_AIR
from .record import Record
from .replay import blade_effective_wind
from .structure import _CYCLIC, N_DOF
from .structure import _FLAP as FLAP
from .validation import check_number
from .waves import synthesize_waves
from .wind import (
    TURBSIM_GRID_SPACING,
    RotorWind,
    constrain_to_hub,
    hub_series,
    kaimal_spectrum,
    rotor_averaging,
    synthesize_rotor_wind,
)


def mean_shear_z(wind_speed: float, exponent: float = 0.2, hub_height: float = 90.0, radius: float = 63.0) -> float:
    """Vertical gradient (1/s) of the plane fitted over the rotor disc to the power-law profile
    ``V (z/H)^exponent`` (area-weighted least squares: ``int z U dA / int z^2 dA``)."""
    r = np.linspace(0.0, radius, 201)[1:]
    a = np.linspace(0.0, 2 * np.pi, 181)[:-1]
    rr, aa = np.meshgrid(r, a, indexing="ij")
    z = rr * np.cos(aa)
    u = wind_speed * ((hub_height + z) / hub_height) ** exponent
    w = rr  # polar area element
    return float(np.sum(w * z * u) / np.sum(w * z * z))

__all__ = ["simulate", "Simulator", "MAX_INTERNAL_STEP", "MAX_SAMPLE_TIME"]

MAX_INTERNAL_STEP = 0.025
"""Largest internal integration step (s); longer sample times are subdivided."""
MAX_SAMPLE_TIME = 0.15
"""Largest sample time (s): the 2nd tower modes (up to ~2.6 Hz) must lie below the Nyquist frequency."""
N_EX = INPUT_BLOCKS["shear"].stop  # exogenous (precomputed) inputs: const, wave(6), wind, elev, hub wind, shear(2)
_PLATFORM_DOF = {"PtfmSurge": 0, "PtfmSway": 1, "PtfmHeave": 2, "PtfmRoll": 3, "PtfmPitch": 4, "PtfmYaw": 5}
_PLATFORM_RATE = {"PtfmTVxi": 0, "PtfmTVyi": 1, "PtfmTVzi": 2, "PtfmRVxi": 3, "PtfmRVyi": 4, "PtfmRVzi": 5}
"""ElastoDyn's platform velocities (m/s, deg/s) as initial conditions of the platform DOFs' rates."""
_INITIAL_CHANNELS = (*_PLATFORM_DOF, *_PLATFORM_RATE, "TTDspFA", "TTDspSS", "RotSpeed", "BldPitch1", "GenTq")


def elastodyn_platform_angles(y: np.ndarray, i_roll: int, i_pitch: int, i_yaw: int, mean_pitch: float = 0.0) -> None:
    """Turn the model's platform roll and yaw (deg, in place in ``y`` of shape (n, channels)) into ElastoDyn's.

    The model's roll ``r`` and yaw ``y`` are small rotations about the platform's own axes, which pitch with it: a
    slender spar yaws about its long axis. ElastoDyn (OpenFAST v5, ``SetCoordSy``) instead describes the platform
    by Euler angles in the order yaw about the vertical, pitch about the yawed lateral axis, roll about the pitched
    longitudinal axis (``EulerConstructZYX``): ``R = R_z(PtfmYaw) R_y(PtfmPitch) R_x(PtfmRoll)``. Equating it with
    ``R_y(p) (I + [r, 0, y]x)`` to first order in ``r`` and ``y`` (the pitch ``p`` finite) gives

        PtfmRoll = r + y tan(p),    PtfmPitch = p,    PtfmYaw = y / cos(p):

    at OpenFAST's 4 deg mean pitch at rated wind, 7 % of the platform's own yaw appears as roll. OpenFAST's
    records show exactly that: their roll over yaw in 0.065-0.11 Hz, where the yaw mode drives both (coherence
    0.8-0.95), is 0.078-0.092 deg/deg at 12 m/s (mean pitch 4.1 deg, sin 0.072) and 0.044-0.048 at 18 m/s
    (2.8 deg, sin 0.049). (ElastoDyn before v5 used the rotation vector of ``SmllRotTrans``, which would show
    ``p y / 2``.) :func:`body_platform_angles` is the inverse.

    With ``mean_pitch`` (rad) ``y`` already holds that map about the mean pitch ``p0`` (the linear model's rows:
    roll ``r + y tan(p0)``, yaw ``y / cos(p0)``, :attr:`surrogates.model.LinearSystem.mean_pitch`); only the rest,
    at the instantaneous pitch, is added.
    """
    p = np.deg2rad(y[:, i_pitch])
    y_body = y[:, i_yaw] * math.cos(mean_pitch)
    y[:, i_roll] += (np.tan(p) - math.tan(mean_pitch)) * y_body
    y[:, i_yaw] = y_body / np.cos(p)


def body_platform_angles(roll: float, pitch: float, yaw: float) -> tuple[float, float]:
    """The model's body-axes roll and yaw for ElastoDyn's platform Euler angles (the inverse of
    :func:`elastodyn_platform_angles`).

    Parameters
    ----------
    roll, pitch, yaw : float
        ElastoDyn's ``PtfmRoll``, ``PtfmPitch``, ``PtfmYaw`` (rad).

    Returns
    -------
    (float, float)
        Roll and yaw about the platform's own (pitched) axes (rad).
    """
    y = yaw * math.cos(pitch)
    return roll - math.tan(pitch) * y, y


def _blade_wind_columns(wind: RotorWind, wind_speed: float) -> np.ndarray:
    """The stepper's blade winds (n_field, N_BLADE_COLUMNS) of a synthesised rotor field (``RotorWind`` with its
    polar field): the wind along each blade at ``N_BLADE_AZIMUTH`` azimuths weighted as its thrust and torque
    answer it, then as its in-plane force does (ring weights at ``wind_speed``)."""
    w_ip = inplane_ring_weights(wind.polar_radii, wind_speed)[0]
    return np.concatenate([
        blade_effective_wind(wind.polar_u, wind.polar_radii, wind.polar_azimuth_rad, N_BLADE_AZIMUTH),
        blade_effective_wind(wind.polar_u, wind.polar_radii, wind.polar_azimuth_rad, N_BLADE_AZIMUTH, w_ip)], axis=1)


# ------------------------------------------------------------------------------------------------ kernel
# scalar parameters of the kernel, packed in one float array ``par``
P_DT, P_SMOOR, P_ZF, P_SDRAG, P_ROTOR, P_V0, P_OMEGA0, P_J, P_NGEAR, P_RADIUS, P_QAREA, P_SAERO, P_TILT, \
    P_JREACT, P_GENEFF, P_SASYM, P_DTDU, P_DQDU, P_RT, P_GIP, P_RS, P_RTY, P_SKIN, P_MZG, P_RIP, P_PHIT, P_VT, P_WT, \
    P_VY, P_WY, P_FIP, P_SPINC, P_SSKEW, P_SKT, P_SKM, P_SKF, P_SBEND, P_DBEND, P_SCURV, P_INCF0, \
    P_INCF1, P_LAGC, P_LAGS, P_SKMN, P_SKMB, P_SKF1, P_SKC0, P_SKC1 = range(48)
N_SKM_NODES = 16
P_SKM_PITCH = 48
P_SKM_K = P_SKM_PITCH + N_SKM_NODES
N_PAR = P_SKM_K + N_SKM_NODES
"""(P_PHIT: the blade's flap mode at the thrust's centre, ``BladeFlapMode.thrust_shape``; P_VT, P_WT, P_VY, P_WY:
:func:`surrogates.model.cyclic_flap_aero_shares`; P_FIP: the in-plane force's share of a blade's tip flap velocity,
its gain-weighted mean of the flap shape; P_SPINC: ``c / J`` of :func:`surrogates.model.rotor_free_inertia`, how the
rotor speed relative to the nacelle answers the nacelle's roll about the shaft; P_SSKEW: strength of
``rotor_skew``; P_SKT, P_SKM: one blade's thrust and moment per m/s of tangential airspeed,
:func:`surrogates.aero.skew_gains` at the equilibrium's inclination; P_SKF, P_SKF1, P_SKC0, P_SKC1: one blade's force
along the in-plane wind and moment across it per m/s of it, straight blades and per metre of tip deflection,
:func:`surrogates.aero.inplane_wind_loads`; P_SBEND, P_DBEND: strength of
``blade_deflection`` and the tip deflection (m) of :func:`surrogates.aero.blade_deflection_table`'s bent blades;
P_SCURV: strength of ``sampled_wind_curvature``; P_INCF0, P_INCF1: the in-plane force's share of the rotor's
in-plane wind, straight blades and per metre of tip deflection, :func:`surrogates.aero.inclined_rotor_inplane`;
P_LAGC, P_LAGS: cosine and sine of :data:`surrogates.model.DISC_RATE_LAG_DEG`; P_SKMN, P_SKMB: the number of nodes
of :func:`surrogates.aero.inclined_rotor_moment_by_pitch` (0: P_SKM held) and its value at the equilibrium's pitch;
its nodes' pitch (rad) from P_SKM_PITCH and moment per m/s of in-plane wind from P_SKM_K, N_SKM_NODES slots each.)"""
I_ACC = N_CONTROLLER_STATE
"""Slots of the stepper's carried state ``ctrl`` after the controller's: the platform's heave, roll and pitch
accelerations of the previous internal step (m/s^2, rad/s^2), which the CM kinematics (``cm_kinematics``) read."""
N_CARRIED = N_CONTROLLER_STATE + 3
H_CURV = 1.0
"""Wind step (m/s) of the second differences that give the rotor's curvature in the wind (sampled_wind_curvature):
two rotor-table cells of tip-speed ratio at rated (0.5 apart), so that the bilinear table's kinks average out."""
FIELD_DT = 0.05
"""Time step (s) of the synthesised turbulent field over the rotor disc."""
N_BLADE_AZIMUTH = 24
"""Azimuths of the blade-effective wind around the rotor (-)."""
N_BLADE_COLUMNS = 2 * N_BLADE_AZIMUTH
"""Columns of the stepper's blade winds: the wind along each blade at ``N_BLADE_AZIMUTH`` azimuths weighted as its
thrust and torque answer it (radius-weighted), then as its in-plane force does
(:func:`surrogates.aero.inplane_ring_weights`); a replayed rotor azimuth adds one more column."""
FIELD_AZIMUTH = 16
"""Points per ring of the synthesised polar field (-), as the reference runs' ``inflow.npz`` sample the TurbSim grid;
the blade-effective wind is interpolated from them to ``N_BLADE_AZIMUTH`` azimuths, as in a replay."""
FIELD_GRID_SPACING = TURBSIM_GRID_SPACING
"""Resolution (m) of the synthesised turbulence: the field as OpenFAST reads it from the OC3 deck's TurbSim grid,
by bilinear interpolation (:func:`surrogates.wind.grid_interpolation_variance`)."""
I_WIND = INPUT_BLOCKS["wind"].start
I_HUB_WIND = INPUT_BLOCKS["hub_wind"].start
I_ACTION = INPUT_BLOCKS["action"].start
I_HUB = INPUT_BLOCKS["hub"].start
I_NL = INPUT_BLOCKS["nonlinear"].start
I_ROTOR = INPUT_BLOCKS["rotor"].start
HARMONICS_WIND_SPEED = 12.0
"""Wind speed (m/s) of OpenFAST's steady run on which :class:`surrogates.model.RotorHarmonics` were measured,
under the power-law shear :data:`HARMONICS_SHEAR_EXPONENT`."""
HARMONICS_SHEAR_EXPONENT = 0.2


@functools.lru_cache(maxsize=1)
def side_force_law() -> float:
    """The rotor's 3P side force per unit of ``V^2 dQ/dV`` (s/m^2: N of force per N m^2/s of ``V^2 dQ/dV``), for
    :attr:`surrogates.model.RotorHarmonics.side_force_3p` = 1.

    The side force's amplitude is ``side_force_3p * T_12 * (V^2 dQ/dV) / (V_12^2 dQ/dV_12)``: the harmonic's
    fraction of the thrust ``T_12`` at the 12 m/s point where it is defined, carried to any other state by the
    rotor-normal wind ``V`` and the torque's sensitivity to it ``dQ/dV`` (at constant rotor speed and pitch; from
    the rotor tables at every step with the nonlinear rotor, at the operating point without). The blades passing
    the tower lose in-plane (torque) force in proportion to their sensitivity to the wind and to the shadow's
    deficit, a fixed fraction of the wind; OpenFAST's side-to-side 3P response in steady wind with shear 0.2 at
    8, 10, 12, 14 and 18 m/s (``tools/openfast_rotor_harmonics_runs.py``) rises as ``V^2 dQ/dV`` does
    (x8 from 8 to 18 m/s) while the thrust falls above rated: the tower's 3P side-to-side response scaled with the
    thrust was 2x OpenFAST's at 8 m/s and 0.1x at 18 m/s. With the linear rotor the 12 m/s side force is exactly
    ``side_force_3p * T_12``; the nonlinear rotor's ``dQ/dV`` (+-1 m/s differences of the rotor-normal wind, the
    blades bent) is within 1-2 % of the operating point's there.

    Returns
    -------
    float
        ``T_12 / (V_12^2 dQ/dV_12)`` (s/m^2), with ``V_12`` = :data:`HARMONICS_WIND_SPEED`.
    """
    op = operating_point(HARMONICS_WIND_SPEED)
    return float(op.thrust / (HARMONICS_WIND_SPEED**2 * op.dQ_dV))


@functools.lru_cache(maxsize=1)
def _shear_share() -> dict[str, float]:
    return sampled_shear_harmonics()


def sampled_shear_harmonics(wind_speed: float = HARMONICS_WIND_SPEED,
                            shear_exponent: float = HARMONICS_SHEAR_EXPONENT,
                            hub_height: float = 90.0) -> dict[str, float]:
    """The rotor's 3P and 6P loads from its blades sampling the mean power-law shear, as the simulation's
    rotationally sampled rotor (``rotor_asymmetry``) computes them, in the units of
    :class:`surrogates.model.RotorHarmonics`.

    OpenFAST's 3P/6P shaft loads, which :class:`~surrogates.model.RotorHarmonics` holds, are those of the tower's
    shadow *and* the shear; when the blades sample a field that carries the mean shear, the shear's share is in
    that field already. This is the share (each blade's thrust, torque and in-plane force at its effective wind,
    linear in the departure from the disc mean; projected on the harmonics' own phases: ``cos 3 psi`` for thrust,
    torque, tilt and side force, ``sin 3 psi`` for yaw, ``psi = 0`` blade 1 up) that the simulation subtracts
    from the measured amplitudes, leaving the shadow's: at 12 m/s it is 28 % of the 3P thrust and 59 % of the 3P
    tilt moment.

    Parameters
    ----------
    wind_speed : float
        Hub-height mean wind speed (m/s).
    shear_exponent : float
        Power-law exponent of the mean profile (-).
    hub_height : float
        Hub height (m).

    Returns
    -------
    dict of str to float
        ``thrust_3p``, ``thrust_6p``, ``torque_3p``, ``moment_3p``, ``yaw_moment_3p``, ``side_force_3p``: fractions
        of the operating point's thrust, torque and thrust times radius, signed as the harmonics are (positive:
        in phase with the measured harmonic).
    """
    from .aero import operating_point
    from .load_cases import operating_case
    from .oc3 import load_oc3

    wind_speed = check_number("wind_speed", wind_speed, positive=True)
    shear_exponent = check_number("shear_exponent", shear_exponent, nonneg=True)
    d = load_oc3()
    rt = rotor_table()
    op = operating_point(wind_speed, operating_case(wind_speed).rotor_rpm, d.rotor_inertia)
    radii = np.linspace(0.0, rt.radius, 5)
    az = np.arange(FIELD_AZIMUTH) * 2.0 * np.pi / FIELD_AZIMUTH
    z = radii[:, None] * np.cos(az)[None, :]
    polar = wind_speed * ((hub_height + z) / hub_height) ** shear_exponent
    w_ip = inplane_ring_weights(radii, wind_speed)[0]
    v_t = blade_effective_wind(polar[None], radii, az, N_BLADE_AZIMUTH)[0].astype(float)
    v_ip = blade_effective_wind(polar[None], radii, az, N_BLADE_AZIMUTH, w_ip)[0].astype(float)
    disc = float(np.mean(v_t))
    r_t, r_ty = blade_load_radii(rt.radius)
    g_ip = blade_inplane_gain(wind_speed)
    psi = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
    az_n = np.arange(N_BLADE_AZIMUTH) * 2.0 * np.pi / N_BLADE_AZIMUTH
    thrust = np.zeros_like(psi)
    torque = np.zeros_like(psi)
    tilt = np.zeros_like(psi)
    yaw = np.zeros_like(psi)
    side = np.zeros_like(psi)
    for b in range(3):
        psi_b = psi + b * 2.0 * np.pi / 3.0
        phi = (-psi_b) % (2.0 * np.pi)  # the blade's azimuth from the top towards +y, as the kernel reads it
        dv = np.interp(phi, az_n, v_t, period=2.0 * np.pi) - disc
        dv_ip = np.interp(phi, az_n, v_ip, period=2.0 * np.pi) - disc
        d_t = op.dT_dV / 3.0 * dv
        thrust += d_t
        torque += op.dQ_dV / 3.0 * dv
        tilt += d_t * r_t * np.cos(psi_b)
        yaw += d_t * r_ty * np.sin(psi_b)
        side += -g_ip * dv_ip * np.cos(psi_b)

    def coef(x: np.ndarray, fn, n: int) -> float:
        return float(2.0 * np.mean(x * fn(n * psi)))

    tr = op.thrust * rt.radius
    return {
        "thrust_3p": coef(thrust, np.cos, 3) / op.thrust,
        "thrust_6p": coef(thrust, np.cos, 6) / op.thrust,
        "torque_3p": coef(torque, np.cos, 3) / op.aero_torque,
        "moment_3p": -coef(tilt, np.cos, 3) / tr,
        "yaw_moment_3p": coef(yaw, np.sin, 3) / tr,
        "side_force_3p": -coef(side, np.cos, 3) / op.thrust,
    }


@numba.njit(cache=True, nogil=True)
def _mooring_generalised(x, gx, gy, gyaw, tab, zf, out):
    """Mooring loads as generalised forces on the 6 platform DOFs about the SWL reference point: out[6:12], the
    forces along the fixed axes and the moments along the platform's roll, pitch and yaw axes (out[0:6] is
    scratch: the table's loads about the displaced fairlead centre)."""
    dx = x[0] + zf * x[4]
    dy = x[1] - zf * x[3]
    mooring_loads(gx, gy, gyaw, tab, dx, dy, x[5], out[0:6])
    lx, ly, lz = zf * x[4], -zf * x[3], zf  # fairlead centre relative to the displaced reference point
    fx, fy, fz = out[0], out[1], out[2]
    out[6] = fx
    out[7] = fy
    out[8] = fz
    mx = out[3] + ly * fz - lz * fy  # moments about the fixed axes
    my = out[4] + lz * fx - lx * fz
    mz = out[5] + lx * fy - ly * fx
    # the platform's roll turns about its pitched longitudinal axis and its yaw about its own long axis: a moment
    # about the fixed axes loads them by its components along them -- the spar's axis R_y(pitch) R_x(roll) e_z for
    # the yaw, so that the line forces, which act at the fairlead centre on that axis, have no moment about it
    # whatever the roll (only the lines' spread about the centre does)
    c, s = math.cos(x[4]), math.sin(x[4])
    cr, sr = math.cos(x[3]), math.sin(x[3])
    out[9] = c * mx - s * mz
    out[10] = my
    out[11] = s * cr * mx - sr * my + c * cr * mz


@numba.njit(cache=True, nogil=True)
def _by_pitch(par, n, pitch):
    """Linear interpolation of the P_SKM_K nodes over the P_SKM_PITCH nodes at ``pitch`` (rad), held beyond them."""
    b0 = P_SKM_PITCH
    k0 = P_SKM_K
    if pitch <= par[b0]:
        return par[k0]
    for i in range(1, n):
        if pitch <= par[b0 + i]:
            f = (pitch - par[b0 + i - 1]) / (par[b0 + i] - par[b0 + i - 1])
            return par[k0 + i - 1] + f * (par[k0 + i] - par[k0 + i - 1])
    return par[k0 + n - 1]


@numba.njit(cache=True, nogil=True)
def _loads(x, ctrl, k, psi, action, u_ex, vel, blade, strip_z, drag_coef, drag_along, drag_across, drag_dir, moor_gx,
           moor_gy, moor_gyaw, moor_tab, moor_g0,
           moor_jac, moor_out, harm, e_s, h_v, r_pitch, tsr_grid, pitch_grid, ct_tab, cq_tab, ctb_tab, cqb_tab, par,
           u):
    """Fill u[10:] (actions, hub loads, nonlinear generalised forces, rotor outputs) from the state at the start
    of a step; return the rotor acceleration (rad/s^2, 0 when the rotor is linear or parked)."""
    nd = N_DOF
    hub0 = I_HUB
    nl0 = I_NL
    rot0 = I_ROTOR
    for i in range(hub0, u.shape[0]):
        u[i] = 0.0
    u[I_ACTION] = action[0]
    u[I_ACTION + 1] = action[1]
    v_hub_wind = u_ex[k, I_HUB_WIND]
    u[rot0 + 4] = v_hub_wind * abs(v_hub_wind)
    # --- quadratic drag on the relative velocity, strip by strip, minus its equivalent linearisation (which the
    #     linear model holds)
    s_drag = par[P_SDRAG]
    if s_drag > 0.0:
        ex, ey = drag_dir[0], drag_dir[1]
        for j in range(strip_z.shape[0]):
            z = strip_z[j]
            vx = x[nd + 0] + z * x[nd + 4]
            vy = x[nd + 1] - z * x[nd + 3]
            ux = vel[k, j, 0] - vx
            uy = vel[k, j, 1] - vy
            s = math.sqrt(ux * ux + uy * uy)
            ua = ux * ex + uy * ey
            lx = drag_along[j] * ua * ex + drag_across[j] * (ux - ua * ex)
            ly = drag_along[j] * ua * ey + drag_across[j] * (uy - ua * ey)
            fx = s_drag * (drag_coef[j] * s * ux - lx)
            fy = s_drag * (drag_coef[j] * s * uy - ly)
            u[nl0 + 0] += fx
            u[nl0 + 1] += fy
            u[nl0 + 3] += -z * fy
            u[nl0 + 4] += z * fx
    # --- catenary mooring: table loads on (fairlead offset, yaw), minus their own linearisation (which the
    #     linear stiffness already holds)
    s_moor = par[P_SMOOR]
    if s_moor > 0.0:
        _mooring_generalised(x, moor_gx, moor_gy, moor_gyaw, moor_tab, par[P_ZF], moor_out)
        for i in range(6):
            acc = moor_out[6 + i] - moor_g0[i]
            for j in range(6):
                acc += moor_jac[i, j] * x[j]
            u[nl0 + i] += s_moor * acc
    # --- second-order kinematics of the platform's rotations (cm_kinematics): the structure's centre of mass sits
    #     z_G below the reference point, at height z + z_G cos(theta) (and the same in roll), so the heave
    #     equation carries M z_G (cos(theta) theta'^2 + sin(theta) theta'') and pitch the reciprocal
    #     M z_G sin(theta) z'' (Lagrange's equations for a rotation about one axis, each axis on its own: what the
    #     linear model lacks; OpenFAST's ElastoDyn keeps the whole rigid-body kinematics). The accelerations are the
    #     previous step's (the coupling is weak: (M z_G theta)^2 / (M I) < 1 %)
    s_kin = par[P_SKIN]
    if s_kin > 0.0:
        mzg = s_kin * par[P_MZG]
        s_phi, c_phi = math.sin(x[3]), math.cos(x[3])
        s_th, c_th = math.sin(x[4]), math.cos(x[4])
        u[nl0 + 2] += mzg * (c_th * x[nd + 4] * x[nd + 4] + s_th * ctrl[I_ACC + 2]
                             + c_phi * x[nd + 3] * x[nd + 3] + s_phi * ctrl[I_ACC + 1])
        u[nl0 + 3] += mzg * s_phi * ctrl[I_ACC]
        u[nl0 + 4] += mzg * s_th * ctrl[I_ACC]
    # --- nonlinear rotor: Ct/Cq surfaces at the wind relative to the moving hub, DISCON's torque and pitch
    domega = 0.0
    side_drive = harm[15]  # V^2 dQ/dV of the 3P side force (N m^2/s): the operating point's, or below
    if par[P_ROTOR] > 0.0:
        v_hub = 0.0
        theta = 0.0
        yaw = 0.0  # tower-top yaw rotation (rad)
        rate_y = 0.0  # tower-top pitch and yaw rates (rad/s); r_pitch holds the pitch row, then the yaw row
        rate_z = 0.0
        for i in range(nd):
            v_hub += h_v[i] * x[nd + i]
            theta += r_pitch[i] * x[i]
            yaw += r_pitch[nd + i] * x[i]
            rate_y += r_pitch[i] * x[nd + i]
            rate_z += r_pitch[nd + i] * x[nd + i]
        wind = u_ex[k, I_WIND] + par[P_V0]
        vn = wind * math.cos(par[P_TILT] - theta) - par[P_SAERO] * v_hub  # shaft elevation: tilt - pitch
        omega = par[P_OMEGA0] + x[2 * nd]
        pitch = ctrl[2] + action[0]
        lam = omega * par[P_RADIUS] / max(abs(vn), 0.1)
        ct, cq = rotor_coefficients(tsr_grid, pitch_grid, ct_tab, cq_tab, lam, pitch)
        # the blades bent downwind by their collective flap deflection (blade_deflection): quadratic in the tip
        # deflection between the straight rotor and the tabulated bent one
        f_bend = 0.0
        if par[P_SBEND] > 0.0:
            f_bend = x[FLAP] / par[P_DBEND]
            f_bend = par[P_SBEND] * f_bend * f_bend
            ctb, cqb = rotor_coefficients(tsr_grid, pitch_grid, ctb_tab, cqb_tab, lam, pitch)
            ct += f_bend * (ctb - ct)
            cq += f_bend * (cqb - cq)
        qdyn = par[P_QAREA] * vn * abs(vn)
        thrust = qdyn * ct
        q_aero = qdyn * par[P_RADIUS] * cq
        # curvature of the rotor's thrust and torque in a uniform wind at this step's speed and pitch (second
        # differences over +-H_CURV m/s): each blade meets its own wind, and a blade's load is curved in it
        # (sampled_wind_curvature), so the rotor carries 1/3 * 1/2 * d2(load)/dV2 * dv_b^2 per blade beyond the
        # linear blade loads
        # (the same differences give the torque's sensitivity to the wind, dQ/dV, which sets the 3P side force)
        t_uu = 0.0
        q_uu = 0.0
        s_curv = par[P_SCURV]
        need_dq = harm[0] != 0.0 and harm[12] != 0.0
        if s_curv > 0.0 or need_dq:
            dq_dv = 0.0
            for sgn in (-1.0, 1.0):
                v_c = vn + sgn * H_CURV
                lam_c = omega * par[P_RADIUS] / max(abs(v_c), 0.1)
                ct_c, cq_c = rotor_coefficients(tsr_grid, pitch_grid, ct_tab, cq_tab, lam_c, pitch)
                if f_bend > 0.0:
                    ctb, cqb = rotor_coefficients(tsr_grid, pitch_grid, ctb_tab, cqb_tab, lam_c, pitch)
                    ct_c += f_bend * (ctb - ct_c)
                    cq_c += f_bend * (cqb - cq_c)
                q_c = par[P_QAREA] * v_c * abs(v_c)
                t_uu += q_c * ct_c
                q_uu += q_c * par[P_RADIUS] * cq_c
                dq_dv += sgn * q_c * par[P_RADIUS] * cq_c
            t_uu = s_curv * (t_uu - 2.0 * thrust) / (H_CURV * H_CURV) / 6.0
            q_uu = s_curv * (q_uu - 2.0 * q_aero) / (H_CURV * H_CURV) / 6.0
            side_drive = vn * vn * dq_dv / (2.0 * H_CURV)
        # advancing and retreating blades (rotor_skew): the wind's component in the rotor plane -- up the disc
        # w_z from the shaft's inclination (tilt - pitch, nose up), sideways w_y from the top's yaw, less the hub's
        # own in-plane velocity -- adds w_y cos(psi_b) + w_z sin(psi_b) to blade b's airspeed; with one blade's
        # thrust, moment and in-plane force per m/s of airspeed (skew_gains, at the operating point as the other
        # rotor-asymmetry gains), the three blades sum to 1.5x: a yaw moment from w_z, a tilt moment from w_y, an
        # in-plane force against each, and the cyclic flap modes loaded as by any once-per-revolution thrust
        s_skew = par[P_SSKEW]
        w_z = 0.0
        w_y = 0.0
        if s_skew > 0.0:
            v_y = 0.0
            v_up = 0.0
            for i in range(nd):
                v_y += r_pitch[3 * nd + i] * x[nd + i]
                v_up += r_pitch[4 * nd + i] * x[nd + i]
            w_z = 1.5 * s_skew * (wind * math.sin(theta - par[P_TILT]) - par[P_SAERO] * v_up)
            w_y = 1.5 * s_skew * (-wind * math.sin(yaw) - par[P_SAERO] * v_y)
            # the force along the in-plane wind and the yaw moment across the lateral one (inplane_wind_loads:
            # AeroDyn's skewed wake and the blades' cone, M = k e_x x w), growing with the blades' downwind bend;
            # the tilt moment across the wind up the disc is held by the shear's calibrated tilt gain
            # (ROTOR_ASYMMETRY, which gives OpenFAST's mean tower-base moment): it is left out here
            bend = par[P_SBEND] * x[FLAP] if par[P_SBEND] > 0.0 else 0.0
            f_w = par[P_SKF] + bend * par[P_SKF1]
            u[hub0 + 1] += f_w * w_y
            u[hub0 + 2] += f_w * w_z
            u[hub0 + 5] += (par[P_SKC0] + bend * par[P_SKC1]) * w_y
            # the moment per m/s of in-plane wind follows the blade pitch along AeroDyn's operating points
            # (inclined_rotor_moment_by_pitch), relative to the equilibrium's
            k_m = par[P_SKM]
            n_sk = int(par[P_SKMN])
            if n_sk > 1:
                k_m += _by_pitch(par, n_sk, pitch) - par[P_SKMB]
            u[hub0 + 4] += k_m * w_y
            u[hub0 + 5] += k_m * w_z
            # (the cross moment loads the hub only: loading the cyclic flap modes with it too, as the advancing
            # blades' moment does, put the held platform's yaw moment per pitch rate 1.25x OpenFAST's and its slow
            # slope on the blade pitch 0.70x; tests/test_yaw_locked.py)
            u[nl0 + _CYCLIC[0]] += par[P_PHIT] * par[P_WT] * par[P_SKT] * w_y
            u[nl0 + _CYCLIC[1]] += par[P_PHIT] * par[P_WY] * par[P_SKT] * w_z
        # rotationally sampled turbulence: each blade's wind departs from the disc mean; linear blade loads give
        # the rotor's tilt/yaw moments, in-plane force and the 3P-band thrust and torque
        # and the disc's own tilt and yaw rates: a point (y, z) of the disc moves downwind at rate_y z - rate_z y,
        # so the blades meet a relative-wind gradient (-rate_y over z, +rate_z over y): the rotor's aerodynamic
        # damping of tilt and yaw (aero_damping)
        # and the blades' own cyclic flap velocity in the rotating frame at the thrust's centre (the collective's
        # is in v_hub): (q_t' + Omega q_y) cos psi_b + (q_y' - Omega q_t) sin psi_b
        s_asym = par[P_SASYM]
        s_rot = par[P_SAERO] if par[P_RS] > 0.0 else 0.0
        has_field = s_asym > 0.0 and blade.shape[0] > k and blade[k, 0] == blade[k, 0]  # NaN: azimuth only
        # the inclined (or yawed) rotor's in-plane wind W (the skew block's, per blade) meets the coned blades and
        # AeroDyn's skewed wake as a gradient against it: blade b's in-plane force sees its axial wind change by
        # -eps (W . e_r,b), eps linear in the collective flap deflection (the blades' downwind cone);
        # inclined_rotor_inplane
        eps_f = 0.0
        if s_skew > 0.0:
            eps_f = par[P_INCF0] + (par[P_SBEND] * par[P_INCF1] * x[FLAP] if par[P_SBEND] > 0.0 else 0.0)
            eps_f *= 1.0 / 1.5  # w_y, w_z carry the three blades' 1.5 and the strength
        if has_field or s_rot > 0.0 or eps_f != 0.0:
            it = _CYCLIC[0]
            iy = _CYCLIC[1]
            tip_t = x[nd + it] + omega * x[iy]
            tip_y = x[nd + iy] - omega * x[it]
            flap_t = par[P_PHIT] * par[P_VT] * tip_t
            # the blades answer the disc's rates DISC_RATE_LAG_DEG of azimuth late: the rates' gradient turned by it
            lag_y = rate_y * par[P_LAGC] - rate_z * par[P_LAGS]
            lag_z = rate_y * par[P_LAGS] + rate_z * par[P_LAGC]
            flap_y = par[P_PHIT] * par[P_VY] * tip_y
            mt = 0.0  # tilt and yaw moments of the blades' thrust
            my = 0.0
            ft = 0.0  # generalised forces on the cyclic flap modes
            fyw = 0.0
            fy = 0.0
            fz = 0.0
            for b in range(3):
                psi_b = psi + b * 2.0 * math.pi / 3.0
                c_b = math.cos(psi_b)
                s_b = math.sin(psi_b)
                # blade at r_s (-sin, cos)
                dv_r = -s_rot * (lag_y * par[P_RS] * c_b + lag_z * par[P_RS] * s_b)
                dv = dv_r - s_rot * (flap_t * c_b + flap_y * s_b)
                # the in-plane force meets the rates at its own mean radius and the flap at its own mean shape
                dv_r = dv_r * par[P_RIP] - s_rot * par[P_FIP] * (tip_t * c_b + tip_y * s_b)
                dv_r -= eps_f * (w_z * c_b - w_y * s_b)  # the in-plane wind along blade b, at (y, z) = r (-sin, cos)
                if has_field:
                    n_az = N_BLADE_AZIMUTH
                    d_az = 2.0 * math.pi / n_az
                    phi = (-psi_b) % (2.0 * math.pi)  # the blade's azimuth from the top towards +y
                    fa = phi / d_az
                    i0 = int(fa) % n_az
                    i1 = (i0 + 1) % n_az
                    wa = fa - int(fa)
                    v_b = (1.0 - wa) * blade[k, i0] + wa * blade[k, i1]
                    v_ip = (1.0 - wa) * blade[k, n_az + i0] + wa * blade[k, n_az + i1]
                    dv_ip = dv_r + s_asym * (v_ip - wind)
                    dv += s_asym * (v_b - wind)
                else:
                    dv_ip = dv_r
                d_t = par[P_DTDU] / 3.0 * dv
                d_q = par[P_DQDU] / 3.0 * dv
                # the curvature's share goes to the collective thrust and torque only: its once-per-revolution
                # part, summed over the blades, is the shear's 3P tilt and yaw, which the measured harmonics hold
                thrust += d_t + t_uu * dv * dv
                q_aero += d_q + q_uu * dv * dv
                # blade at (y, z) = r (-sin, cos): tilt = z F, yaw = -y F (its own lever: see ROTOR_ASYMMETRY); the
                # cyclic flap modes take the thrust at the thrust's centre (their response lags it: cyclic_flap_lag)
                mt += d_t * par[P_RT] * c_b
                my += d_t * par[P_RTY] * s_b
                ft += d_t * c_b
                fyw += d_t * s_b
                f_ip = par[P_GIP] * dv_ip  # the blade's in-plane force, along the direction of rotation
                fy += -f_ip * c_b
                fz += -f_ip * s_b
            u[hub0 + 1] += fy
            u[hub0 + 2] += fz
            u[hub0 + 4] += mt
            u[hub0 + 5] += my
            u[nl0 + it] += par[P_PHIT] * par[P_WT] * ft
            u[nl0 + iy] += par[P_PHIT] * par[P_WY] * fyw
        q_gen_hss = ctrl[3] + action[1] / par[P_NGEAR]
        q_gen = par[P_NGEAR] * q_gen_hss
        domega = (q_aero - q_gen) / par[P_J]
        reaction = q_gen + par[P_JREACT] * domega  # torque the drivetrain puts on the nacelle about the shaft
        # the thrust acts along the rotor axis, which turns with the tower top (a follower force): pitching
        # forward by theta tips it down by theta (e_y x e_s), the platform's set-down under thrust; yawing by psi
        # turns it sideways by psi (e_z x e_s), a side force T psi that drives sway and roll (the tower top's roll
        # would turn only the shaft's 5 deg tilt component, T sin(tilt) phi: left out)
        e_follow_x = e_s[0] + theta * e_s[2] - yaw * e_s[1]
        e_follow_y = e_s[1] + yaw * e_s[0]
        e_follow_z = e_s[2] - theta * e_s[0]
        u[hub0 + 0] += thrust * e_follow_x
        u[hub0 + 1] += thrust * e_follow_y
        u[hub0 + 2] += thrust * e_follow_z
        for a in range(3):
            u[hub0 + 3 + a] += reaction * e_s[a]
        u[rot0 + 0] = pitch
        u[rot0 + 1] = q_gen_hss
        u[rot0 + 2] = q_gen * omega * par[P_GENEFF]
        u[rot0 + 3] = thrust
    # --- rotor harmonics: harm = [T0, Q0, R, Omega0, a3, a6, aq, am, a1, b1, mi, am_yaw, c_side, (shear shares),
    #     V0^2 dQ/dV at the operating point]; the side force is c_side V^2 dQ/dV (side_force_law)
    #     (strengths applied). psi = 0: blade 1 up, so cos(3 psi) = -1 when a blade points down, through the
    #     tower's shadow and the slowest wind of the shear: the collective thrust dips while the tilt moment
    #     peaks (anti-phase); side force with the sign OpenFAST shows; yaw: see RotorHarmonics
    t0 = harm[0]
    if t0 != 0.0:
        omega = harm[3] + x[2 * nd]
        c1, s1 = math.cos(psi), math.sin(psi)
        c3, s3 = math.cos(3.0 * psi), math.sin(3.0 * psi)
        c6 = math.cos(6.0 * psi)
        # where the blades sample a field (with its mean shear), the shear's share of the measured 3P thrust and
        # tilt is theirs already (sampled_shear_harmonics): the harmonics keep the tower shadow's
        a3 = harm[4]
        am = harm[7]
        if par[P_ROTOR] > 0.0 and par[P_SASYM] > 0.0 and blade.shape[0] > k and blade[k, 0] == blade[k, 0]:
            a3 -= harm[13]
            am -= harm[14]
        fs = t0 * (a3 * c3 + harm[5] * c6 + harm[8] * c1)
        mq = harm[1] * harm[6] * c3
        tr = t0 * harm[2]
        cent = harm[10] * omega * omega
        side = harm[12] * side_drive
        for a in range(3):
            u[hub0 + a] += fs * e_s[a]
            u[hub0 + 3 + a] += mq * e_s[a]
        u[rot0 + 3] += fs  # RotThrust carries the harmonic thrust too
        u[hub0 + 1] += cent * s1 - side * c3
        u[hub0 + 2] += cent * c1
        u[hub0 + 4] += tr * (-am * c3 + harm[9] * c1)
        u[hub0 + 5] += tr * (harm[11] * s3 + harm[9] * s1)
        # the harmonic amplitudes are OpenFAST's shaft loads, measured behind its flexible blades: they act on the
        # hub, not through the blades' flap mode (which the hub-load block would also drive, by h_v[FLAP])
        f_shaft = fs + (cent * s1 - side * c3) * e_s[1] + cent * c1 * e_s[2]
        u[nl0 + FLAP] -= h_v[FLAP] * f_shaft
    return domega


@numba.njit(cache=True, nogil=True)
def _advance(x, ctrl, psi, k0, n_steps, every, phi_t, g_rest_t, exo, u_ex, action, vel, blade, strip_z, drag_coef,
             drag_along,
             drag_across, drag_dir, moor_gx,
             moor_gy, moor_gyaw, moor_tab, moor_g0, moor_jac, harm, e_s, h_v, r_pitch, tsr_grid, pitch_grid, ct_tab,
             cq_tab, ctb_tab, cqb_tab, discon, par, x_hist, u_hist, out0):
    """Advance ``n_steps`` internal steps from step index ``k0``.

    ``exo[k]`` is the precomputed contribution of the exogenous inputs to ``x[k+1]``; ``u_ex[k]`` the exogenous
    inputs themselves (the nonlinear rotor reads the wind from them). Every ``every`` steps the state and the
    per-step inputs (actions, hub loads, nonlinear forces, rotor outputs) are stored in ``x_hist[out0 + i]``
    and ``u_hist[out0 + i]`` (outputs are formed from them afterwards by one matrix product). ``x`` and the
    controller state ``ctrl`` are updated in place; the new rotor azimuth is returned.
    """
    n_x = x.shape[0]
    n_r = g_rest_t.shape[0]
    u = np.zeros(N_EX + n_r)
    xn = np.zeros(n_x)
    n_out = 0
    dt = par[P_DT]
    rotor = par[P_ROTOR] > 0.0
    moor_out = np.zeros(12)
    measured_azimuth = blade.shape[1] > N_BLADE_COLUMNS
    for step in range(n_steps):
        k = k0 + step
        if measured_azimuth and blade.shape[0] > k:  # a replay of the rotor's measured azimuth (rad; NaN: none)
            a = blade[k, N_BLADE_COLUMNS]
            if a == a:
                psi = a
        domega = _loads(x, ctrl, k, psi, action, u_ex, vel, blade, strip_z, drag_coef, drag_along, drag_across,
                        drag_dir,
                        moor_gx, moor_gy, moor_gyaw,
                        moor_tab, moor_g0, moor_jac, moor_out, harm, e_s, h_v, r_pitch, tsr_grid, pitch_grid, ct_tab,
                        cq_tab, ctb_tab, cqb_tab, par, u)
        if step % every == 0:
            row = out0 + n_out
            for i in range(n_x):
                x_hist[row, i] = x[i]
            for i in range(n_r):
                u_hist[row, i] = u[N_EX + i]
            n_out += 1
        # xn = exo[k] + phi x + g_rest u, column by column: each xn[r] sums in the same order as a row-wise dot
        # product (so the same bits), while the inner loop over r runs in SIMD lanes
        for r in range(n_x):
            xn[r] = exo[k, r]
        for i in range(n_x):
            xi = x[i]
            for r in range(n_x):
                xn[r] += phi_t[i, r] * xi
        for i in range(n_r):
            ui = u[N_EX + i]
            for r in range(n_x):
                xn[r] += g_rest_t[i, r] * ui
        psi += (harm[3] + x[2 * N_DOF]) * dt
        for i in range(3):  # heave, roll, pitch accelerations over the step, for the next step's CM kinematics
            ctrl[I_ACC + i] = (xn[N_DOF + 2 + i] - x[N_DOF + 2 + i]) / dt
        droll = 0.0  # the nacelle's roll rate about the shaft: its change over the step
        if rotor:
            for i in range(N_DOF):
                droll += r_pitch[2 * N_DOF + i] * (xn[N_DOF + i] - x[N_DOF + i])
        for r in range(n_x):
            x[r] = xn[r]
        if rotor:
            # the rotor speed relative to the nacelle: J Omega' + c (r_s . q'') = Qa - Qg (rotor_free_inertia)
            x[2 * N_DOF] += domega * dt - par[P_SPINC] * droll
            discon_step(discon, ctrl, par[P_NGEAR] * (par[P_OMEGA0] + x[2 * N_DOF]), dt)
    return psi


@numba.njit(cache=True, nogil=True)
def _interp_columns(t, delay, t_field, values, out):
    """``out[:, c] = np.interp(t - delay[c], t_field, values[:, c])`` for every column, with numpy's arithmetic
    (the same interval, the same precomputed slopes and end values; so the same numbers), for increasing ``t``
    and ``t_field``: each column's interval advances with ``t`` instead of being searched for."""
    n_f = t_field.size
    n_c = values.shape[1]
    slopes = np.empty((max(n_f - 1, 0), n_c))
    for j in range(n_f - 1):
        for c in range(n_c):
            slopes[j, c] = (values[j + 1, c] - values[j, c]) / (t_field[j + 1] - t_field[j])
    at = np.zeros(n_c, dtype=np.int64)  # each column's interval, advancing with t
    for i in range(t.size):
        for c in range(n_c):
            xv = t[i] - delay[c]
            if xv <= t_field[0]:
                out[i, c] = values[0, c]
            elif xv >= t_field[n_f - 1]:
                out[i, c] = values[n_f - 1, c]
            else:
                j = at[c]
                while t_field[j + 1] <= xv:
                    j += 1
                at[c] = j
                if xv == t_field[j]:
                    out[i, c] = values[j, c]
                else:
                    out[i, c] = slopes[j, c] * (xv - t_field[j]) + values[j, c]


@numba.njit(cache=True, nogil=True)
def _sensor_noise(y, e_white, white, e_col, col, gain, a, out):
    """``out = y + e_white white + c``, with ``c`` the AR(1) coloured noise ``c[t] = e_col[t] col gain + a c[t-1]``
    (``c[-1] = 0``) of every channel: the arithmetic of ``lfilter([1], [1, -a], e_col * col * gain, axis=0)``, in
    one pass without temporaries."""
    n, m = y.shape
    state = np.zeros(m)
    for t in range(n):
        for c in range(m):
            state[c] = e_col[t, c] * col[c] * gain + a * state[c]
            out[t, c] = (y[t, c] + e_white[t, c] * white[c]) + state[c]


# -------------------------------------------------------------------------------------------- discretised
@dataclass(frozen=True)
class _Discrete:
    phi: np.ndarray
    g_ex0: np.ndarray
    g_ex1: np.ndarray
    g_rest: np.ndarray


def _discretise(sys: LinearSystem, dt: float) -> _Discrete:
    """Exact discretisation: FOH on the exogenous inputs, ZOH on the rest (van Loan's block exponential)."""
    n, m = sys.A.shape[0], sys.B.shape[1]
    big = np.zeros((n + 2 * m, n + 2 * m))
    big[:n, :n] = sys.A * dt
    big[:n, n:n + m] = sys.B * dt
    big[n:n + m, n + m:] = np.eye(m)
    e = sla.expm(big)
    phi = e[:n, :n]
    gam1 = e[:n, n:n + m]  # int_0^T e^{A s} ds B
    gam2 = e[:n, n + m:]  # int_0^T e^{A (T - tau)} tau / T dtau B
    g_ex0 = np.ascontiguousarray(gam1[:, :N_EX] - gam2[:, :N_EX])
    g_ex1 = np.ascontiguousarray(gam2[:, :N_EX])
    return _Discrete(np.ascontiguousarray(phi), g_ex0, g_ex1, np.ascontiguousarray(gam1[:, N_EX:]))


@functools.lru_cache(maxsize=1)
def _steady_thrust_curve() -> tuple[np.ndarray, np.ndarray]:
    """The controlled rotor's steady thrust (N) on a grid of wind speeds (m/s), 3-30 m/s."""
    winds = np.linspace(3.0, 30.0, 109)
    return winds, np.array([operating_point(float(v)).thrust for v in winds])


@functools.lru_cache(maxsize=256)
def turbulent_thrust_ratio(wind_speed: float, turbulence_intensity: float, axial_share: float = 1.0) -> float:
    """Mean thrust of the controlled rotor in turbulent wind over its steady thrust at the mean wind (-).

    The steady thrust curve ``T(v)`` (:func:`surrogates.aero.operating_point`: the controller's steady state at
    each wind) averaged over a Gaussian rotor-effective wind of mean ``V`` and the standard deviation of the
    disc-averaged IEC Kaimal wind (:func:`surrogates.wind.kaimal_spectrum` times the disc's coherence reduction
    :func:`surrogates.wind.rotor_averaging`), both met along the shaft (``axial_share`` = cos of the rotor's
    inclination). The thrust curve peaks at rated wind, so near rated turbulence lowers the mean thrust (0.87 at
    11.7 m/s, TI 0.17) and above and below rated it raises it slightly (1.02): the platform's mean pitch in
    OpenFAST's turbulent 12 m/s run is 4.1 deg, in its steady 12 m/s run 4.8 deg.

    Parameters
    ----------
    wind_speed : float
        Mean hub-height wind (m/s), > 0.
    turbulence_intensity : float
        Longitudinal turbulence intensity (-), >= 0.
    axial_share : float
        Share of the wind met along the shaft (-), in (0, 1].

    Returns
    -------
    float
    """
    v = check_number("wind_speed", wind_speed, positive=True)
    ti = check_number("turbulence_intensity", turbulence_intensity)
    c = check_number("axial_share", axial_share, positive=True)
    if ti <= 0.0:
        return 1.0
    f = np.linspace(5e-4, 2.0, 4000)
    h2, _ = rotor_averaging(f, v)
    sigma = float(np.sqrt(np.trapezoid(kaimal_spectrum(f, v, ti) * h2, f)))
    nodes, weights = np.polynomial.hermite_e.hermegauss(21)
    winds, thrust = _steady_thrust_curve()
    steady = float(np.interp(c * v, winds, thrust))
    mean = float(np.sum(weights * np.interp(c * np.maximum(v + sigma * nodes, 0.0), winds, thrust)) / weights.sum())
    return mean / steady if steady > 0 else 1.0


class Simulator:
    """Everything that does not depend on the seed: discretised system, nonlinear-effect tables, outputs.

    Parameters
    ----------
    model : FOWTModel
    case : int or LoadCase or None
        Load case (None: parked rotor, still water, no wind).
    dt : float
        Output sample time (s), at most :data:`MAX_SAMPLE_TIME`.

    Notes
    -----
    :func:`simulate` is the usual entry point; the Gymnasium environment uses a Simulator to step the model
    in chunks with actions.
    """

    def __init__(self, model: FOWTModel, case: int | LoadCase | None, dt: float = 0.0125) -> None:
        if not isinstance(model, FOWTModel):
            raise ValueError(f"model must be a surrogates.FOWTModel, got {type(model).__name__}")
        dt = check_number("dt", dt, positive=True)
        if dt > MAX_SAMPLE_TIME:
            raise ValueError(
                f"dt={dt} s is too large: sampling must resolve the 2nd tower modes (~2.6 Hz); use dt <= "
                f"{MAX_SAMPLE_TIME} s (the paper's data are at 0.0125 s)"
            )
        self.model = model
        self.case = _as_case(case)
        self.dt = dt
        self.substeps = max(1, math.ceil(dt / MAX_INTERNAL_STEP - 1e-9))
        self.dt_int = dt / self.substeps
        eff = model.effects
        self.nonlinear_rotor = eff["rotor_nonlinear"] > 0
        self.system = model._system(self.case, nonlinear_rotor=self.nonlinear_rotor)
        self.nonlinear_rotor = self.nonlinear_rotor and self.system.op is not None
        # the operating state (mean pitch of the system, equilibrium, controller's steady state, skew gains) is
        # the same for every Simulator of this model and case: the model keeps it, as it keeps its systems
        key = (self.case, self.nonlinear_rotor)
        known = model._operating_states.get(key)
        if known is not None:
            pitch, x_eq, ctrl, skew = known
            if pitch is not None:
                self.system = model._system(self.case, nonlinear_rotor=True, mean_pitch=pitch)
            self._build(state=(x_eq, ctrl, skew))
            return
        self._build()
        pitch = None
        if self.nonlinear_rotor:
            # the pitched platform's terms (fixed-axes hydrodynamics, the tilted yaw's gravity stiffness) at the
            # mean pitch this simulation will hold, not the linear model's (4.2 against 4.9 deg in steady 12 m/s
            # wind: the aligned rotor's operating point) -- OpenFAST's operating yaw mode sits where the mean
            # pitch puts it (0.092 Hz at 4.9 deg without aerodynamics, 0.130 Hz upright)
            pitch = self.mean_operating_pitch()
            if abs(pitch - self.system.mean_pitch) > 1e-4:
                self.system = model._system(self.case, nonlinear_rotor=True, mean_pitch=pitch)
                self._build(warm=(self.x_eq, self.ctrl0))
            else:
                pitch = None
        model._operating_states[key] = (pitch, self.x_eq.copy(), self.ctrl0[:N_CONTROLLER_STATE].copy(),
                                        self.par[[P_SKT, P_SKM, P_SKMB, P_SKMN]].copy())

    def _build(self, warm: tuple[np.ndarray, np.ndarray] | None = None,
               state: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> None:
        """Everything that follows from ``self.system``: the discretisation, the nonlinear tables and parameters,
        the equilibrium and the controller's steady state (its search started from ``warm`` = (state, controller
        state) when given; taken as they are from ``state`` = (equilibrium, controller state, skew gains), a
        previous Simulator's of this model and case)."""
        model = self.model
        eff = model.effects
        disc = _discretise(self.system, self.dt_int)
        self.phi, self.g_ex0, self.g_ex1, self.g_rest = disc.phi, disc.g_ex0, disc.g_ex1, disc.g_rest
        # the stepper reads them column by column (_advance)
        self._phi_t, self._g_rest_t = np.ascontiguousarray(disc.phi.T), np.ascontiguousarray(disc.g_rest.T)
        self.cy = np.ascontiguousarray(self.system.C)
        self._i_roll, self._i_pitch, self._i_yaw = (ALL_CHANNELS.index(c) for c in ("PtfmRoll", "PtfmPitch", "PtfmYaw"))
        self.dy = np.ascontiguousarray(self.system.D)
        st = self.system.structure
        self.drag = self.system.drag if self.system.drag is not None else drag_strips()
        self.strip_z = np.ascontiguousarray(self.drag.z, dtype=float)
        self.drag_arrays = tuple(np.ascontiguousarray(a, dtype=float) for a in (
            self.drag.coef, self.drag.along, self.drag.across, self.drag.direction))
        tab = mooring_table()
        self.moor_grids = tuple(np.ascontiguousarray(g, dtype=float) for g in (tab.grid_dx, tab.grid_dy, tab.grid_yaw))
        self.moor_tab = np.ascontiguousarray(tab.table, dtype=float)
        zf = float(tab.fairlead_z)
        self.moor_g0, self.moor_jac = self._mooring_linearisation(zf)
        self.e_s = np.ascontiguousarray(st.shaft_axis, dtype=float)
        self.h_v = np.ascontiguousarray(st.shaft_axis @ st.hub_translation, dtype=float)
        self.r_pitch = np.ascontiguousarray(np.concatenate([st.tower_top_rotation[1], st.tower_top_rotation[2],
                                                            st.shaft_axis @ st.tower_top_rotation,
                                                            st.hub_translation[1], st.disc_up @ st.hub_translation]),
                                            dtype=float)  # tower-top pitch row, yaw row, about the shaft, then the
        # hub's lateral and up-the-disc translation
        rt = rotor_table()
        bent = blade_deflection_table()
        self.rotor_grids = (np.ascontiguousarray(rt.tsr, dtype=float), np.ascontiguousarray(rt.pitch_rad, dtype=float),
                            np.ascontiguousarray(rt.ct, dtype=float), np.ascontiguousarray(rt.cq, dtype=float),
                            np.ascontiguousarray(bent.ct, dtype=float), np.ascontiguousarray(bent.cq, dtype=float))
        h = model.harmonics
        op = self.system.op
        s3, s1 = eff["rotor_3p"], eff["rotor_1p"]
        self.harm = np.array([
            op.thrust if op else 0.0, op.aero_torque if op else 0.0, st.data.tip_radius,
            self.system.rotor_speed, s3 * h.thrust_3p, s3 * h.thrust_6p, s3 * h.torque_3p, s3 * h.moment_3p,
            s1 * h.thrust_1p, s1 * h.moment_1p, s1 * h.mass_imbalance, s3 * h.yaw_moment_3p,
            s3 * h.side_force_3p * side_force_law(),
            0.0, 0.0,  # the sampled shear's share of the 3P thrust and tilt (set with the nonlinear rotor)
            self.case.wind_speed**2 * op.dQ_dV if op and self.case is not None else 0.0,
        ])
        d = st.data
        par = np.zeros(N_PAR)
        n_by_pitch = 0  # nodes of inclined_rotor_moment_by_pitch (set with the nonlinear rotor)
        par[P_DT] = self.dt_int
        par[P_PHIT] = st.data.blade_flap.thrust_shape
        par[P_SMOOR] = float(eff["mooring_nonlinear"])
        par[P_SDRAG] = float(eff["quadratic_drag"])
        par[P_ZF] = zf
        par[P_ROTOR] = 1.0 if self.nonlinear_rotor else 0.0
        par[P_V0] = self.case.wind_speed if self.case is not None else 0.0
        par[P_OMEGA0] = self.system.rotor_speed
        par[P_J] = st.rotor_inertia_lss
        par[P_NGEAR] = d.gearbox_ratio
        par[P_RADIUS] = rt.radius
        par[P_QAREA] = 0.5 * RHO_AIR * np.pi * rt.radius**2
        par[P_SAERO] = float(eff["aero_damping"])
        par[P_TILT] = d.shaft_tilt_rad
        par[P_JREACT] = d.gearbox_ratio * (d.gearbox_ratio - 1.0) * d.generator_inertia
        par[P_GENEFF] = DISCON["GenEff"]
        if op is not None and self.nonlinear_rotor:
            par[P_SASYM] = float(eff["rotor_asymmetry"])
            par[P_DTDU], par[P_DQDU] = op.dT_dV, op.dQ_dV
            par[P_RT], par[P_RTY] = blade_load_radii(rt.radius)
            par[P_VT], par[P_WT], par[P_VY], par[P_WY] = cyclic_flap_aero_shares(rt.radius)
            # the measured 3P thrust and tilt moment hold the shear's share, which the sampled field carries;
            # (the yaw and side-force harmonics' phases were fitted to this model's response and the torque
            # harmonic is the shaft's, behind the drivetrain: none of them is comparable with a sampled share)
            share = _shear_share()
            self.harm[13] = s3 * par[P_SASYM] * share["thrust_3p"]
            self.harm[14] = s3 * par[P_SASYM] * share["moment_3p"]
            r_node, s_node = blade_inplane_sensitivity(round(self.case.wind_speed, 2))
            par[P_GIP] = float(s_node.sum())
            # the disc's tilt and yaw rates load the in-plane force at its own mean radius, not at r_s
            par[P_RS] = BLADE_SAMPLING_RADIUS * rt.radius
            par[P_RIP] = float(np.sum(s_node * r_node) / s_node.sum()) / par[P_RS]
            par[P_FIP] = float(np.sum(s_node * d.blade_flap.shape(r_node)) / s_node.sum())
            par[P_SPINC] = rotor_free_inertia(st)[0] / st.rotor_inertia_lss
            par[P_SSKEW] = float(eff["rotor_skew"])
            par[P_SCURV] = float(eff["sampled_wind_curvature"])
            par[P_INCF0], par[P_INCF1] = inclined_rotor_inplane(self.case.wind_speed)
            par[P_SKF], par[P_SKF1], par[P_SKC0], par[P_SKC1] = inplane_wind_loads(self.case.wind_speed)
            par[P_LAGC], par[P_LAGS] = math.cos(DISC_RATE_LAG), math.sin(DISC_RATE_LAG)
            beta_k, k_beta = inclined_rotor_moment_by_pitch()
            n_by_pitch = beta_k.size
            par[P_SKM_PITCH:P_SKM_PITCH + beta_k.size] = beta_k
            par[P_SKM_K:P_SKM_K + beta_k.size] = k_beta
        if op is not None and self.nonlinear_rotor:
            par[P_SBEND] = float(eff["blade_deflection"])
            par[P_DBEND] = bent.tip_deflection
        self.par = par
        self.discon = np.ascontiguousarray(DISCON_PARAMS, dtype=float)
        par[P_SKIN] = float(eff["cm_kinematics"])
        par[P_MZG] = float(st.mass[0, 4] - d.added_mass[0, 4])  # the structure's first mass moment M z_G (kg m)
        self.ctrl0 = np.zeros(N_CARRIED)  # controller state, then the previous step's accelerations (I_ACC)
        if op is not None:
            self.ctrl0[:N_CONTROLLER_STATE] = initial_controller_state(d.gearbox_ratio * op.rotor_speed, op.pitch)
        self.mean_shear = np.zeros(2)
        if self.case is not None and self.case.wind_speed > 0:
            self.mean_shear[1] = mean_shear_z(self.case.wind_speed)
        if state is not None:
            self.x_eq = np.array(state[0], dtype=float)
            self.ctrl0[:N_CONTROLLER_STATE] = state[1]
            par[[P_SKT, P_SKM, P_SKMB, P_SKMN]] = state[2]
            return
        if warm is not None and op is not None:
            self.ctrl0[:N_CONTROLLER_STATE] = warm[1][:N_CONTROLLER_STATE]
        self.x_eq = self._equilibrium(None if warm is None else warm[0])
        if par[P_SSKEW] > 0.0:  # the skew gains at the inclination the equilibrium holds, then its share in it
            theta0 = float(st.tower_top_rotation[1] @ self.x_eq[:N_DOF])
            par[P_SKT] = skew_gains(self.case.wind_speed, theta0 - d.shaft_tilt_rad)[0]
            # the moment from AeroDyn (skewed wake, cone), at the equilibrium's flap deflection
            m0, m1 = inclined_rotor_moment(self.case.wind_speed)
            par[P_SKM] = m0 + float(eff["blade_deflection"]) * m1 * float(self.x_eq[FLAP])
            # the pitch-indexed moment (its nodes set above), relative to the equilibrium's pitch; read by the
            # kernel's own interpolation, then again at the pitch of the equilibrium found with it (~0.01 deg on)
            par[P_SKMN] = n_by_pitch
            if n_by_pitch > 1:
                par[P_SKMB] = _by_pitch(par, n_by_pitch, float(self.ctrl0[2]))
            self.x_eq = self._equilibrium(self.x_eq)
            if n_by_pitch > 1:
                par[P_SKMB] = _by_pitch(par, n_by_pitch, float(self.ctrl0[2]))

    def mean_operating_pitch(self) -> float:
        """Mean platform pitch (rad) of a simulation of this load case: the equilibrium's (the controller's steady
        state with the simulation's rotor) in steady wind; in turbulent wind the parked pitch plus the thrust's
        share of the equilibrium's, times :func:`turbulent_thrust_ratio` (the pitch follows the mean thrust).
        Against the simulations' own means (8 seeds, OpenFAST's shared runs' conditions): 2.68 / 2.63 deg at
        8.2 m/s, 4.33 / 4.07 at 11.7 m/s, 2.83 / 2.77 at 17.8 m/s, 4.89 / 4.75 in steady 12 m/s wind with waves."""
        pitch = float(self.x_eq[4])
        lc = self.case
        if lc is None or lc.wind_speed <= 0 or lc.turbulence_intensity <= 0:
            return pitch
        rest = float(self.model._system(None, nonlinear_rotor=False).mean_pitch)
        st = self.system.structure
        chi = float(st.tower_top_rotation[1] @ self.x_eq[:N_DOF]) - st.data.shaft_tilt_rad
        ratio = turbulent_thrust_ratio(round(float(lc.wind_speed), 4), round(float(lc.turbulence_intensity), 5),
                                       round(math.cos(chi), 5))
        return rest + (pitch - rest) * ratio

    # ------------------------------------------------------------------------------------------ helpers
    def _mooring_linearisation(self, zf: float) -> tuple[np.ndarray, np.ndarray]:
        """Generalised mooring load at zero offset and its Jacobian (central differences on the same table)."""
        out = np.zeros(12)
        gx, gy, gyaw = self.moor_grids

        def g(q6: np.ndarray) -> np.ndarray:
            x = np.zeros(N_STATE)
            x[:6] = q6
            _mooring_generalised(x, gx, gy, gyaw, self.moor_tab, zf, out)
            return out[6:12].copy()

        g0 = g(np.zeros(6))
        jac = np.zeros((6, 6))
        for j, hstep in enumerate((0.5, 0.5, 0.0, 0.005, 0.005, 0.01)):
            if hstep == 0.0:
                continue
            e = np.zeros(6)
            e[j] = hstep
            jac[:, j] = (g(e) - g(-e)) / (2 * hstep)
        return g0, np.ascontiguousarray(-jac)

    def loads(self, x: np.ndarray, k: int, psi: float, action: np.ndarray, u_ex: np.ndarray, vel: np.ndarray,
              ctrl: np.ndarray, blade: np.ndarray | None = None) -> tuple[np.ndarray, float]:
        """Per-step inputs ``u`` (N_INPUT,) and rotor acceleration at state ``x`` and forcing sample ``k``."""
        u = np.zeros(N_INPUT)
        if blade is None:
            blade = np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
        domega = _loads(x, ctrl, k, psi, np.asarray(action, float), u_ex, vel, blade, self.strip_z,
                        *self.drag_arrays,
                        *self.moor_grids, self.moor_tab, self.moor_g0, self.moor_jac, np.zeros(12), self.harm,
                        self.e_s, self.h_v, self.r_pitch, *self.rotor_grids, self.par, u)
        return u, domega

    def _equilibrium(self, x0: np.ndarray | None = None) -> np.ndarray:
        """Static equilibrium under the mean loads, the mean rotor loads and the static nonlinear forces.

        With the nonlinear rotor the controller's steady state is solved with it: the blade pitch (above rated) or
        the rotor speed (below rated) at which the rotor's aerodynamic torque -- at the equilibrium's inclination,
        flap deflection and sampled shear, as the simulation's rotor meets them -- balances the torque law
        (:func:`surrogates.controller.steady_state`), alternating with the structure's equilibrium under the
        loads of that state until both hold. The load case's operating point (``system.op``) is the aligned,
        straight-bladed rotor's: at 12 m/s its pitch is 3.1 deg and its thrust 601 kN, while the rotor tilted 10 deg
        by the shaft and the platform's pitch, with bent blades, settles at 0.97 deg and takes more thrust,
        so that a simulation started from the operating point's equilibrium drifts 0.6 deg in pitch and a few
        metres in surge during its first minutes (OpenFAST's steady 12 m/s run: pitch 4.8 deg, blade pitch 1.3
        deg). ``self.ctrl0`` is set to that steady state (the DLL's state on a first call at that speed and pitch).
        """
        inputs = self._equilibrium_inputs()
        x = self._structural_equilibrium(inputs, np.zeros(N_STATE) if x0 is None else x0)
        if not (self.nonlinear_rotor and self.system.op is not None and self.case is not None):
            return x
        n_gear = float(self.par[P_NGEAR])
        omega0 = float(self.system.rotor_speed)
        state = (omega0 + float(x[2 * N_DOF]), float(self.ctrl0[2]))
        for _ in range(12):
            ss = steady_state(functools.partial(self._aero_torque_at, inputs, x.copy()),
                              float(self.case.wind_speed), n_gear)
            self.ctrl0[:N_CONTROLLER_STATE] = initial_controller_state(n_gear * ss.rotor_speed, ss.pitch)
            x[2 * N_DOF] = ss.rotor_speed - omega0
            done = abs(ss.rotor_speed - state[0]) < 1e-7 and abs(ss.pitch - state[1]) < 1e-7
            # the structure to the final tolerance once the controller's state has settled
            x = self._structural_equilibrium(inputs, x, tol=1e-10 if done else 1e-6)
            state = (ss.rotor_speed, ss.pitch)
            if done:
                break
        return x

    def _equilibrium_inputs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The steady inputs of :meth:`_equilibrium`: exogenous sample, strip velocities, blade winds, azimuths."""
        u_ex = np.zeros((1, N_EX))
        u_ex[0, 0] = 1.0
        if self.case is not None:
            u_ex[0, INPUT_BLOCKS["hub_wind"].start] = self.case.wind_speed
        u_ex[0, INPUT_BLOCKS["shear"]] = self.mean_shear
        vel = np.zeros((1, self.strip_z.size, 2))
        # the blades sample the mean sheared wind as they will in the simulation (its mean tilt and yaw moments and
        # side force: the rotor's asymmetric loads), averaged over a third of a turn (the three blades' period)
        blade = self._steady_blade_wind()
        psis = np.linspace(0.0, 2.0 * np.pi / 3.0, 8, endpoint=False) if blade.shape[0] else np.zeros(1)
        return u_ex, vel, blade, psis

    @contextlib.contextmanager
    def _mean_harmonics(self):
        """Within: the rotor harmonics' mean term zeroed (the equilibrium's loads are the mean loads)."""
        harm = self.harm
        self.harm = harm.copy()
        self.harm[0] = 0.0
        try:
            yield
        finally:
            self.harm = harm

    def _aero_torque_at(self, inputs: tuple, x: np.ndarray, _wind: float, omega: float, pitch: float) -> float:
        """The rotor's aerodynamic torque (N m, LSS) at state ``x`` with rotor speed ``omega`` (rad/s) and blade
        pitch ``pitch`` (rad), averaged over the azimuths of ``inputs`` (no generator torque: J domega); in the
        signature of :func:`surrogates.controller.steady_state` (the wind is the case's, in ``inputs``)."""
        u_ex, vel, blade, psis = inputs
        xx = x.copy()
        xx[2 * N_DOF] = omega - float(self.system.rotor_speed)
        ctrl = self.ctrl0.copy()
        ctrl[0] = float(self.par[P_NGEAR]) * omega
        ctrl[2] = pitch
        ctrl[3] = 0.0
        with self._mean_harmonics():
            domega = np.mean([self.loads(xx, 0, float(p), np.zeros(2), u_ex, vel, ctrl, blade)[1] for p in psis])
        return float(self.par[P_J] * domega)

    def _structural_equilibrium(self, inputs: tuple, x0: np.ndarray, tol: float = 1e-10) -> np.ndarray:
        """The DOFs' static equilibrium (rates zero) under the loads at the controller state ``self.ctrl0``,
        from ``x0`` (its rotor-speed state kept), to a relative change of ``tol`` per iteration."""
        u_ex, vel, blade, psis = inputs
        a_qq = self.system.A[N_DOF:2 * N_DOF, :N_DOF]
        b_c = self.system.B[N_DOF:2 * N_DOF, 0]
        b_rest = self.system.B[N_DOF:2 * N_DOF, N_EX:]
        b_ex = self.system.B[N_DOF:2 * N_DOF, 1:N_EX]
        x = np.array(x0, dtype=float)
        x[N_DOF:2 * N_DOF] = 0.0
        with self._mean_harmonics():  # the mean of the harmonics is zero
            for _ in range(300):
                u = np.mean([self.loads(x, 0, float(p), np.zeros(2), u_ex, vel, self.ctrl0.copy(), blade)[0]
                             for p in psis], axis=0)
                q_new = -np.linalg.solve(a_qq, b_c + b_ex @ u_ex[0, 1:] + b_rest @ u[N_EX:])
                done = np.max(np.abs(q_new - x[:N_DOF])) < tol * (1.0 + np.max(np.abs(q_new)))
                x[:N_DOF] = 0.5 * (x[:N_DOF] + q_new)
                if done:
                    break
        return x

    def _steady_blade_wind(self) -> np.ndarray:
        """The blade-effective winds (1, N_BLADE_COLUMNS) of the case's mean sheared wind, as :meth:`forcing` builds
        them from a field; empty when the rotor does not sample a field (no wind)."""
        lc = self.case
        if lc is None or lc.wind_speed <= 0:
            return np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
        wd = synthesize_rotor_wind(lc.wind_speed, 0.0, 2 * FIELD_DT, FIELD_DT, seed=0, n_azimuth=FIELD_AZIMUTH,
                                   return_field=True, grid_spacing=FIELD_GRID_SPACING)
        return np.ascontiguousarray(_blade_wind_columns(wd, lc.wind_speed)[:1], dtype=np.float32)

    def initial_state(self, initial: Mapping[str, float] | None) -> tuple[np.ndarray, np.ndarray]:
        """State and controller state to start from: the equilibrium, with ``initial`` (OpenFAST channel name ->
        value in OpenFAST units) overriding platform DOFs and their rates (``PtfmTVxi`` ... ``PtfmRVzi``), tower-top
        deflections, the rotor speed, and the controller's pitch (``BldPitch1``, deg) and generator torque
        (``GenTq``, kN·m): with these the controller starts where a record's was (its integrator consistent with
        that pitch at that speed, :func:`surrogates.controller.initial_controller_state`), not from its steady
        state -- a replay's rotor speed, and with it the azimuth, then follows the record's from the start."""
        x = self.x_eq.copy()
        ctrl = self.ctrl0.copy()
        if not initial:
            return x, ctrl
        st = self.system.structure
        t_top = st.point_translation(st.data.tower_top_height)
        for name, value in dict(initial).items():
            v = check_number(f"initial[{name!r}]", value)
            if name in _PLATFORM_DOF:
                i = _PLATFORM_DOF[name]
                x[i] = v if i < 3 else np.deg2rad(v)
            elif name in _PLATFORM_RATE:
                i = _PLATFORM_RATE[name]
                x[N_DOF + i] = v if i < 3 else np.deg2rad(v)
            elif name in ("TTDspFA", "TTDspSS"):
                mode = 6 if name == "TTDspFA" else 8
                axis = 0 if name == "TTDspFA" else 1
                x[mode] = (v - t_top[axis, 6:N_DOF] @ x[6:N_DOF] + t_top[axis, mode] * x[mode]) / t_top[axis, mode]
            elif name == "RotSpeed":
                if not self.system.op:
                    raise ValueError("initial: RotSpeed needs an operating load case (the rotor is parked)")
                x[2 * N_DOF] = v * np.pi / 30.0 - self.system.rotor_speed
                ctrl[0] = st.data.gearbox_ratio * v * np.pi / 30.0
            elif name in ("BldPitch1", "GenTq"):
                if not self.system.op:
                    raise ValueError(f"initial: {name} needs an operating load case (the rotor is parked)")
            else:
                raise ValueError(f"initial: unknown channel {name!r}; known: {sorted(_INITIAL_CHANNELS)}")
        # ElastoDyn's roll and yaw are Euler angles and its rotational velocities fixed-axes components; the
        # model's roll and yaw turn about the platform's own, pitched axes (elastodyn_platform_angles)
        # (a channel not given keeps its equilibrium value in ElastoDyn's terms)
        pitch = float(x[4])
        p_eq = float(self.x_eq[4])
        if "PtfmRoll" in initial or "PtfmYaw" in initial:
            r_eq, y_eq = float(self.x_eq[3]), float(self.x_eq[5])
            roll_ed = np.deg2rad(float(initial["PtfmRoll"])) if "PtfmRoll" in initial else r_eq + math.tan(p_eq) * y_eq
            yaw_ed = np.deg2rad(float(initial["PtfmYaw"])) if "PtfmYaw" in initial else y_eq / math.cos(p_eq)
            x[3], x[5] = body_platform_angles(float(roll_ed), pitch, float(yaw_ed))
        if "PtfmRVxi" in initial or "PtfmRVzi" in initial:
            c, s = math.cos(pitch), math.sin(pitch)
            wr, wy = self.x_eq[N_DOF + 3], self.x_eq[N_DOF + 5]
            wx = np.deg2rad(float(initial["PtfmRVxi"])) if "PtfmRVxi" in initial else c * wr + s * wy
            wz = np.deg2rad(float(initial["PtfmRVzi"])) if "PtfmRVzi" in initial else -s * wr + c * wy
            x[N_DOF + 3], x[N_DOF + 5] = c * wx - s * wz, s * wx + c * wz
        if self.system.op and ("BldPitch1" in initial or "GenTq" in initial):
            pitch = np.deg2rad(float(initial["BldPitch1"])) if "BldPitch1" in initial else float(ctrl[2])
            torque = 1e3 * float(initial["GenTq"]) if "GenTq" in initial else None
            ctrl[:N_CONTROLLER_STATE] = initial_controller_state(float(ctrl[0]), pitch, torque)
        return x, ctrl

    def advance(self, x: np.ndarray, ctrl: np.ndarray, psi: float, k0: int, n_steps: int, every: int,
                exo: np.ndarray, u_ex: np.ndarray, action: np.ndarray, vel: np.ndarray, blade: np.ndarray,
                x_hist: np.ndarray, u_hist: np.ndarray, out0: int) -> float:
        """Run the compiled stepper (``x`` and ``ctrl`` in place); returns the new rotor azimuth (rad)."""
        return _advance(x, ctrl, psi, k0, n_steps, every, self._phi_t, self._g_rest_t, exo, u_ex, action, vel, blade,
                        self.strip_z, *self.drag_arrays, *self.moor_grids, self.moor_tab, self.moor_g0, self.moor_jac,
                        self.harm, self.e_s, self.h_v, self.r_pitch, *self.rotor_grids, self.discon, self.par,
                        x_hist, u_hist, out0)

    def blade_sampling_delay(self, mean_speed: float | None = None) -> np.ndarray:
        """Delay (s) with which the blade at each of the ``N_BLADE_AZIMUTH`` azimuths meets the turbulence that
        crosses the rotor centre.

        The disc is tilted by the shaft tilt plus the equilibrium pitch of the tower top (~9-10 deg at rated):
        its upper half sits downwind of the centre and its lower half upwind, by ``r cos(psi) sin(chi)``, and a
        frozen field advected at the mean speed ``U`` reaches each point that much later or earlier. At the
        radius of the radius-weighted blade wind (``BLADE_SAMPLING_RADIUS``, 0.75 R) that is +-0.7 s at 12 m/s:
        OpenFAST's InflowWind samples the field at each blade node's own position, so the rotationally sampled
        turbulence must see the same delays.

        Parameters
        ----------
        mean_speed : float, optional
            Advection speed (m/s); default the load case's mean wind speed.

        Returns
        -------
        ndarray (N_BLADE_AZIMUTH,)
            Delays (s) at azimuths ``j 2 pi / N`` from the top towards +y; zeros without wind.
        """
        speed = self.case.wind_speed if mean_speed is None and self.case is not None else mean_speed
        if speed is None or not speed > 0.1:
            return np.zeros(N_BLADE_AZIMUTH)
        st = self.system.structure
        chi = float(st.tower_top_rotation[1] @ self.x_eq[:N_DOF]) - st.data.shaft_tilt_rad  # nose-up tilt (rad)
        psi = np.arange(N_BLADE_AZIMUTH) * 2.0 * np.pi / N_BLADE_AZIMUTH
        return BLADE_SAMPLING_RADIUS * st.data.tip_radius * np.cos(psi) * np.sin(chi) / float(speed)

    def forcing(self, n_steps: int, seed_sequence: np.random.SeedSequence,
                hub_wind: tuple[np.ndarray, np.ndarray] | None = None,
                ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
        """Exogenous inputs for ``n_steps`` internal steps (+1 sample for the hold), strip velocities, initial
        rotor azimuth, and the blade-effective wind around the rotor (``(n, n_azimuth)`` float32: the turbulent
        field over the disc averaged along a blade with weights proportional to the radius, at azimuths
        measured from the top towards +y; empty without turbulent wind). ``hub_wind`` = ``(t, u)`` (s from the
        start of the simulation, m/s) conditions the turbulent field on that hub-height series
        (:func:`surrogates.wind.constrain_to_hub`)."""
        wave_ss, wind_ss, psi_ss = seed_sequence.spawn(3)
        n = n_steps + 1
        duration = n * self.dt_int
        u_ex = np.zeros((n, N_EX))
        u_ex[:, 0] = 1.0
        vel = np.zeros((n, self.strip_z.size, 2))
        lc = self.case
        if lc is not None and lc.hs > 0:
            w = synthesize_waves(lc.hs, lc.tp, lc.gamma, lc.wave_dir_deg, duration, self.dt_int,
                                 seed=int(wave_ss.generate_state(1)[0]), n_strips=N_STRIPS)
            u_ex[:, INPUT_BLOCKS["wave"]] = w.excitation[:n] + self.drag.excitation(w.velocity[:n])
            u_ex[:, INPUT_BLOCKS["elev"].start] = w.elevation[:n]
            vel = np.ascontiguousarray(w.velocity[:n])
        blade = np.zeros((0, N_BLADE_COLUMNS), dtype=np.float32)
        if lc is not None and lc.wind_speed > 0:
            # the field at FIELD_DT (its content above ~2 Hz is negligible), interpolated to the internal step
            wd = synthesize_rotor_wind(lc.wind_speed, lc.turbulence_intensity, duration + 2 * FIELD_DT, FIELD_DT,
                                       seed=int(wind_ss.generate_state(1)[0]), n_azimuth=FIELD_AZIMUTH,
                                       return_field=True, grid_spacing=FIELD_GRID_SPACING)
            if hub_wind is not None and lc.turbulence_intensity > 0:
                wd = constrain_to_hub(wd, hub_wind[0], hub_wind[1])
            t = np.arange(n) * self.dt_int
            u_ex[:, INPUT_BLOCKS["wind"].start] = np.interp(t, wd.t, wd.rotor_effective) - lc.wind_speed
            u_ex[:, INPUT_BLOCKS["hub_wind"].start] = np.interp(t, wd.t, wd.hub)
            u_ex[:, INPUT_BLOCKS["shear"].start] = np.interp(t, wd.t, wd.shear_y)
            u_ex[:, INPUT_BLOCKS["shear"].start + 1] = np.interp(t, wd.t, wd.shear_z)
            on_blade = _blade_wind_columns(wd, lc.wind_speed)
            # each azimuth meets the frozen field with its own delay (the disc is tilted: blade_sampling_delay)
            delay = np.tile(self.blade_sampling_delay(), 2)
            t_field = np.arange(on_blade.shape[0]) * FIELD_DT
            blade = np.empty((n, on_blade.shape[1]), dtype=np.float32)
            _interp_columns(t, delay, t_field, np.ascontiguousarray(on_blade, dtype=float), blade)
        psi0 = float(np.random.default_rng(psi_ss).uniform(0.0, 2.0 * np.pi))
        return np.ascontiguousarray(u_ex), vel, psi0, np.ascontiguousarray(blade)

    def exogenous(self, u_ex: np.ndarray) -> np.ndarray:
        """Contribution of the exogenous inputs (first-order hold) to each next state, shape (n_steps, N_STATE)."""
        exo = u_ex[:-1] @ self.g_ex0.T  # then added in place: the same sums as one expression
        exo += u_ex[1:] @ self.g_ex1.T
        return np.ascontiguousarray(exo)

    def outputs(self, x_hist: np.ndarray, u_ex_out: np.ndarray, u_hist: np.ndarray) -> np.ndarray:
        """Channel values ``C x + D u`` from stored states and inputs (n, 55), with ``PtfmRoll`` and ``PtfmYaw`` as
        ElastoDyn reports them (:func:`elastodyn_platform_angles`)."""
        y = x_hist @ self.cy.T  # then added in place: the same sums as one expression, without its temporaries
        y += u_ex_out @ self.dy[:, :N_EX].T
        y += u_hist @ self.dy[:, N_EX:].T
        elastodyn_platform_angles(y, self._i_roll, self._i_pitch, self._i_yaw, self.system.mean_pitch)
        return y

    def add_noise(self, y: np.ndarray, seed_sequence: np.random.SeedSequence) -> np.ndarray:
        """Add white + AR(1) coloured sensor noise (model.noise) to outputs ``y`` (n, 55)."""
        white, col = self.model.noise.std(list(ALL_CHANNELS))
        if not np.any(white) and not np.any(col):
            return y
        rng = np.random.default_rng(seed_sequence)
        e_white = rng.standard_normal(y.shape)
        if not np.any(col):
            return y + e_white * white
        a = math.exp(-self.dt / max(self.model.noise.correlation_time, 1e-9))
        e_col = rng.standard_normal(y.shape)
        out = np.empty(y.shape)
        _sensor_noise(np.ascontiguousarray(y, dtype=float), e_white, np.asarray(white, dtype=float), e_col,
                      np.asarray(col, dtype=float), math.sqrt(1.0 - a * a), a, out)
        return out


def _hub_wind_series(hub_wind: object, sim: Simulator, replayed_wind: bool) -> tuple[np.ndarray, np.ndarray]:
    """``simulate(hub_wind=...)`` as ``(t, u)`` with ``t`` from 0 at the series' first sample (s, m/s)."""
    if replayed_wind:
        raise ValueError("hub_wind conditions the synthesised turbulence; wind= replays a measured wind instead: "
                         "give one of them")
    lc = sim.case
    if lc is None or not (lc.wind_speed > 0 and lc.turbulence_intensity > 0):
        raise ValueError("hub_wind conditions the synthesised turbulence: the case needs wind_speed > 0 and "
                         "turbulence_intensity > 0 (the level of the field's random rest)")
    if isinstance(hub_wind, Record):
        if "Wind1VelX" not in hub_wind.channels:
            raise ValueError("hub_wind: the record has no Wind1VelX channel")
        t, u = hub_wind.t, hub_wind["Wind1VelX"]
    elif isinstance(hub_wind, tuple | list) and len(hub_wind) == 2:
        t, u = hub_wind
    else:
        raise ValueError(f"hub_wind must be a Record with Wind1VelX or a (t, u) pair, got {type(hub_wind).__name__}")
    t, u = hub_series(t, u, "hub_wind (t, u)")
    return t - t[0], u


def simulate(
    model: FOWTModel,
    case: int | LoadCase | None,
    duration: float | None = None,
    dt: float = 0.0125,
    seed: int | Sequence[int] = 0,
    *,
    transient: float = 60.0,
    noise: bool = True,
    return_truth: bool = False,
    initial: Mapping[str, float] | None = None,
    waves: object = None,
    wind: object = None,
    azimuth: object = None,
    hub_wind: object = None,
    on_progress: Callable[[float], None] | None = None,
) -> Record | list[Record]:
    """Simulate the surrogate under a load case and return its 45 sensor channels.

    Parameters
    ----------
    model : FOWTModel
        The model (its effects, rotor harmonics and sensor noise).
    case : int or LoadCase or None
        OLC number (1-12), a :class:`LoadCase`, or None (parked, still water, no wind).
    duration : float or None
        Length of the returned record (s); None: 600 s, or with replayed inputs everything they cover after the
        transient.
    dt : float
        Sample time (s); default 0.0125 s (80 Hz, as the paper's data).
    seed : int or sequence of int
        Seed of waves, wind, rotor azimuth and noise. A sequence simulates one record per seed (in parallel
        threads on all cores) and returns a list; each record equals the single-seed run bit for bit.
    transient : float
        Simulated time discarded before the record starts (s), so that the start-up from the static
        equilibrium has decayed.
    noise : bool
        Add the model's sensor noise (:class:`surrogates.SensorNoise`).
    return_truth : bool
        If True, return ``(noisy, truth)`` pairs: the noise-free record alongside (a list of pairs for a batch).
    initial : mapping, optional
        Initial conditions for a free decay or a start-up, OpenFAST channel name -> value in OpenFAST units:
        ``PtfmSurge``, ``PtfmSway``, ``PtfmHeave`` (m), ``PtfmRoll``, ``PtfmPitch``, ``PtfmYaw`` (deg),
        ``TTDspFA``, ``TTDspSS`` (m, set through the first tower mode of that plane), ``RotSpeed`` (rpm) and
        ``Azimuth`` (deg, blade 1 up = 0, increasing clockwise looking downwind, as OpenFAST's; default drawn
        from the seed).
        Unnamed states start at the static equilibrium. Use ``transient=0`` to record from the release, e.g.
        ``simulate(model, None, 300, initial={"PtfmPitch": 5.0}, transient=0)``.
    waves : MeasuredWaves, Record or (t, elevation), optional
        Replay a measured wave elevation (m, at the spar axis; a record's ``Wave1Elev``) instead of the JONSWAP
        draw, see :mod:`surrogates.replay`. The case's ``hs``/``tp`` still set the drag linearisation.
    wind : MeasuredWind, Record or (t, hub wind), optional
        Replay a measured wind (hub series, rotor-effective series or polar field; a record's ``Wind1VelX`` is a
        hub series) instead of the turbulence draw; the case's ``wind_speed`` is the linearisation point (use
        the measured mean). With replayed inputs the simulation starts at the latest start of their time axes
        and the returned record's time stamps are theirs (``transient`` later).
    azimuth : Record or (t, deg), optional
        With ``waves``/``wind``: the rotor's measured azimuth (a record's ``Azimuth``, deg, OpenFAST's
        convention), which then places the blades in the turbulent field and sets the phase of the 3P/6P loads
        at every step instead of the azimuth integrated from the simulated rotor speed (outside its time span
        the simulated one continues). The rotationally sampled loads are phase-locked to the blades: a rotor
        speed 0.1 % off shifts their 3P phase by ~90° within ten minutes, so a twin replays the measured azimuth
        as it replays the measured wind. The rotor speed stays the simulation's own.
    hub_wind : Record or (t, u), optional
        Condition the synthesised turbulence on a measured hub-height wind (a record's ``Wind1VelX``, a met
        mast's or nacelle anemometer's series; m/s): the field is drawn from the IEC model *given* that series
        (:func:`surrogates.wind.constrain_to_hub`), so the record's ``Wind1VelX`` follows it and its slow gusts
        load the rotor, while the rest of the rotor plane stays random (the seed). Its first sample is placed at
        the returned record's first (after ``transient``); the constraint fades in over the last 20 s of the
        transient and out after the series ends. Only its fluctuation is used: the case's ``wind_speed`` is the
        mean (give the series' mean). Needs a turbulent case (``wind_speed`` and ``turbulence_intensity`` > 0,
        the level of the random rest); not with ``wind=``.
    on_progress : callable, optional
        A progress bar's hook: called with the simulated seconds (transient included) just integrated, about
        every 1 % of each seed's run; ``(duration + transient) * n_seeds`` seconds in all. With several seeds it
        is called from their threads. The record is the same bit for bit with or without it.

    Returns
    -------
    Record or list of Record
        Channels :data:`surrogates.channels.ALL_CHANNELS` in OpenFAST units; ``meta`` holds the load case,
        seed, dt, effects and model settings.

    Raises
    ------
    ValueError
        Non-positive or non-finite duration/dt/transient, dt too large, a bad case or model.
    """
    if not np.isfinite(transient) or transient < 0:
        raise ValueError(f"transient must be finite and >= 0 (s), got {transient!r}")
    replay = waves is not None or wind is not None
    if azimuth is not None and not replay:
        raise ValueError("azimuth replays a measured rotor azimuth alongside measured waves or wind (waves=, wind=)")
    if replay:
        from .replay import (
            advection_delay,
            as_measured_waves,
            as_measured_wind,
            measured_azimuth,
            replay_forcing,
            replay_meta,
            replay_window,
            with_measured_azimuth,
        )

        waves = None if waves is None else as_measured_waves(waves)
        wind = None if wind is None else as_measured_wind(wind)
        az_series = None if azimuth is None else measured_azimuth(azimuth)
        if duration is not None:
            duration = check_number("duration", duration, positive=True)
        t_start, duration = replay_window(waves, wind, duration, transient, dt)
    duration = check_number("duration", 600.0 if duration is None else duration, positive=True)
    batch = not np.isscalar(seed)
    seeds = [int(s) for s in (seed if batch else [seed])]  # type: ignore[union-attr]
    if any(s < 0 for s in seeds):
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    sim = Simulator(model, case, dt)
    hub_track = None if hub_wind is None else _hub_wind_series(hub_wind, sim, wind is not None)
    n_out = int(round(duration / sim.dt))
    if n_out < 2:
        raise ValueError(f"duration={duration} s is shorter than two samples of dt={sim.dt} s")
    n_skip = int(round(transient / sim.dt))
    n_steps = (n_out + n_skip) * sim.substeps
    seqs = [np.random.SeedSequence(s) for s in seeds]
    children = [sq.spawn(2) for sq in seqs]  # forcing, noise
    n_rec = n_out + n_skip
    out_steps = np.arange(n_skip, n_rec) * sim.substeps

    initial = dict(initial) if initial else None
    psi_start = None
    if initial and "Azimuth" in initial:  # the rotor's azimuth is not a state of x: it seeds the stepper
        psi_start = math.radians(check_number("initial['Azimuth']", initial["Azimuth"]))
    x_start, ctrl_start = sim.initial_state({k: v for k, v in initial.items() if k != "Azimuth"} if initial else None)

    # the hub series on the simulation's clock: its first sample at the record's first, after the transient
    hub_sim = None if hub_track is None else (hub_track[0] + n_skip * sim.dt, hub_track[1])

    def run_one(forcing_seq: np.random.SeedSequence) -> np.ndarray:
        if replay:
            u_ex, vel, psi0, blade = replay_forcing(sim, n_steps, t_start, waves, wind, forcing_seq)
            if az_series is not None:
                blade = with_measured_azimuth(blade, t_start + np.arange(n_steps + 1) * sim.dt_int, *az_series)
        else:
            u_ex, vel, psi0, blade = sim.forcing(n_steps, forcing_seq, hub_sim)
        if psi_start is not None:
            psi0 = psi_start
        x, ctrl = x_start.copy(), ctrl_start.copy()
        x_hist = np.zeros((n_rec, N_STATE))
        u_hist = np.zeros((n_rec, N_INPUT - N_EX))
        exo, action = sim.exogenous(u_ex), np.zeros(2)
        # in chunks of whole output samples when someone watches (the stepper resumes exactly where it stopped)
        chunk = n_steps if on_progress is None else sim.substeps * max(1, n_rec // 100)
        for k0 in range(0, n_steps, chunk):
            n = min(chunk, n_steps - k0)
            psi0 = sim.advance(x, ctrl, psi0, k0, n, sim.substeps, exo, u_ex, action, vel, blade, x_hist, u_hist,
                               k0 // sim.substeps)
            if on_progress is not None:
                on_progress(n * sim.dt_int)
        return sim.outputs(x_hist[n_skip:], u_ex[out_steps], u_hist[n_skip:])

    def run_and_noise(ch: list[np.random.SeedSequence]) -> tuple[np.ndarray, np.ndarray]:
        truth = run_one(ch[0])
        return truth, (sim.add_noise(truth, ch[1]) if noise else truth)

    # FFT synthesis, the compiled stepper (nogil) and BLAS all release the GIL: a batch runs on threads, each seed's
    # sensor noise drawn in its own thread from its own seed
    if len(seeds) == 1:
        y_outs = [run_and_noise(children[0])]
    else:
        with ThreadPoolExecutor(max_workers=min(len(seeds), os.cpu_count() or 1)) as pool:
            y_outs = list(pool.map(run_and_noise, children))
    lc = sim.case
    t = np.arange(n_out) * sim.dt
    if replay:
        t = t + (t_start + n_skip * sim.dt)
    out: list = []
    for s, (truth, noisy) in zip(seeds, y_outs, strict=True):
        if not np.all(np.isfinite(truth)):
            raise FloatingPointError("simulation diverged (non-finite outputs); please report this case and seed")
        meta = {
            "source": "surrogates.simulate",
            "case": lc.to_dict() if lc is not None else None,
            "seed": s,
            "dt": sim.dt,
            "transient": float(transient),
            "model": model.to_dict(),
            "noise": bool(noise),
            "initial": dict(initial) if initial else None,
        }
        if hub_track is not None:
            meta["hub_wind"] = {"t_start": float(hub_track[0][0]), "t_end": float(hub_track[0][-1]),
                                "series_mean": float(np.mean(hub_track[1]))}
        if replay:
            meta["replay"] = replay_meta(waves, wind, t_start,
                                         None if wind is None else advection_delay(sim, wind))
        rec = Record(t, noisy, list(ALL_CHANNELS), [UNITS[c] for c in ALL_CHANNELS], meta)
        if return_truth:
            out.append((rec, Record(t, truth, list(ALL_CHANNELS), [UNITS[c] for c in ALL_CHANNELS],
                                    {**meta, "noise": False})))
        else:
            out.append(rec)
    return out if batch else out[0]

