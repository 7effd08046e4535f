"""Channel names and units of the sensors, following OpenFAST's output conventions.

Nine tower gauges are equally spaced from 10 m (tower base, gauge 1) to 87.6 m (tower top, gauge 9) above
still water level. OpenFAST's tower-local axes are used: ``xt`` points downwind (fore-aft, FA), ``yt`` to port
(side-to-side, SS). Hence

========================  ==========================================  ==========
channel                   meaning                                     unit
========================  ==========================================  ==========
``TwHt{i}ALxt``           FA absolute acceleration at gauge i         m/s^2
``TwHt{i}ALyt``           SS absolute acceleration at gauge i         m/s^2
``TwHt{i}MLyt``           FA bending moment (about yt) at gauge i     kN-m
``TwHt{i}MLxt``           SS bending moment (about xt) at gauge i     kN-m
========================  ==========================================  ==========

The unit strings in :data:`UNITS` are OpenFAST's (``kN-m`` for moments, ``deg`` for platform rotations), so a
record that mimics an OpenFAST output file carries them. They are labels only: nothing in this module
converts values.

Examples
--------
>>> from surrogates.channels import tower_channels, channel_index, UNITS
>>> fa = tower_channels("FA")
>>> fa[0], fa[9], len(fa)
('TwHt1ALxt', 'TwHt1MLyt', 18)
>>> UNITS["TwHt1MLyt"]
'kN-m'
>>> channel_index(fa, ["TwHt9ALxt", "TwHt1MLyt"]).tolist()
[8, 9]
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "N_GAUGES",
    "GAUGE_HEIGHTS",
    "OPENFAST_GAUGE_HEIGHTS",
    "PLANES",
    "tower_channels",
    "PLATFORM_CHANNELS",
    "ENVIRONMENT_CHANNELS",
    "ROTOR_CHANNELS",
    "TOWER_EXTRA_CHANNELS",
    "ALL_CHANNELS",
    "UNITS",
    "channel_index",
    "channel_units",
    "UnknownChannelError",
]

N_GAUGES = 9
"""Number of tower gauges (-)."""

GAUGE_HEIGHTS: NDArray[np.float64] = np.linspace(10.0, 87.6, N_GAUGES)
"""Heights of the tower gauges above still water level (m), gauge 1 (index 0) lowest; read-only."""
GAUGE_HEIGHTS.flags.writeable = False

OPENFAST_GAUGE_HEIGHTS: NDArray[np.float64] = 10.0 + 77.6 * np.array(
    [0.025, 0.125, 0.275, 0.375, 0.475, 0.625, 0.725, 0.875, 0.975])
"""Heights above still water (m) of the nine gauges of the shared OpenFAST OC3 Hywind runs: the centres of
ElastoDyn tower nodes 1, 3, 6, 8, 10, 13, 15, 18, 20 of 20 (``TwrGagNd``), 11.94 ... 85.66 m; read-only. Pass
them as ``FOWTModel(gauge_heights=OPENFAST_GAUGE_HEIGHTS)`` to compare gauge by gauge."""
OPENFAST_GAUGE_HEIGHTS.flags.writeable = False

PLANES = ("FA", "SS")
"""Names of the two bending planes: fore-aft (``xt``) and side-to-side (``yt``)."""

# plane -> (acceleration suffix, moment suffix). FA bending is a rotation about yt, SS about xt.
_PLANE_SUFFIXES = {"FA": ("ALxt", "MLyt"), "SS": ("ALyt", "MLxt")}


def _gauge_names(suffix: str) -> list[str]:
    return [f"TwHt{i}{suffix}" for i in range(1, N_GAUGES + 1)]


def tower_channels(plane: str | None = None) -> list[str]:
    """Names of the tower-gauge channels, in the order the estimators expect.

    Parameters
    ----------
    plane : {"FA", "SS"} or None, optional
        ``"FA"`` (fore-aft) gives the seed paper's 18-channel planar state: accelerations
        ``TwHt1ALxt`` ... ``TwHt9ALxt`` (m/s^2) followed by bending moments about ``yt``
        ``TwHt1MLyt`` ... ``TwHt9MLyt`` (kN-m). ``"SS"`` (side-to-side) gives ``TwHt{i}ALyt`` then
        ``TwHt{i}MLxt``. ``None`` (default) gives all 36 channels in the order FA accelerations, SS
        accelerations, FA moments, SS moments, each block from gauge 1 to gauge 9. Case-insensitive.

    Returns
    -------
    list of str
        A new list (18 names for one plane, 36 for both).

    Raises
    ------
    ValueError
        If `plane` is not ``"FA"``, ``"SS"`` or ``None``.

    Examples
    --------
    >>> tower_channels("SS")[:2]
    ['TwHt1ALyt', 'TwHt2ALyt']
    >>> len(tower_channels())
    36
    """
    if plane is None:
        fa_acc, fa_mom = _PLANE_SUFFIXES["FA"]
        ss_acc, ss_mom = _PLANE_SUFFIXES["SS"]
        return _gauge_names(fa_acc) + _gauge_names(ss_acc) + _gauge_names(fa_mom) + _gauge_names(ss_mom)
    key = plane.upper() if isinstance(plane, str) else None
    if key not in _PLANE_SUFFIXES:
        raise ValueError(f"plane must be 'FA', 'SS' or None, got {plane!r}")
    acc, mom = _PLANE_SUFFIXES[key]
    return _gauge_names(acc) + _gauge_names(mom)


PLATFORM_CHANNELS: list[str] = ["PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw"]
"""Platform rigid-body motions: surge, sway, heave (m), roll, pitch, yaw (deg), OpenFAST names."""

ENVIRONMENT_CHANNELS: list[str] = ["RotSpeed", "Wave1Elev", "Wind1VelX"]
"""Rotor speed (rpm), wave elevation at the platform (m), hub-height longitudinal wind speed (m/s)."""

ROTOR_CHANNELS: list[str] = ["BldPitch1", "GenTq", "GenPwr", "RotThrust"]
"""Blade pitch (deg), generator torque (kN-m, high-speed shaft), electrical power (kW), low-speed-shaft thrust
(kN: aerodynamic thrust plus the rotor's weight and inertia along the shaft, ElastoDyn's ``RotThrust``)."""

TOWER_EXTRA_CHANNELS: list[str] = ["TwrBsMxt", "TwrBsMyt", "YawBrTAxp", "YawBrTAyp", "TTDspFA", "TTDspSS"]
"""Tower-base side-to-side / fore-aft bending moments at 10 m above SWL (kN-m), tower-top (yaw-bearing)
fore-aft / side-to-side accelerations without gravity (m/s^2), tower-top fore-aft / side-to-side deflections
relative to the undeflected tower (m), ElastoDyn's definitions."""

ALL_CHANNELS: list[str] = (tower_channels(None) + PLATFORM_CHANNELS + ENVIRONMENT_CHANNELS + ROTOR_CHANNELS
                           + TOWER_EXTRA_CHANNELS)
"""All 55 known channels, in the order: the 36 tower channels of ``tower_channels(None)`` (FA accelerations,
SS accelerations, FA moments, SS moments, gauges 1-9 each), then :data:`PLATFORM_CHANNELS`,
:data:`ENVIRONMENT_CHANNELS`, :data:`ROTOR_CHANNELS` and :data:`TOWER_EXTRA_CHANNELS`."""

UNITS: dict[str, str] = {
    **{name: "m/s^2" for name in _gauge_names("ALxt") + _gauge_names("ALyt")},
    **{name: "kN-m" for name in _gauge_names("MLyt") + _gauge_names("MLxt")},
    "PtfmSurge": "m",
    "PtfmSway": "m",
    "PtfmHeave": "m",
    "PtfmRoll": "deg",
    "PtfmPitch": "deg",
    "PtfmYaw": "deg",
    "RotSpeed": "rpm",
    "Wave1Elev": "m",
    "Wind1VelX": "m/s",
    "BldPitch1": "deg",
    "GenTq": "kN-m",
    "GenPwr": "kW",
    "RotThrust": "kN",
    "TwrBsMxt": "kN-m",
    "TwrBsMyt": "kN-m",
    "YawBrTAxp": "m/s^2",
    "YawBrTAyp": "m/s^2",
    "TTDspFA": "m",
    "TTDspSS": "m",
}
"""OpenFAST unit string of every channel in :data:`ALL_CHANNELS`."""


class UnknownChannelError(ValueError, KeyError):
    """A requested channel name is not among the available ones.

    A :class:`ValueError` (bad argument) that is also a :class:`KeyError`, so that ``record["name"]``
    behaves like a mapping lookup.
    """

    __str__ = ValueError.__str__  # KeyError would wrap the message in quotes


def _as_name_list(names: str | Sequence[str], argname: str) -> list[str]:
    if isinstance(names, str):
        return [names]
    if isinstance(names, np.ndarray) and names.ndim != 1:
        raise ValueError(f"{argname} must be a string or a 1-D sequence of strings, got shape {names.shape}")
    try:
        out = list(names)
    except TypeError:
        raise ValueError(f"{argname} must be a string or a sequence of strings, got {type(names).__name__}") from None
    bad = [n for n in out if not isinstance(n, str)]
    if bad:
        raise ValueError(f"{argname} must contain only strings, got {bad[:3]!r}")
    return out


def channel_index(names: Sequence[str], wanted: str | Sequence[str]) -> NDArray[np.intp]:
    """Column indices of the `wanted` channels within `names`.

    Parameters
    ----------
    names : sequence of str
        The available channel names, in column order (must be unique).
    wanted : str or sequence of str
        The channel name(s) to look up; the result follows this order. Repeats are allowed.

    Returns
    -------
    ndarray of int, shape (len(wanted),)
        ``names[idx[k]] == wanted[k]``.

    Raises
    ------
    UnknownChannelError
        (a :class:`ValueError`) listing every unknown name, with a close-match suggestion where one exists.
    ValueError
        If `names` holds duplicates or non-strings.

    Examples
    --------
    >>> channel_index(["a", "b", "c"], ["c", "a"]).tolist()
    [2, 0]
    """
    available = _as_name_list(names, "names")
    requested = _as_name_list(wanted, "wanted")
    position: dict[str, int] = {}
    duplicates: list[str] = []
    for i, name in enumerate(available):
        if name in position:
            duplicates.append(name)
        position.setdefault(name, i)
    if duplicates:
        raise ValueError(f"names must be unique; duplicated: {sorted(set(duplicates))}")
    unknown = [name for name in requested if name not in position]
    if unknown:
        raise UnknownChannelError(_unknown_message(unknown, available))
    return np.array([position[name] for name in requested], dtype=np.intp)


def _unknown_message(unknown: list[str], available: list[str]) -> str:
    lowered = {name.lower(): name for name in available}
    parts = []
    for name in dict.fromkeys(unknown):  # unique, order kept
        match = difflib.get_close_matches(name.lower(), list(lowered), n=1, cutoff=0.6)
        hint = f" (did you mean {lowered[match[0]]!r}?)" if match else ""
        parts.append(f"{name!r}{hint}")
    shown = ", ".join(repr(n) for n in available[:6]) + (", ..." if len(available) > 6 else "")
    return f"unknown channel name(s): {', '.join(parts)}; {len(available)} channel(s) available: [{shown}]"


def channel_units(names: str | Sequence[str]) -> list[str]:
    """OpenFAST unit strings of known channels.

    Parameters
    ----------
    names : str or sequence of str
        Channel names from :data:`ALL_CHANNELS`.

    Returns
    -------
    list of str
        ``[UNITS[name] for name in names]``.

    Raises
    ------
    UnknownChannelError
        (a :class:`ValueError`) if a name is not in :data:`UNITS`.

    Examples
    --------
    >>> channel_units(["PtfmPitch", "TwHt3ALxt"])
    ['deg', 'm/s^2']
    """
    requested = _as_name_list(names, "names")
    unknown = [name for name in requested if name not in UNITS]
    if unknown:
        raise UnknownChannelError(_unknown_message(unknown, list(UNITS)))
    return [UNITS[name] for name in requested]
