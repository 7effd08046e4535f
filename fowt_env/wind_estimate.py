"""Rotor-effective wind estimated from a record's own rotor signals: the measured thrust, rotor speed and blade
pitch, through the rotor's steady thrust coefficient.

A nacelle anemometer or OpenFAST's ``Wind1VelX`` gives the wind at one point, the hub; what drives the rotor is the
wind averaged over the 126 m disc, which at the platform's slow frequencies the hub point resolves poorly (the
replay of an OC3 Hywind record at 12 m/s from ``Wind1VelX`` explains about half of the platform-band surge). The
rotor itself is a better anemometer: its thrust ``T = 1/2 rho A Ct(lambda, beta) v_rel^2``, with
``lambda = Omega R / v_rel``, is inverted for the wind relative to the hub ``v_rel`` at every sample (the steady
``Ct`` table of :func:`surrogates.aero.rotor_table`, with the blades bent by the thrust as the model's
``blade_deflection`` effect bends them), and the hub's fore-aft velocity is added back.

Steps, per sample (SI units; the record's channels in OpenFAST units):

1. aerodynamic thrust from ElastoDyn's ``RotThrust`` (kN: aerodynamic thrust plus the rotor's weight and inertia
   along the tilted shaft): ``T = RotThrust - m_r g sin(-tilt) - m_r g cos(tilt) theta_top + m_r a_top``, with
   ``theta_top`` the tower-top pitch (platform pitch plus the tip slope ``1.5 TTDspFA / L`` of the tower as a
   cantilever) and ``a_top`` the tower-top fore-aft acceleration (``TwHt9ALxt``);
2. thrust, rotor speed and pitch low-passed (zero-phase 4th-order Butterworth, :data:`CUTOFF_HZ`: the blade
   passing's 3P and sensor noise are not wind);
3. ``v_rel`` from the thrust curve ``T(v)`` at that rotor speed and pitch (monotonic interpolation on a grid);
4. plus the hub's fore-aft velocity, the derivative of ``PtfmSurge + z_hub PtfmPitch + TTDspFA`` (low-passed).

Quasi-steady: no dynamic inflow, no rotational sampling. For a surrogate record the rotor is the surrogate's own,
so the estimate is close; for OpenFAST (AeroDyn's BEM with its dynamics) it is an approximation.

Examples
--------
>>> import surrogates
>>> rec = surrogates.simulate(surrogates.FOWTModel(), 7, duration=300.0, dt=0.1, seed=1)
>>> wind = rotor_effective_wind(rec)
>>> wind.level, round(float(wind.rotor_effective.mean()), 0)
('rotor_effective', 12.0)
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy.signal import butter, sosfiltfilt

from surrogates import Record
from surrogates.aero import blade_deflection_table, rotor_table
from surrogates.oc3 import GRAVITY, RHO_AIR
from surrogates.replay import MeasuredWind
from surrogates.structure import build_structure

__all__ = ["CUTOFF_HZ", "ROTOR_WIND_CHANNELS", "rotor_effective_wind"]

ROTOR_WIND_CHANNELS: tuple[str, ...] = ("RotThrust", "RotSpeed", "BldPitch1", "PtfmSurge", "PtfmPitch", "TTDspFA",
                                        "TwHt9ALxt", "Wind1VelX")
"""Channels the estimate reads (``Wind1VelX`` only as the hub series kept beside it)."""

CUTOFF_HZ = 0.5
"""Low-pass corner (Hz) of the thrust, rotor speed, pitch and hub motion before the inversion."""

_V_GRID = np.linspace(3.0, 35.0, 321)  # m/s: relative wind grid of the thrust-curve inversion (0.1 m/s)


@lru_cache(maxsize=1)
def _constants() -> tuple[float, float, float, float]:
    st = build_structure()
    d = st.data
    return float(d.rotor_mass), float(d.shaft_tilt_rad), float(st.hub_position[2]), float(d.tower_length)


def _ct(lam: NDArray[np.float64], beta: NDArray[np.float64],
        bend: NDArray[np.float64] | float = 0.0) -> NDArray[np.float64]:
    """Steady thrust coefficient at tip-speed ratios ``lam`` and pitch ``beta`` (rad), bilinear on the table's
    uniform grid and clamped at its edges (vectorised form of :func:`surrogates.aero.rotor_coefficients`); with
    ``bend`` = (tip deflection / the bent table's)^2, that of the blades bent downwind
    (:func:`surrogates.aero.blade_deflection_table`, the model's ``blade_deflection`` effect)."""
    tab = rotor_table()
    nl, nb = tab.tsr.size, tab.pitch_rad.size
    fl = np.clip((lam - tab.tsr[0]) / (tab.tsr[1] - tab.tsr[0]), 0.0, nl - 1.000001)
    fb = np.clip((beta - tab.pitch_rad[0]) / (tab.pitch_rad[1] - tab.pitch_rad[0]), 0.0, nb - 1.000001)
    i, j = fl.astype(int), fb.astype(int)
    wl, wb = fl - i, fb - j

    def lookup(ct: NDArray[np.float64]) -> NDArray[np.float64]:
        return ((1 - wl) * (1 - wb) * ct[i, j] + wl * (1 - wb) * ct[i + 1, j] + (1 - wl) * wb * ct[i, j + 1]
                + wl * wb * ct[i + 1, j + 1])

    straight = lookup(tab.ct)
    if np.all(np.asarray(bend) == 0.0):
        return straight
    return straight + bend * (lookup(blade_deflection_table().ct) - straight)


@lru_cache(maxsize=1)
def _flap_compliance() -> tuple[float, tuple[float, float]]:
    """The model's collective flap mode under the rotor thrust: the mode's value at the thrust's centre (-, the
    share of the thrust it takes), and its stiffness parked (N/m) and centrifugal stiffening per (rad/s)^2, so
    that the quasi-static tip deflection is ``T shape / (k + k_cent Omega^2)`` (m)."""
    st = build_structure()
    flap = st.data.blade_flap
    i = st.labels.index("blade_flap")
    return float(flap.thrust_shape), (float(st.stiffness[i, i]), float(st.data.n_blades * flap.centrifugal))


def rotor_effective_wind(record: Record, cutoff_hz: float = CUTOFF_HZ) -> MeasuredWind:
    """Estimate the rotor-effective wind (m/s) of a record from its rotor thrust, speed and pitch.

    Parameters
    ----------
    record : Record
        With the channels of :data:`ROTOR_WIND_CHANNELS` (OpenFAST names and units), uniformly sampled, operating
        (rotor speed > 0).
    cutoff_hz : float
        Low-pass corner (Hz), below the record's Nyquist frequency.

    Returns
    -------
    surrogates.replay.MeasuredWind
        Level ``"rotor_effective"`` on the record's time axis; its hub series is the record's ``Wind1VelX``.

    Raises
    ------
    ValueError
        Missing channels (named), non-finite samples, a parked rotor or a cutoff at or above Nyquist.
    """
    missing = [c for c in ROTOR_WIND_CHANNELS if c not in record.channels]
    if missing:
        raise ValueError(f"a rotor-effective wind estimate needs the channels {missing}")
    fs = record.fs
    if not 0.0 < cutoff_hz < 0.5 * fs:
        raise ValueError(f"cutoff_hz must lie between 0 and the Nyquist frequency {0.5 * fs:g} Hz, got {cutoff_hz!r}")
    x = {c: np.asarray(record[c], float) for c in ROTOR_WIND_CHANNELS}
    bad = [c for c, v in x.items() if not np.all(np.isfinite(v))]
    if bad:
        raise ValueError(f"the channels {bad} hold NaN or inf; fill or cut the gaps before estimating the wind")
    if np.median(x["RotSpeed"]) <= 0.5:
        raise ValueError("the rotor is parked (RotSpeed ~ 0): its thrust says nothing about the wind")
    m_r, tilt, z_hub, tower = _constants()
    sos = butter(4, cutoff_hz, fs=fs, output="sos")

    def low(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return sosfiltfilt(sos, v - v[0]) + v[0]

    pitch = np.deg2rad(x["PtfmPitch"])
    theta_top = pitch + 1.5 * x["TTDspFA"] / tower
    thrust = (x["RotThrust"] * 1e3 + m_r * GRAVITY * math.sin(tilt) - m_r * GRAVITY * math.cos(tilt) * theta_top
              + m_r * x["TwHt9ALxt"])
    thrust, omega, beta = low(thrust), low(x["RotSpeed"] * math.pi / 30.0), low(np.deg2rad(x["BldPitch1"]))
    tab = rotor_table()
    area = math.pi * tab.radius**2
    v = _V_GRID[None, :]
    # the blades bend under the thrust (their quasi-static flap deflection: the thrust at its centre over the flap
    # mode's stiffness, stiffened by the rotation), and bent blades carry less thrust at the same wind
    shape, (k_flap, k_cent) = _flap_compliance()
    deflection = np.clip(thrust, 0.0, None) * shape / (k_flap + k_cent * omega**2)
    bend = ((deflection / blade_deflection_table().tip_deflection) ** 2)[:, None]
    curve = 0.5 * RHO_AIR * area * v**2 * _ct(omega[:, None] * tab.radius / v, np.repeat(beta[:, None], v.size, 1),
                                             bend)
    # the first grid speed whose thrust reaches the measured one, linearly interpolated (T rises with v at fixed
    # rotor speed and pitch over the operating range; clamped at the grid's ends)
    k = np.clip(np.argmax(curve >= thrust[:, None], axis=1), 1, _V_GRID.size - 1)
    rows = np.arange(thrust.size)
    t0, t1 = curve[rows, k - 1], curve[rows, k]
    w = np.clip((thrust - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0, 1.0)
    v_rel = _V_GRID[k - 1] + w * (_V_GRID[k] - _V_GRID[k - 1])
    never = ~np.any(curve >= thrust[:, None], axis=1)
    v_rel[never] = _V_GRID[-1]
    hub_velocity = np.gradient(low(x["PtfmSurge"] + z_hub * pitch + x["TTDspFA"]), record.dt)
    return MeasuredWind.from_rotor_effective(np.asarray(record.t, float), v_rel + hub_velocity, x["Wind1VelX"],
                                             source="rotor-effective wind estimated from RotThrust, RotSpeed, "
                                                    "BldPitch1 (fowt_env.wind_estimate)")
