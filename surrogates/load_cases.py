"""Operational load cases: a sea state, a wind condition and a rotor speed.

The twelve operational load cases (OLC 1-12) are those of the seed paper, Abaei et al., "Equation-Free Digital
Twins for Nonlinear Structural Dynamics", Table 1: four sea states (Hs = 1, 2, 3, 4 m), each with three wave
directions (0, 45, 90 deg relative to the wind, 0 = aligned with the wind, i.e. fore-aft dominant), under a
constant 12 m/s wind with the rotor at 12.1 rpm.

The paper does not state the JONSWAP peak-enhancement factor nor the turbulence intensity. These are **our
assumptions**, documented here and in :func:`load_case`:

- ``gamma = 3.3``: the default JONSWAP peak-enhancement factor of DNV-RP-C205 (section 3.5.5) when nothing
  better is known (:data:`DEFAULT_JONSWAP_GAMMA`).
- ``turbulence_intensity = I_ref (0.75 V + 5.6 m/s) / V`` with ``I_ref = 0.14``: the normal turbulence model
  (NTM) of IEC 61400-1 (ed. 3), turbulence class B, at the hub-height wind speed V = 12 m/s, i.e. 0.1703
  (:func:`iec_ntm_turbulence_intensity`).

Angles are stored in degrees because that is how load-case tables are written; use
:attr:`LoadCase.wave_dir_rad` and :attr:`LoadCase.rotor_speed_rad_s` to get SI values.

Examples
--------
>>> from surrogates.load_cases import load_case
>>> olc = load_case(7)
>>> olc.name, olc.hs, olc.tp, olc.wave_dir_deg, olc.wind_speed
('OLC7', 3.0, 10.0, 0.0, 12.0)
>>> round(olc.turbulence_intensity, 4)
0.1703
>>> olc.replace(hs=3.5).hs
3.5
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

__all__ = [
    "LoadCase",
    "load_case",
    "LOAD_CASES",
    "iec_ntm_turbulence_intensity",
    "DEFAULT_JONSWAP_GAMMA",
    "IEC_CLASS_B_I_REF",
    "PAPER_WIND_SPEED",
    "PAPER_ROTOR_RPM",
    "operating_case",
    "steady_rotor_rpm",
]

DEFAULT_JONSWAP_GAMMA = 3.3
"""JONSWAP peak-enhancement factor (-): DNV-RP-C205's default; our assumption for the paper's cases."""

IEC_CLASS_B_I_REF = 0.14
"""Reference turbulence intensity of IEC 61400-1 (ed. 3) turbulence class B (-)."""

PAPER_WIND_SPEED = 12.0
"""Hub-height mean wind speed of all the paper's load cases (m/s), Abaei et al. Table 1."""

PAPER_ROTOR_RPM = 12.1
"""Rotor speed of all the paper's load cases (rpm), Abaei et al. section on operational load cases."""

# Abaei et al., Table 1: case id -> (Hs (m), Tp (s), wave direction relative to the wind (deg)).
_TABLE_1: dict[int, tuple[float, float, float]] = {
    1: (1.0, 6.0, 0.0),
    2: (1.0, 9.0, 45.0),
    3: (1.0, 12.0, 90.0),
    4: (2.0, 8.0, 0.0),
    5: (2.0, 10.0, 45.0),
    6: (2.0, 14.0, 90.0),
    7: (3.0, 10.0, 0.0),
    8: (3.0, 12.0, 45.0),
    9: (3.0, 16.0, 90.0),
    10: (4.0, 9.0, 0.0),
    11: (4.0, 12.0, 45.0),
    12: (4.0, 20.0, 90.0),
}


def iec_ntm_turbulence_intensity(wind_speed: float, i_ref: float = IEC_CLASS_B_I_REF) -> float:
    """Turbulence intensity of the IEC 61400-1 (ed. 3) normal turbulence model.

    ``sigma_1 = I_ref (0.75 V + b)`` with ``b = 5.6 m/s``, returned as the intensity ``sigma_1 / V``.

    Parameters
    ----------
    wind_speed : float
        Hub-height mean wind speed V (m/s), > 0.
    i_ref : float, optional
        Reference turbulence intensity at 15 m/s (-): 0.16 (class A), 0.14 (class B, default), 0.12 (class C).

    Returns
    -------
    float
        Longitudinal turbulence intensity (-).

    Raises
    ------
    ValueError
        If `wind_speed` is not finite and positive, or `i_ref` is not finite and non-negative.

    Examples
    --------
    >>> round(iec_ntm_turbulence_intensity(12.0), 4)
    0.1703
    """
    v = _real(wind_speed, "wind_speed")
    i_ref = _real(i_ref, "i_ref")
    if v <= 0.0:
        raise ValueError(f"wind_speed must be > 0 m/s, got {v!r}")
    if i_ref < 0.0:
        raise ValueError(f"i_ref must be >= 0, got {i_ref!r}")
    return i_ref * (0.75 * v + 5.6) / v


def _real(value: Any, name: str) -> float:
    """``value`` as a finite Python float, or a ValueError naming the argument."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.integer | np.floating):
        raise ValueError(f"{name} must be a real number, got {value!r} ({type(value).__name__})")
    out = float(value)
    if not math.isfinite(out):
        raise ValueError(f"{name} must be finite, got {out!r}")
    return out


@dataclass(frozen=True)
class LoadCase:
    """Environmental and operating conditions of one simulation.

    Immutable; numeric fields are stored as Python floats. Build variants with :meth:`replace`.

    Parameters
    ----------
    hs : float
        Significant wave height (m), >= 0 (0 = still water).
    tp : float
        Peak spectral wave period (s), > 0.
    wave_dir_deg : float
        Wave propagation direction relative to the wind (deg); 0 = aligned with the wind (fore-aft),
        90 = perpendicular (side-to-side).
    wind_speed : float
        Hub-height mean wind speed (m/s), >= 0.
    rotor_rpm : float or None
        Rotor speed (rpm), >= 0 (0 = parked). None: the steady speed the OC3 Hywind controller reaches at
        ``wind_speed`` (:func:`surrogates.aero.operating_point`); it then follows the wind speed in
        :meth:`replace`. With the nonlinear rotor (the default) it is only the starting speed: the rotor speed is
        a state driven by the aerodynamic and generator torques.
    turbulence_intensity : float
        Longitudinal turbulence intensity (-), 0 <= TI < 1 (0 = steady wind).
    gamma : float
        JONSWAP peak-enhancement factor (-), 1 <= gamma <= 10 (1 = Pierson-Moskowitz).
    name : str, optional
        Label, e.g. ``"OLC7"``; default ``"custom"``.

    Raises
    ------
    ValueError
        Naming the offending argument if a value is not a finite real number or is out of range.

    Examples
    --------
    >>> lc = LoadCase(hs=2.0, tp=10.0, wave_dir_deg=45.0, wind_speed=12.0, rotor_rpm=12.1,
    ...               turbulence_intensity=0.17, gamma=3.3, name="mine")
    >>> LoadCase.from_dict(lc.to_dict()) == lc
    True
    >>> round(lc.wave_dir_rad, 4)
    0.7854
    """

    hs: float
    """Significant wave height (m)."""
    tp: float
    """Peak spectral wave period (s)."""
    wave_dir_deg: float
    """Wave direction relative to the wind (deg)."""
    wind_speed: float
    """Hub-height mean wind speed (m/s)."""
    rotor_rpm: float | None
    """Rotor speed (rpm)."""
    turbulence_intensity: float
    """Longitudinal turbulence intensity (-)."""
    gamma: float
    """JONSWAP peak-enhancement factor (-)."""
    name: str = "custom"
    """Label of the load case."""
    rotor_rpm_auto: bool = dataclasses.field(default=False, compare=False, repr=False)
    """True when ``rotor_rpm`` was derived from the wind speed (it is recomputed when the wind speed changes)."""

    def __post_init__(self) -> None:
        if self.rotor_rpm is None:
            object.__setattr__(self, "rotor_rpm_auto", True)
            object.__setattr__(self, "rotor_rpm", steady_rotor_rpm(_real(self.wind_speed, "wind_speed")))
        for field in dataclasses.fields(self):
            if field.name == "rotor_rpm_auto":
                object.__setattr__(self, field.name, bool(self.rotor_rpm_auto))
            elif field.name != "name":
                object.__setattr__(self, field.name, _real(getattr(self, field.name), field.name))
        if not isinstance(self.name, str):
            raise ValueError(f"name must be a string, got {self.name!r} ({type(self.name).__name__})")
        if self.hs < 0.0:
            raise ValueError(f"hs must be >= 0 m, got {self.hs!r}")
        if self.tp <= 0.0:
            raise ValueError(f"tp must be > 0 s, got {self.tp!r}")
        if self.wind_speed < 0.0:
            raise ValueError(f"wind_speed must be >= 0 m/s, got {self.wind_speed!r}")
        if self.rotor_rpm < 0.0:
            raise ValueError(f"rotor_rpm must be >= 0 rpm, got {self.rotor_rpm!r}")
        if not 0.0 <= self.turbulence_intensity < 1.0:
            raise ValueError(f"turbulence_intensity must be in [0, 1), got {self.turbulence_intensity!r}")
        if not 1.0 <= self.gamma <= 10.0:
            raise ValueError(f"gamma must be in [1, 10], got {self.gamma!r}")

    @property
    def wave_dir_rad(self) -> float:
        """Wave direction relative to the wind (rad)."""
        return math.radians(self.wave_dir_deg)

    @property
    def rotor_speed_rad_s(self) -> float:
        """Rotor speed (rad/s)."""
        return self.rotor_rpm * 2.0 * math.pi / 60.0

    def to_dict(self) -> dict[str, float | str]:
        """JSON-friendly dictionary of the fields (Python floats and the name).

        Returns
        -------
        dict
            ``{"hs": ..., "tp": ..., ..., "name": ...}``; :meth:`from_dict` inverts it exactly.
        """
        return {field.name: getattr(self, field.name) for field in dataclasses.fields(self)
                if field.name != "rotor_rpm_auto"}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LoadCase:
        """Build a load case from a mapping such as the output of :meth:`to_dict`.

        Parameters
        ----------
        data : mapping
            Field name -> value. ``name`` is optional; every other field is required.

        Returns
        -------
        LoadCase

        Raises
        ------
        ValueError
            If `data` is not a mapping, misses a required field, holds an unknown key, or a value is invalid.
        """
        if not isinstance(data, Mapping):
            raise ValueError(f"data must be a mapping of LoadCase fields, got {type(data).__name__}")
        fields = [field.name for field in dataclasses.fields(cls)]
        unknown = sorted(set(data) - set(fields), key=str)
        if unknown:
            raise ValueError(f"data has unknown LoadCase field(s) {unknown}; expected keys from {fields}")
        missing = [name for name in fields if name not in ("name", "rotor_rpm_auto") and name not in data]
        if missing:
            raise ValueError(f"data misses LoadCase field(s) {missing}")
        return cls(**dict(data))

    def replace(self, **changes: Any) -> LoadCase:
        """A copy with some fields changed (and validated again).

        Parameters
        ----------
        **changes
            New values of fields, e.g. ``hs=2.5``.

        Returns
        -------
        LoadCase

        Raises
        ------
        ValueError
            If a keyword is not a field, or a new value is invalid.
        """
        fields = [field.name for field in dataclasses.fields(self)]
        unknown = sorted(set(changes) - set(fields))
        if unknown:
            raise ValueError(f"unknown LoadCase field(s) {unknown}; fields are {fields}")
        if self.rotor_rpm_auto and "wind_speed" in changes and "rotor_rpm" not in changes:
            changes["rotor_rpm"] = None  # the rotor speed follows the wind speed
        return dataclasses.replace(self, **changes)


def steady_rotor_rpm(wind_speed: float) -> float:
    """Steady rotor speed (rpm) of the NREL 5 MW under the OC3 Hywind controller at a mean wind (m/s); 0 for no
    wind."""
    if wind_speed <= 0.0:
        return 0.0
    from .aero import operating_point

    return float(operating_point(float(wind_speed)).rotor_speed * 30.0 / math.pi)


def operating_case(
    wind_speed: float,
    hs: float = 0.0,
    tp: float = 10.0,
    *,
    gamma: float = 1.0,
    wave_dir_deg: float = 0.0,
    turbulence_intensity: float | None = None,
    name: str = "custom",
) -> LoadCase:
    """A load case anywhere in the operating range: the rotor speed follows the wind speed.

    Parameters
    ----------
    wind_speed : float
        Hub-height mean wind speed (m/s), > 0.
    hs, tp : float
        Significant wave height (m; 0 = still water) and peak period (s).
    gamma : float
        JONSWAP peak-enhancement factor (-); 1 (Pierson-Moskowitz) is what IEC 61400-3's rule gives for most
        operational sea states (and what OpenFAST's ``WavePkShp = DEFAULT`` used in the reference runs).
    wave_dir_deg : float
        Wave direction relative to the wind (deg).
    turbulence_intensity : float, optional
        Default: IEC 61400-1 NTM, class B (:func:`iec_ntm_turbulence_intensity`).
    name : str

    Returns
    -------
    LoadCase

    Examples
    --------
    >>> lc = operating_case(8.0, hs=2.0, tp=9.0)
    >>> round(lc.rotor_rpm, 1), round(lc.replace(wind_speed=18.0).rotor_rpm, 1)
    (9.0, 12.1)
    """
    v = _real(wind_speed, "wind_speed")
    if v <= 0:
        raise ValueError(f"wind_speed must be > 0 m/s for an operating case, got {v!r}")
    ti = iec_ntm_turbulence_intensity(v) if turbulence_intensity is None else turbulence_intensity
    return LoadCase(hs=hs, tp=tp, wave_dir_deg=wave_dir_deg, wind_speed=v, rotor_rpm=None, turbulence_intensity=ti,
                    gamma=gamma, name=name)


def _paper_case(n: int) -> LoadCase:
    hs, tp, direction = _TABLE_1[n]
    return LoadCase(
        hs=hs,
        tp=tp,
        wave_dir_deg=direction,
        wind_speed=PAPER_WIND_SPEED,
        rotor_rpm=None,  # the controller's speed: 12.1 rpm at the paper's 12 m/s, and it follows replace()
        turbulence_intensity=iec_ntm_turbulence_intensity(PAPER_WIND_SPEED, IEC_CLASS_B_I_REF),
        gamma=DEFAULT_JONSWAP_GAMMA,
        name=f"OLC{n}",
    )


LOAD_CASES: Mapping[int, LoadCase] = MappingProxyType({n: _paper_case(n) for n in _TABLE_1})
"""The paper's operational load cases, OLC number (1-12) -> :class:`LoadCase` (read-only mapping)."""


def load_case(n: int) -> LoadCase:
    """Operational load case ``n`` of the seed paper (Abaei et al., Table 1).

    Hs, Tp and the wave direction are the paper's; every case has a 12 m/s wind and a 12.1 rpm rotor. The
    JONSWAP ``gamma = 3.3`` (DNV-RP-C205 default) and the turbulence intensity of IEC 61400-1 NTM class B at
    12 m/s (0.1703) are our assumptions: the paper does not state them.

    Parameters
    ----------
    n : int
        Load-case number, 1 to 12.

    Returns
    -------
    LoadCase
        Named ``f"OLC{n}"``.

    Raises
    ------
    ValueError
        If `n` is not one of 1, ..., 12.

    Examples
    --------
    >>> load_case(12).tp
    20.0
    """
    if isinstance(n, bool | np.bool_) or not isinstance(n, int | np.integer) or int(n) not in LOAD_CASES:
        raise ValueError(f"n must be a load-case number in {sorted(LOAD_CASES)}, got {n!r}")
    return LOAD_CASES[int(n)]
