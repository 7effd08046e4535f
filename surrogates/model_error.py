"""Perturbed "truth" models: the model-error axis of an estimator comparison.

A virtual sensor built on a model (a Kalman filter on :meth:`FOWTModel.linearize`) is only as good as the model.
On the surrogate's own data it is handed the exact model of the records; on a real turbine the structure is not
the drawing's. :func:`perturbed_model` makes a surrogate whose physics differs from the nominal one in a named,
physical way, so that test (and training) records can come from it while model-based sensors keep the nominal
model -- the robustness table of any estimator comparison.

Perturbations (:data:`PERTURBATIONS`; values are factors unless stated):

``tower_stiffness``
    Tower bending stiffness EI (fore-aft and side-to-side) times the factor: the tower-mode rows of the
    stiffness matrix scale, and the tower's structural damping by its square root (the damping *ratio* of the
    tower file stays, as ElastoDyn defines it). Damage, a softer foundation, a model error in EI.
``platform_mass``
    Platform (spar) mass and its inertia about its own centre of mass times the factor (uniform ballast or
    marine growth), with the platform weight's pitch/roll restoring ``-m g z_cm``. The static heave set-down the
    extra weight would cause (about 6.6 m for +3 %) is not modelled: the model keeps its reference draft.
``mooring_stiffness``
    The linear mooring stiffness matrix (all three lines, 6 x 6) times the factor. The catenary's nonlinear
    excess over its tangent (the ``mooring_nonlinear`` effect) is unchanged.
``rotor_mass_imbalance``
    Static unbalance of the rotor as the fraction by which one blade is heavier than the others: the
    ``rotor_1p`` effect's ``mass_imbalance`` becomes ``fraction x`` the blade's first mass moment about the
    rotor apex (0.02 -> 7.75 t·m, against the nominal 2 t·m).
any effect name of :data:`surrogates.EFFECTS`
    That effect's strength, e.g. ``quadratic_drag=1.5`` (Morison drag 50 % stronger).

:data:`STANDARD_PERTURBATIONS` holds the five of issue 17's model-error table.

Examples
--------
>>> from surrogates.model_error import perturbed_model
>>> m = perturbed_model({"tower_stiffness": 0.95})
>>> f0 = perturbed_model({}).modal_analysis().frequency("tower_fa_1")
>>> bool(m.modal_analysis().frequency("tower_fa_1") < f0)
True
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from functools import cached_property
from typing import Any

import numpy as np

from .effects import EFFECTS
from .model import FOWTModel, RotorHarmonics, SensorNoise
from .oc3 import GRAVITY
from .structure import N_DOF, Structure, build_structure

__all__ = ["PERTURBATIONS", "STANDARD_PERTURBATIONS", "PerturbedModel", "perturbed_model", "check_perturbations"]

PERTURBATIONS: dict[str, str] = {
    "tower_stiffness": "tower bending stiffness EI, fore-aft and side-to-side (factor)",
    "platform_mass": "platform mass and inertia about its CM (factor)",
    "mooring_stiffness": "linear mooring stiffness of all lines (factor)",
    "rotor_mass_imbalance": "one blade heavier by this fraction of its mass (static rotor unbalance)",
}
"""The structural perturbations (besides every effect name, whose value is the effect's strength)."""

STANDARD_PERTURBATIONS: dict[str, dict[str, float]] = {
    "tower stiffness x0.95": {"tower_stiffness": 0.95},
    "platform mass +3 %": {"platform_mass": 1.03},
    "drag x1.5": {"quadratic_drag": 1.5},
    "mooring stiffness -30 %": {"mooring_stiffness": 0.70},
    "rotor mass imbalance 2 %": {"rotor_mass_imbalance": 0.02},
}
"""Issue 17's model-error table: label -> perturbation."""

_STRUCTURAL = ("tower_stiffness", "platform_mass", "mooring_stiffness")


def check_perturbations(changes: Mapping[str, Any] | None) -> dict[str, float]:
    """Validate a perturbation mapping; returns ``{name: float}``.

    Raises
    ------
    ValueError
        Unknown name, or a value that is not finite, not positive (factors) or negative (strengths, fractions).
    """
    out: dict[str, float] = {}
    for name, value in dict(changes or {}).items():
        if name not in PERTURBATIONS and name not in EFFECTS:
            raise ValueError(f"unknown perturbation {name!r}; known: {sorted(PERTURBATIONS)} and the effects "
                             f"{sorted(EFFECTS)}")
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"perturbation {name!r} must be a number, got {value!r}") from None
        if not math.isfinite(v) or v < 0 or (name in _STRUCTURAL and v == 0):
            kind = "a positive factor" if name in _STRUCTURAL else "finite and >= 0"
            raise ValueError(f"perturbation {name!r} must be {kind}, got {value!r}")
        out[str(name)] = v
    return out


def _perturbed_structure(st: Structure, changes: Mapping[str, float]) -> Structure:
    """A copy of ``st`` with the structural perturbations applied (see the module docstring)."""
    d = st.data
    mass, k, c = st.mass.copy(), st.stiffness.copy(), st.damping.copy()
    bodies = list(st.bodies)
    f = changes.get("tower_stiffness", 1.0)
    if f != 1.0:  # the tower-mode block holds only the EI integral (hydrostatics/mooring act on the platform)
        k[6:N_DOF, 6:N_DOF] *= f
        c[6:N_DOF, 6:N_DOF] *= math.sqrt(f)
    f = changes.get("platform_mass", 1.0)
    if f != 1.0:
        i = next(j for j, b in enumerate(bodies) if b.name == "platform")
        b = bodies[i]
        extra = (f - 1.0) * (b.mass * b.translation.T @ b.translation + b.rotation.T @ b.inertia @ b.rotation)
        mass += 0.5 * (extra + extra.T)
        bodies[i] = dataclasses.replace(b, mass=b.mass * f, inertia=b.inertia * f)
        restoring = (f - 1.0) * (-d.platform_mass * GRAVITY * d.platform_cm_z)
        k[3, 3] += restoring
        k[4, 4] += restoring
        d = dataclasses.replace(d, platform_mass=d.platform_mass * f,
                                platform_inertia=np.asarray(d.platform_inertia) * f)
    f = changes.get("mooring_stiffness", 1.0)
    if f != 1.0:
        k[:6, :6] += (f - 1.0) * st.data.mooring_stiffness
        d = dataclasses.replace(d, mooring_stiffness=np.asarray(st.data.mooring_stiffness) * f)
    return dataclasses.replace(st, data=d, mass=mass, stiffness=0.5 * (k + k.T), damping=c, bodies=tuple(bodies))


class PerturbedModel(FOWTModel):
    """A :class:`FOWTModel` whose structure (and rotor unbalance, effect strengths) differ from the nominal.

    Build it with :func:`perturbed_model`. It simulates, linearises and analyses like its base class;
    :meth:`with_effects` and :meth:`with_noise` keep the perturbation, :meth:`to_dict` records it under
    ``"perturbation"``.

    Parameters
    ----------
    perturbation : mapping of str to float
        Structural perturbations (:data:`PERTURBATIONS`; the effect strengths and the unbalance are passed to
        :class:`FOWTModel` by :func:`perturbed_model`).
    *args, **kwargs
        :class:`FOWTModel`'s arguments.
    """

    def __init__(self, *args: Any, perturbation: Mapping[str, float] | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.perturbation = check_perturbations(perturbation)

    @cached_property
    def structure(self) -> Structure:
        """The perturbed linearised structure (cached per model)."""
        return _perturbed_structure(build_structure(), self.perturbation)

    def _copy(self, effects: Mapping[str, float], noise: SensorNoise) -> PerturbedModel:
        return PerturbedModel(effects, harmonics=self.harmonics, noise=noise, accel_gravity=self.accel_gravity,
                              gauge_heights=self.gauge_heights, perturbation=self.perturbation)

    def with_effects(self, **strengths: float) -> PerturbedModel:
        """New perturbed model with some effect strengths changed."""
        base = FOWTModel.with_effects(self, **strengths)
        return self._copy(base.effects, self.noise)

    def with_noise(self, noise: SensorNoise | None = None, **changes: float) -> PerturbedModel:
        """New perturbed model with another sensor-noise specification."""
        base = FOWTModel.with_noise(self, noise, **changes)
        return self._copy(self.effects, base.noise)

    def to_dict(self) -> dict:
        """:meth:`FOWTModel.to_dict` plus ``"perturbation"``."""
        return {**super().to_dict(), "perturbation": dict(self.perturbation)}

    def __repr__(self) -> str:
        return f"PerturbedModel({self.perturbation}, {super().__repr__()})"


def perturbed_model(changes: Mapping[str, Any] | None, base: FOWTModel | None = None) -> FOWTModel:
    """The surrogate with named physical perturbations (a "truth" that differs from the nominal model).

    Parameters
    ----------
    changes : mapping of str to float
        Perturbation name -> value: the structural ones of :data:`PERTURBATIONS` (factors;
        ``rotor_mass_imbalance`` a fraction of one blade's mass) and effect strengths by effect name. Empty or
        None: ``base`` itself.
    base : FOWTModel, optional
        The nominal model (default ``FOWTModel()``): its effects, harmonics, noise, gauges are kept.

    Returns
    -------
    FOWTModel
        ``base`` unchanged when there is nothing structural to change, else a :class:`PerturbedModel`.

    Raises
    ------
    ValueError
        Unknown perturbation names or bad values (:func:`check_perturbations`).
    """
    base = base if base is not None else FOWTModel()
    ch = check_perturbations(changes)
    effects = {**base.effects, **{k: v for k, v in ch.items() if k in EFFECTS}}
    harmonics = base.harmonics
    if "rotor_mass_imbalance" in ch:
        harmonics = RotorHarmonics(**{**dataclasses.asdict(harmonics), "mass_imbalance":
                                      ch["rotor_mass_imbalance"] * base.structure.data.blade_first_moment})
    structural = {k: v for k, v in ch.items() if k in _STRUCTURAL}
    kwargs = {"harmonics": harmonics, "noise": base.noise, "accel_gravity": base.accel_gravity,
              "gauge_heights": base.gauge_heights}
    if structural:
        return PerturbedModel(effects, perturbation=structural, **kwargs)
    return FOWTModel(effects, **kwargs)
