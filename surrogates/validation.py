"""Argument checks shared by the surrogate's modules: clear ``ValueError`` messages that name the argument."""

from __future__ import annotations

import numpy as np

__all__ = ["check_number"]


def check_number(name: str, value: float, *, positive: bool = False, nonneg: bool = False) -> float:
    """Return ``value`` as a float after checking it is a finite number (and > 0 or >= 0 if asked).

    Parameters
    ----------
    name : str
        Argument name used in the error message.
    value : float
        The value to check.
    positive, nonneg : bool
        Require ``value > 0`` or ``value >= 0``.

    Raises
    ------
    ValueError
        Not a number, not finite, or out of the requested range.
    """
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a number, got {value!r}") from exc
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if positive and v <= 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    if nonneg and v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return v
