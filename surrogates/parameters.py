"""Named structural and hydrodynamic parameter scalings: model error as a model builds it.

Each parameter is a dimensionless multiplier of a physical property of the OC3 Hywind surrogate (1.0 nominal):
a tower that lost stiffness, ballast or marine growth, a wrong added-mass or drag coefficient, a damaged mooring
line. ``FOWTModel(parameters={"tower_fa_stiffness": 0.95})`` builds the perturbed model; the discrepancy workflow
(``fowt_env.discrepancy``) searches them as candidates beside the effects of :data:`surrogates.EFFECTS`.

How each scaling acts (the generalised coordinates of :mod:`surrogates.structure`):

* ``tower_fa_stiffness``, ``tower_ss_stiffness`` -- the bending stiffness EI of the tower in one plane: the
  elastic stiffness of that plane's two tower modes. The structural damping coefficient follows as
  ``sqrt(s)`` (ElastoDyn's definition keeps the damping *ratio*). The Ritz mode shapes are the nominal ones
  (for the few-percent changes of damage the shapes barely move; the frequencies do).
* ``platform_mass`` -- platform mass at its centre of mass (ballast, marine growth): its translational and
  rotational inertia about the reference point, and the restoring moment of its weight in roll and pitch
  (the draft is taken as re-trimmed: the weight's heave balance is not changed).
* ``platform_inertia`` -- the platform's roll, pitch and yaw inertia about its own centre of mass.
* ``added_mass`` -- the hydrodynamic added-mass matrix (all six DOFs).
* ``drag_cd`` -- the Morison drag coefficient of the spar: the equivalent linear damping and excitation and
  the ``quadratic_drag`` remainder alike.
* ``mooring_line_1`` ... ``mooring_line_3`` -- the linearised restoring of one line (its 6x6 tangent stiffness
  from the catenary solve of :mod:`surrogates.mooring`; line 1 downwind, 2 and 3 at +-120 deg). The offset-
  dependent remainder of the ``mooring_nonlinear`` effect and the crow-foot yaw spring are not scaled.
* ``structural_damping`` -- the tower's structural damping (all four tower modes).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache
from typing import Any

import numpy as np

from .drag import DragStrips, drag_strips
from .model import FOWTModel, SensorNoise
from .oc3 import GRAVITY
from .structure import Structure, build_structure

__all__ = ["Parameter", "PARAMETERS", "ParametricModel", "as_parametric", "resolve_parameters",
           "scaled_structure", "scaled_drag", "line_tangent_stiffness"]


@dataclass(frozen=True)
class Parameter:
    """A named parameter scaling of the surrogate.

    Attributes
    ----------
    name : str
    doc : str
        One-line physical description.
    bounds : tuple of float
        Plausible range of the multiplier (-): the discrepancy workflow's search range.
    probe : float
        A multiplier inside ``bounds`` that changes the response clearly (the workflow's first probe).
    """

    name: str
    doc: str
    bounds: tuple[float, float]
    probe: float


PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("tower_fa_stiffness", "Fore-aft bending stiffness EI of the tower (damage, foundation "
                  "flexibility): the fore-aft tower modes' frequencies move as its square root.", (0.5, 1.5), 0.8),
        Parameter("tower_ss_stiffness", "Side-to-side bending stiffness EI of the tower.", (0.5, 1.5), 0.8),
        Parameter("platform_mass", "Platform mass at its centre of mass (ballast, marine growth): inertia and "
                  "the weight's roll/pitch restoring.", (0.8, 1.2), 1.05),
        Parameter("platform_inertia", "Roll, pitch and yaw inertia of the platform about its centre of mass.",
                  (0.5, 1.5), 1.2),
        Parameter("added_mass", "Hydrodynamic added mass of the spar (all six DOFs).", (0.5, 1.5), 1.2),
        Parameter("drag_cd", "Morison drag coefficient of the spar (linearised damping and quadratic "
                  "remainder).", (0.25, 3.0), 2.0),
        Parameter("mooring_line_1", "Linearised restoring of mooring line 1 (downwind, 0 deg).", (0.2, 1.5), 0.6),
        Parameter("mooring_line_2", "Linearised restoring of mooring line 2 (+120 deg).", (0.2, 1.5), 0.6),
        Parameter("mooring_line_3", "Linearised restoring of mooring line 3 (240 deg).", (0.2, 1.5), 0.6),
        Parameter("structural_damping", "Structural damping of the tower's bending modes.", (0.25, 4.0), 2.0),
    )
}


def resolve_parameters(parameters: Mapping[str, float] | None) -> dict[str, float]:
    """Normalise a parameter specification to ``{name: multiplier}`` over all of :data:`PARAMETERS`.

    Parameters
    ----------
    parameters : mapping or None
        Multipliers of some parameters (-); the others stay 1.0. None: all nominal.

    Returns
    -------
    dict
        Multiplier per parameter name (-).

    Raises
    ------
    ValueError
        Unknown parameter name, or a multiplier that is not finite and > 0.
    """
    out = {name: 1.0 for name in PARAMETERS}
    for name, value in dict(parameters or {}).items():
        if name not in PARAMETERS:
            raise ValueError(f"parameters: unknown parameter {name!r}; known parameters are {sorted(PARAMETERS)}")
        try:
            v = float(value)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"parameters: multiplier of {name!r} must be a number, got {value!r}") from exc
        if not np.isfinite(v) or v <= 0:
            raise ValueError(f"parameters: multiplier of {name!r} must be finite and > 0, got {value!r}")
        out[name] = v
    return out


@lru_cache(maxsize=3)
def line_tangent_stiffness(line: int) -> np.ndarray:
    """6x6 tangent stiffness of one mooring line about SWL at zero offset (N/m, N, N·m/rad).

    Parameters
    ----------
    line : int
        Line index 0, 1, 2 (line 1 is downwind). The three matrices add up to
        :func:`surrogates.mooring.tangent_stiffness`.

    Returns
    -------
    ndarray, shape (6, 6)
    """
    from .mooring import _catenary, _geometry, _rotation

    anchors, fairs = _geometry()
    anc, f0 = anchors[line], fairs[line]

    def load(q: np.ndarray) -> np.ndarray:
        rot = _rotation(*q[3:])
        arm = rot @ f0  # reference point at SWL
        fair = q[:3] + arm
        span = anc[:2] - fair[:2]
        xf = float(np.hypot(*span))
        h, v, _, _ = _catenary(xf, fair[2] - anc[2])
        force = np.array([h * span[0] / xf, h * span[1] / xf, -v])
        return np.concatenate([force, np.cross(arm, force)])

    k = np.empty((6, 6))
    for j in range(6):
        step = 0.05 if j < 3 else 5e-4
        dq = np.zeros(6)
        dq[j] = step
        k[:, j] = -(load(dq) - load(-dq)) / (2 * step)
    return 0.5 * (k + k.T)


def scaled_structure(structure: Structure, parameters: Mapping[str, float]) -> Structure:
    """The structure with the parameter multipliers applied (a new object; nominal values return ``structure``).

    Parameters
    ----------
    structure : Structure
        The nominal structure (:func:`surrogates.structure.build_structure`).
    parameters : mapping
        Multipliers (-) as resolved by :func:`resolve_parameters`.

    Returns
    -------
    Structure
    """
    p = resolve_parameters(parameters)
    if all(v == 1.0 for v in p.values()):
        return structure
    d = structure.data
    mass = structure.mass.copy()
    k = structure.stiffness.copy()
    c = structure.damping.copy()
    platform = next(b for b in structure.bodies if b.name == "platform")
    s_m = p["platform_mass"]
    mass += (s_m - 1.0) * platform.mass * platform.translation.T @ platform.translation
    for i in (3, 4):  # weight of the platform below SWL: restoring in roll and pitch
        k[i, i] += -(s_m - 1.0) * platform.mass * GRAVITY * d.platform_cm_z
    mass += (p["platform_inertia"] - 1.0) * platform.rotation.T @ platform.inertia @ platform.rotation
    mass[:6, :6] += (p["added_mass"] - 1.0) * d.added_mass
    for i in range(3):
        k[:6, :6] += (p[f"mooring_line_{i + 1}"] - 1.0) * line_tangent_stiffness(i)
    for idx, s in (((6, 7), p["tower_fa_stiffness"]), ((8, 9), p["tower_ss_stiffness"])):
        block = np.ix_(idx, idx)
        k[block] *= s
        for i in idx:
            c[i, i] *= np.sqrt(s)
    for i in (6, 7, 8, 9):  # the four tower modes (the blades' flap keeps its own damping)
        c[i, i] *= p["structural_damping"]
    return replace(structure, mass=0.5 * (mass + mass.T), stiffness=0.5 * (k + k.T), damping=c)


def scaled_drag(strips: DragStrips, factor: float) -> DragStrips:
    """Drag strips with the drag coefficient multiplied by ``factor`` (-)."""
    if factor == 1.0:
        return strips
    return DragStrips(strips.z, strips.coef * factor, strips.along * factor, strips.across * factor,
                      strips.direction)


class ParametricModel(FOWTModel):
    """A :class:`FOWTModel` with named parameter multipliers (:data:`PARAMETERS`).

    It simulates, linearises and analyses like its base class; :meth:`with_effects`, :meth:`with_noise` and
    :meth:`with_parameters` return new models that keep the other settings; :meth:`to_dict` records the
    multipliers under ``"parameters"``.

    Parameters
    ----------
    effects : {"all", "none"} or mapping, optional
        As for :class:`FOWTModel`.
    parameters : mapping of str to float, optional
        Multipliers of :data:`PARAMETERS` (-); the others stay 1.0.
    **kwargs
        :class:`FOWTModel`'s keyword arguments (harmonics, noise, accel_gravity, gauge_heights).

    Examples
    --------
    >>> from surrogates.parameters import ParametricModel
    >>> soft = ParametricModel(parameters={"tower_fa_stiffness": 0.9})
    >>> f = soft.modal_analysis().frequency("tower_fa_1")
    >>> bool(f < ParametricModel().modal_analysis().frequency("tower_fa_1"))
    True
    """

    def __init__(self, effects: str | Mapping[str, float] | None = "all", *,
                 parameters: Mapping[str, float] | None = None, **kwargs: Any) -> None:
        super().__init__(effects, **kwargs)
        self._parameters = resolve_parameters(parameters)

    @property
    def parameters(self) -> dict[str, float]:
        """Multiplier of every parameter (a copy)."""
        return dict(self._parameters)

    @cached_property
    def structure(self) -> Structure:
        """The linearised structure with the multipliers applied (cached per model)."""
        return scaled_structure(build_structure(), self._parameters)

    def _drag_strips(self) -> DragStrips:
        return scaled_drag(drag_strips(), self._parameters["drag_cd"])

    def _copy(self, effects: Mapping[str, float], noise: SensorNoise, parameters: Mapping[str, float]
              ) -> ParametricModel:
        return ParametricModel(effects, parameters=parameters, harmonics=self.harmonics, noise=noise,
                               accel_gravity=self.accel_gravity, gauge_heights=self.gauge_heights)

    def with_parameters(self, **multipliers: float) -> ParametricModel:
        """New model with some parameter multipliers changed, e.g. ``m.with_parameters(drag_cd=1.5)``."""
        checked = resolve_parameters(multipliers)
        return self._copy(self.effects, self.noise, {**self._parameters, **{k: checked[k] for k in multipliers}})

    def with_effects(self, **strengths: float) -> ParametricModel:
        """New model with some effect strengths changed (the parameters are kept)."""
        return self._copy(FOWTModel.with_effects(self, **strengths).effects, self.noise, self._parameters)

    def with_noise(self, noise: SensorNoise | None = None, **changes: float) -> ParametricModel:
        """New model with another sensor-noise specification (the parameters are kept)."""
        return self._copy(self.effects, FOWTModel.with_noise(self, noise, **changes).noise, self._parameters)

    def to_dict(self) -> dict:
        """:meth:`FOWTModel.to_dict` plus ``"parameters"``."""
        return {**super().to_dict(), "parameters": self.parameters}

    @classmethod
    def from_dict(cls, d: Mapping) -> ParametricModel:
        """Inverse of :meth:`to_dict`."""
        base = FOWTModel.from_dict(d)
        return cls(base.effects, parameters=d.get("parameters"), harmonics=base.harmonics, noise=base.noise,
                   accel_gravity=base.accel_gravity, gauge_heights=base.gauge_heights)

    def __repr__(self) -> str:
        changed = {k: v for k, v in self._parameters.items() if v != 1.0}
        return f"ParametricModel({changed}, {super().__repr__()})"


def as_parametric(model: FOWTModel) -> ParametricModel:
    """``model`` as a :class:`ParametricModel` (itself if it is one; else nominal parameters, same settings)."""
    if isinstance(model, ParametricModel):
        return model
    return ParametricModel(model.effects, harmonics=model.harmonics, noise=model.noise,
                           accel_gravity=model.accel_gravity, gauge_heights=model.gauge_heights)
