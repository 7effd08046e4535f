"""Perturbed "truth" models: the model-error axis of an estimator comparison.

A virtual sensor built on a model (a Kalman filter on :meth:`FOWTModel.linearize`) is only as good as the model.
On the surrogate's own data it is handed the exact model of the records; on a real turbine the structure is not
the drawing's. :func:`perturbed_model` makes a surrogate whose physics differs from the nominal one in named,
physical ways, so that records can come from it while model-based sensors keep the nominal model -- the
robustness table of any estimator comparison. It is a thin vocabulary over :mod:`surrogates.parameters` (whose
:class:`~surrogates.parameters.ParametricModel` applies the scalings) and the effect strengths.

Names (:func:`check_perturbations`; values are multipliers unless stated):

* every parameter of :data:`surrogates.parameters.PARAMETERS` (``tower_fa_stiffness``, ``platform_mass``,
  ``drag_cd``, ``mooring_line_1`` ...);
* ``tower_stiffness``: ``tower_fa_stiffness`` and ``tower_ss_stiffness`` together (EI in both planes);
* ``mooring_stiffness``: ``mooring_line_1..3`` together (the linearised restoring of all three lines; the
  crow-foot yaw spring and the ``mooring_nonlinear`` remainder are not scaled);
* ``rotor_mass_imbalance``: one blade heavier by this *fraction* of its mass: the ``rotor_1p`` effect's static
  unbalance becomes ``fraction x`` the blade's first mass moment about the rotor apex (0.02 -> 7.75 t·m against
  the nominal 2 t·m, :class:`surrogates.model.RotorHarmonics`);
* every effect of :data:`surrogates.EFFECTS`: its strength (``quadratic_drag=1.5`` scales only the drag's
  nonlinear remainder beyond its equivalent linearisation; ``drag_cd=1.5`` is the drag coefficient).

:data:`STANDARD_PERTURBATIONS` holds the five of issue 17's model-error table.

Examples
--------
>>> from surrogates.model_error import perturbed_model
>>> f0 = perturbed_model({}).modal_analysis().frequency("tower_fa_1")
>>> f = perturbed_model({"tower_stiffness": 0.95}).modal_analysis().frequency("tower_fa_1")
>>> bool(abs(f / f0 - 0.95 ** 0.5) < 0.002)  # EI x 0.95: frequency x sqrt(0.95)
True
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from .effects import EFFECTS
from .model import FOWTModel, RotorHarmonics
from .parameters import PARAMETERS, ParametricModel

__all__ = ["ALIASES", "STANDARD_PERTURBATIONS", "check_perturbations", "perturbed_model"]

ALIASES: dict[str, tuple[str, ...]] = {
    "tower_stiffness": ("tower_fa_stiffness", "tower_ss_stiffness"),
    "mooring_stiffness": ("mooring_line_1", "mooring_line_2", "mooring_line_3"),
}
"""Names that scale several parameters of :data:`surrogates.parameters.PARAMETERS` together."""

STANDARD_PERTURBATIONS: dict[str, dict[str, float]] = {
    "tower stiffness x0.95": {"tower_stiffness": 0.95},
    "platform mass +3 %": {"platform_mass": 1.03},
    "drag x1.5": {"drag_cd": 1.5},
    "mooring line stiffness -30 %": {"mooring_stiffness": 0.70},
    "rotor mass imbalance 2 %": {"rotor_mass_imbalance": 0.02},
}
"""Issue 17's model-error table: label -> perturbation."""


def check_perturbations(changes: Mapping[str, Any] | None) -> dict[str, float]:
    """Validate a perturbation mapping; returns ``{name: float}`` (names as given).

    Raises
    ------
    ValueError
        Unknown name, or a value that is not finite, not > 0 (multipliers) or negative (strengths, fractions).
    """
    out: dict[str, float] = {}
    for name, value in dict(changes or {}).items():
        if name not in PARAMETERS and name not in ALIASES and name not in EFFECTS and name != "rotor_mass_imbalance":
            raise ValueError(f"unknown perturbation {name!r}; known: {sorted([*PARAMETERS, *ALIASES])}, "
                             f"'rotor_mass_imbalance' and the effects {sorted(EFFECTS)}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"perturbation {name!r} must be a number, got {value!r}") from None
        multiplier = name in PARAMETERS or name in ALIASES
        if not math.isfinite(v) or v < 0 or (multiplier and v == 0):
            raise ValueError(f"perturbation {name!r} must be {'> 0' if multiplier else '>= 0'} and finite, "
                             f"got {value!r}")
        out[str(name)] = v
    return out


def perturbed_model(changes: Mapping[str, Any] | None, base: FOWTModel | None = None) -> FOWTModel:
    """The surrogate with named physical perturbations (a "truth" that differs from the nominal model).

    Parameters
    ----------
    changes : mapping of str to float
        Perturbation name -> value (see the module docstring). Empty or None: ``base`` itself.
    base : FOWTModel, optional
        The nominal model (default ``FOWTModel()``): its effects, harmonics, noise and gauges are kept.

    Returns
    -------
    FOWTModel
        ``base`` for no change, a :class:`FOWTModel` when only effects or the unbalance change, else a
        :class:`surrogates.parameters.ParametricModel`.

    Raises
    ------
    ValueError
        Unknown names or bad values (:func:`check_perturbations`).
    """
    base = base if base is not None else FOWTModel()
    ch = check_perturbations(changes)
    if not ch:
        return base
    effects = {**base.effects, **{k: v for k, v in ch.items() if k in EFFECTS}}
    harmonics = base.harmonics
    if "rotor_mass_imbalance" in ch:
        moment = base.structure.data.blade_first_moment  # kg·m, one blade about the rotor apex
        harmonics = RotorHarmonics(**{**dataclasses.asdict(harmonics),
                                      "mass_imbalance": ch["rotor_mass_imbalance"] * moment})
    parameters = dict(getattr(base, "parameters", {}))
    for name, value in ch.items():
        for p in ALIASES.get(name, (name,) if name in PARAMETERS else ()):
            parameters[p] = value
    kwargs = {"harmonics": harmonics, "noise": base.noise, "accel_gravity": base.accel_gravity,
              "gauge_heights": base.gauge_heights}
    if any(v != 1.0 for v in parameters.values()):
        return ParametricModel(effects, parameters=parameters, **kwargs)
    return FOWTModel(effects, **kwargs)
