"""Named, switchable physical effects: the vocabulary of the discrepancy workflow.

Each effect has a strength: 1.0 is nominal, 0.0 switches it off, other values scale it (e.g. 1.5 = 50 %
stronger drag). ``FOWTModel(effects="none")`` is the linear turbine: the linearisation of the full model about its
operating point. It switches off every effect that a linearisation cannot hold (``linear=False``) and keeps the
linear ones (aerodynamic damping, gyroscopics, P-delta) on, as every linear model of this turbine (OpenFAST's
included) has them; they can still be switched off by name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

__all__ = ["Effect", "EFFECTS", "resolve_effects"]


@dataclass(frozen=True)
class Effect:
    """A named physical effect of the surrogate.

    Attributes
    ----------
    name : str
    doc : str
        One-line physical description.
    linear : bool
        True if the effect is linear in the state (it then appears in ``linearize()``).
    """

    name: str
    doc: str
    linear: bool


EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect("quadratic_drag", "Morison viscous drag 0.5 rho Cd D |u_rel| u_rel on the spar, u_rel = wave "
               "particle velocity minus platform velocity, integrated over depth strips.", linear=False),
        Effect("mooring_nonlinear", "Offset-dependent catenary restoring of the three OC3 lines (hardening with "
               "surge/sway offset, set-down), beyond the linear tangent stiffness.", linear=False),
        Effect("aero_damping", "Thrust and rotor torque respond to the wind relative to the moving hub (dT/dV times "
               "the hub's fore-aft velocity), and the disc's tilt and yaw rates load it like wind gradients, answered "
               "DISC_RATE_LAG_DEG of azimuth late: aerodynamic damping of platform pitch and yaw and of the tower's "
               "bending, and a yaw moment against the gyroscopic one.", linear=True),
        Effect("gyroscopic", "Angular momentum of the spinning rotor couples tower-top pitch and yaw rates "
               "(moment H x omega).", linear=True),
        Effect("rotor_3p", "Blade passing: tower shadow and wind shear modulate thrust, torque and rotor moments "
               "at 3P and 6P.", linear=False),
        Effect("rotor_1p", "Rotor mass and aerodynamic imbalance: a rotating in-plane force and 1P thrust and "
               "moment variations.", linear=False),
        Effect("rotor_nonlinear", "Thrust and torque from the Cp/Ct/Cq(lambda, beta) surfaces at every step with the "
               "rotor-effective wind relative to the moving hub, under the OC3 Hywind DISCON controller (torque-law "
               "regions, gain-scheduled PI pitch, saturation and rate limits); off = rotor and controller "
               "linearised about the operating point. Any strength > 0 switches it on.", linear=False),
        Effect("rotor_asymmetry", "Rotor yaw and tilt moments and side force from the gradients of the turbulent "
               "wind over the disc (and the mean shear): what drives roll, yaw and the side-to-side tower response.",
               linear=True),
        Effect("rotor_skew", "Advancing and retreating blades: the wind's component in the rotor plane (the shaft's "
               "inclination under the wind, a yaw misalignment, the hub's own in-plane motion) changes each blade's "
               "airspeed once per revolution, hence its thrust and in-plane force: the inclined rotor's yaw moment "
               "and the yawed rotor's tilt moment (AeroDyn's driver on the deck's rotor, with its skewed wake, at the "
               "blades' mean deflection, following the blade pitch along the regulated operating points); a force "
               "along the in-plane wind and a yaw moment across the lateral one (AeroDyn's skewed wake and the "
               "blades' cone, growing with their downwind bend; AeroDyn's driver on the deck's rotor yawed +/-3 deg, "
               "straight and bent: what damps the operating platform's roll as OpenFAST's flexible rotor does); and "
               "the coned blades and AeroDyn's skewed wake meet that in-plane wind as a gradient against it, which "
               "takes back part of the shear's side force (AeroDyn's driver on the deck's rotor, inclined 5 and "
               "10 deg).", linear=True),
        Effect("blade_deflection", "The blades' collective flap deflection bends them downwind at constant length "
               "(coned, turned by their slope, shorter in radius): the rotor's thrust and torque coefficients fall "
               "with the square of the tip deflection, by ~2 % and ~3 % at rated's 5 m (AeroDyn on the deck's bent "
               "blade); OpenFAST's flexible rotor pitches 0.5-1 deg less than its rigid one at rated. In an "
               "inclined rotor the bent blades also take part of the in-plane wind as axial wind (with rotor_skew): "
               "+2.7 kN of side force at 12 m/s, 10 deg and 5 m of tip deflection.", linear=False),
        Effect("sampled_wind_curvature", "Each blade meets its own wind (the shear and the turbulence over the disc), "
               "and its thrust and torque are curved in it: the rotor carries the second-order share "
               "1/6 d2(load)/dV2 sum_b dv_b^2 beyond the linear blade loads (convex torque: a sheared or turbulent "
               "wind gives more power than its disc mean).", linear=False),
        Effect("tower_drag", "Aerodynamic drag of the tower (Cd = 1.0 under the power-law wind profile), "
               "quadratic in the hub-height wind.", linear=False),
        Effect("cm_kinematics", "Second-order kinematics of the platform's rotations: the centre of mass, ~78 m "
               "below the SWL, rises as the spar tilts, so pitch and roll rates and accelerations force heave "
               "(M z_G (cos(theta) theta'^2 + sin(theta) theta'')) and heave accelerations load pitch and roll; "
               "at a mean tilt, the heave-pitch inertial coupling.", linear=False),
        Effect("hydro_fixed_axes", "HydroDyn's added mass acts on the fixed-axes angular acceleration: under the "
               "mean pitch that the thrust holds, the spar's own yaw is also a fixed-axes roll and meets "
               "sin^2(pitch) of the roll added inertia (OpenFAST's yaw mode drops from 0.12 to ~0.09 Hz at rated "
               "wind); the restoring stays in the body axes.", linear=True),
        Effect("p_delta", "Gravity geometric softening: the weight of tower and RNA acting through the lateral "
               "displacements of tilt and bending (P-delta).", linear=True),
    )
}


def resolve_effects(effects: str | Mapping[str, float] | None) -> dict[str, float]:
    """Normalise an effects specification to ``{name: strength}`` over all of :data:`EFFECTS`.

    Parameters
    ----------
    effects : {"all", "none"} or mapping or None
        ``"all"``/None: every effect at 1.0; ``"none"``: the nonlinear effects at 0.0 and the linear ones at 1.0
        (the linearisation of the full model); a mapping sets the named strengths and leaves the others at 1.0.

    Returns
    -------
    dict
        Strength per effect name (-).

    Raises
    ------
    ValueError
        Unknown effect name, or a strength that is negative or not finite.
    """
    if effects is None or (isinstance(effects, str) and effects == "all"):
        return {name: 1.0 for name in EFFECTS}
    if isinstance(effects, str):
        if effects == "none":
            return {name: (1.0 if e.linear else 0.0) for name, e in EFFECTS.items()}
        raise ValueError(f"effects must be 'all', 'none' or a mapping of effect strengths, got {effects!r}")
    out = {name: 1.0 for name in EFFECTS}
    for name, value in dict(effects).items():
        if name not in EFFECTS:
            raise ValueError(f"effects: unknown effect {name!r}; known effects are {sorted(EFFECTS)}")
        try:
            strength = float(value)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"effects: strength of {name!r} must be a number, got {value!r}") from exc
        if not np.isfinite(strength) or strength < 0:
            raise ValueError(f"effects: strength of {name!r} must be finite and >= 0, got {value!r}")
        out[name] = strength
    return out
