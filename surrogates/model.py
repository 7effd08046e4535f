"""``FOWTModel``: the OC3 Hywind surrogate as a state-space system with switchable physical effects.

State ``x`` (28): generalised displacements ``q`` (13, see :data:`surrogates.structure.DOF_LABELS`), their
rates, the rotor-speed deviation ``dOmega`` (rad/s) and the integral of it ``xi`` (rad, the pitch controller's
integrator). Inputs ``u`` (38), in blocks:

=========  =====  ===========================================================================
block      size   meaning (SI)
=========  =====  ===========================================================================
const      1      1.0: carries the mean loads (gravity offsets, mean thrust, generator torque)
wave       6      first-order wave excitation about the SWL reference point (N, N·m)
wind       1      rotor-effective wind deviation from the mean (m/s)
elev       1      wave elevation at the origin (m; passed to ``Wave1Elev`` only)
hub_wind   1      hub-height point wind (m/s; passed to ``Wind1VelX``, and the tower's aerodynamic drag)
shear      2      linear gradients of the streamwise wind over the rotor disc, ``dU/dy`` and ``dU/dz`` (1/s):
                  the rotor's yaw and tilt moments and side force (the ``rotor_asymmetry`` effect)
action     2      collective blade-pitch offset (rad), generator-torque offset (N·m, low-speed shaft)
hub        6      rotor harmonic loads at the hub, global axes (N, N·m): the 1P/3P/6P effects
nonlinear  13     generalised forces of the nonlinear effects (drag, catenary mooring, the sampled rotor's loads on
                  the blades' cyclic flap modes)
rotor      5      quantities evaluated per step: blade pitch (rad), generator torque (N·m, HSS), electrical
                  power (W), aerodynamic thrust (N) of the nonlinear rotor (``rotor_nonlinear``; they reach the
                  outputs only, their loads enter through ``hub``), and ``V|V|`` of the hub-height wind
                  (m²/s², the ``tower_drag`` effect's load)
=========  =====  ===========================================================================

Outputs are the 55 channels of :data:`surrogates.channels.ALL_CHANNELS` in OpenFAST units. Linear effects
(``aero_damping``, ``gyroscopic``, ``p_delta``, ``rotor_skew``: the advancing blades of the inclined or yawed
rotor) live in ``A`` and the ``const`` and ``wind`` columns of ``B``; nonlinear ones are evaluated per step by the
simulator and enter through the ``hub`` and ``nonlinear`` input blocks (with the nonlinear rotor, the rotor's
linear effects are evaluated there too).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linear_sum_assignment

from .aero import (
    OperatingPoint,
    blade_inplane_gain,
    inclined_rotor_inplane,
    inclined_rotor_moment,
    inclined_rotor_moment_by_pitch,
    inplane_wind_loads,
    operating_point,
    skew_gains,
)
from .channels import ALL_CHANNELS, GAUGE_HEIGHTS, UNITS, tower_channels
from .controller import DISCON
from .drag import DragStrips, drag_strips, wave_velocity_rao, with_relative_velocity_std
from .effects import resolve_effects
from .hydro_axes import platform_in_fixed_axes
from .load_cases import LoadCase, load_case
from .oc3 import GRAVITY, BladeFlapMode
from .radiation import modal_radiation_damping
from .structure import _CYCLIC, _FLAP, DOF_LABELS, N_DOF, Structure, build_structure

__all__ = ["FOWTModel", "ModalResult", "LinearSystem", "RotorHarmonics", "SensorNoise", "STATE_NAMES", "INPUT_NAMES"]

STATE_NAMES: tuple[str, ...] = (
    tuple(DOF_LABELS) + tuple(f"d_{d}" for d in DOF_LABELS) + ("rotor_speed_dev", "pitch_integrator")
)
N_STATE = len(STATE_NAMES)
INPUT_BLOCKS: dict[str, slice] = {
    "const": slice(0, 1),
    "wave": slice(1, 7),
    "wind": slice(7, 8),
    "elev": slice(8, 9),
    "hub_wind": slice(9, 10),
    "shear": slice(10, 12),
    "action": slice(12, 14),
    "hub": slice(14, 20),
    "nonlinear": slice(20, 20 + N_DOF),
    "rotor": slice(20 + N_DOF, 25 + N_DOF),
}
N_INPUT = 25 + N_DOF
INPUT_NAMES: tuple[str, ...] = (
    ("const", "wave_Fx", "wave_Fy", "wave_Fz", "wave_Mx", "wave_My", "wave_Mz", "wind_dev", "wave_elevation",
     "hub_wind", "shear_y", "shear_z", "pitch_offset", "torque_offset", "hub_Fx", "hub_Fy", "hub_Fz", "hub_Mx",
     "hub_My", "hub_Mz")
    + tuple(f"nl_{d}" for d in DOF_LABELS)
    + ("rotor_pitch", "rotor_generator_torque", "rotor_power", "rotor_thrust", "hub_wind_squared")
)
assert len(INPUT_NAMES) == N_INPUT and len(STATE_NAMES) == 2 * N_DOF + 2


@dataclass(frozen=True)
class RotorHarmonics:
    """Nominal amplitudes of the rotor harmonic loads (the ``rotor_3p`` and ``rotor_1p`` effects).

    The 3P/6P terms (tower shadow and the mean shear seen by the blades, applied at the hub: OpenFAST's shaft loads
    behind its flexible blades, so the simulation keeps them off the blades' flap mode) are measured on
    OpenFAST's OC3 Hywind deck in steady 12 m/s wind with shear exponent 0.2 (the shared run
    ``d_steady12_Hs2p5_Tp10``; amplitudes of ``RotThrust``, ``YawBrMyp/Mzp`` and ``LSShftTq`` demodulated at 3P
    and 6P against ``Azimuth``), as fractions of this model's aerodynamic thrust and torque at that point
    (601 kN, 4.18 MN·m): thrust 9.8 kN at 3P and 3.9 kN at 6P; tilt 345 kN·m in anti-phase with the thrust
    (the blade pointing down passes the tower's shadow and the shear's slowest wind: the collective thrust dips
    while the tilt moment peaks); yaw 221 kN·m as ``sin 3 psi`` (OpenFAST's phase is 152 deg from it, but with
    that phase this model's 3P platform yaw comes out 3x too large and its fore-aft 3P response 20 % larger:
    the model has no tower torsion); side force 3.7 kN as ``-cos 3 psi`` (OpenFAST: 16 deg from it); torque
    6.2 kN·m; ``psi = 0`` with blade 1 up. They scale with the mean thrust at other wind speeds, except the side
    force, which follows ``V^2 dQ/dV`` at every step (:func:`surrogates.simulate.side_force_law`): OpenFAST's
    side-to-side 3P response in steady wind at 8-18 m/s rises above rated while the thrust falls. The side
    force's 3.7 kN is the 3P amplitude of OpenFAST's tower-top shear force ``YawBrFyp``, a response rather than
    the rotor's own lateral force (the shaft's ``LSShftFya``/``LSShftFza`` turned into the fixed frame with the
    azimuth: 1.4 kN at 3P, 2.1 kN at 18 m/s): an effective side-to-side 3P excitation, whose tower-base response is
    0.64-1.17x OpenFAST's at 8-18 m/s (``tests/test_rotor_harmonics.py``). The 1P terms
    are engineering estimates, not in the OpenFAST deck (its rotor is perfectly balanced): a balancing grade of
    the order of ISO G16 and a small pitch misalignment. Each effect's strength scales them.

    Attributes
    ----------
    thrust_3p, thrust_6p : float
        Thrust modulation at 3P and 6P as a fraction of the mean aerodynamic thrust (-).
    torque_3p : float
        Torque ripple at 3P reaching the nacelle, fraction of the mean aerodynamic torque (-).
    moment_3p : float
        Tilt rotor-moment amplitude at 3P as a fraction of (mean thrust × rotor radius) (-); it peaks when the
        thrust is lowest.
    yaw_moment_3p : float
        Yaw rotor-moment amplitude at 3P, fraction of (mean thrust × rotor radius) (-).
    side_force_3p : float
        Side (in-plane, horizontal) force amplitude at 3P at the 12 m/s operating point, fraction of its thrust
        (-); elsewhere scaled by ``V^2 dQ/dV`` (:func:`surrogates.simulate.side_force_law`).
    thrust_1p : float
        1P thrust variation from aerodynamic imbalance, fraction of mean thrust (-).
    moment_1p : float
        1P tilt/yaw moment amplitude, fraction of (mean thrust × rotor radius) (-).
    mass_imbalance : float
        Static unbalance of the rotor, mass × eccentricity (kg·m).
    """

    thrust_3p: float = 0.0163
    thrust_6p: float = 0.0064
    torque_3p: float = 0.0015
    moment_3p: float = 0.0091
    thrust_1p: float = 0.005
    moment_1p: float = 0.003
    mass_imbalance: float = 2000.0
    yaw_moment_3p: float = 0.0058
    side_force_3p: float = 0.0062


@dataclass(frozen=True)
class SensorNoise:
    """Additive sensor noise: white plus coloured (first-order low-pass, i.e. AR(1)) per kind of channel.

    Standard deviations are in each channel's output unit; ``scale`` multiplies all of them (0 = noise free).

    Attributes
    ----------
    acceleration_white, acceleration_coloured : float
        Tower accelerations (m/s²).
    moment_white, moment_coloured : float
        Tower bending moments (kN·m).
    platform_white : float
        Platform motions (m or deg).
    other_white : float
        RotSpeed (rpm), Wave1Elev (m), Wind1VelX (m/s).
    correlation_time : float
        Correlation time of the coloured part (s).
    scale : float
        Overall multiplier (-).
    """

    acceleration_white: float = 0.005
    acceleration_coloured: float = 0.002
    moment_white: float = 20.0
    moment_coloured: float = 20.0
    platform_white: float = 0.01
    other_white: float = 0.01
    correlation_time: float = 5.0
    scale: float = 1.0

    def std(self, channels: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """White and coloured standard deviations per channel (output units)."""
        white = np.empty(len(channels))
        col = np.zeros(len(channels))
        for i, name in enumerate(channels):
            if name.startswith("TwHt") and "AL" in name:
                white[i], col[i] = self.acceleration_white, self.acceleration_coloured
            elif name.startswith("TwHt"):
                white[i], col[i] = self.moment_white, self.moment_coloured
            elif name.startswith("Ptfm"):
                white[i] = self.platform_white
            else:
                white[i] = self.other_white
        for v in (self.acceleration_white, self.acceleration_coloured, self.moment_white, self.moment_coloured,
                  self.platform_white, self.other_white, self.correlation_time, self.scale):
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"noise: all SensorNoise parameters must be finite and >= 0, got {self!r}")
        return white * self.scale, col * self.scale


@dataclass(frozen=True)
class ModalResult:
    """Modal properties of the linearised model.

    Attributes
    ----------
    labels : list of str
        Mode names (``surge`` ... ``yaw``, ``tower_fa_1``, ``tower_ss_1``, ``tower_fa_2``, ``tower_ss_2``).
    frequencies_hz : ndarray
        Damped natural frequencies (Hz).
    damping_ratios : ndarray
        Damping ratios (-).
    shapes : ndarray, (N_DOF, n_modes)
        Real mode shapes in generalised coordinates, largest component +1.
    """

    labels: list[str]
    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    shapes: np.ndarray

    def frequency(self, label: str) -> float:
        """Frequency (Hz) of the mode called ``label``."""
        if label not in self.labels:
            raise ValueError(f"label: no mode {label!r}; modes are {self.labels}")
        return float(self.frequencies_hz[self.labels.index(label)])

    def as_table(self) -> list[dict[str, float | str]]:
        """One dict per mode: label, frequency_hz, damping_ratio."""
        return [{"label": lab, "frequency_hz": float(f), "damping_ratio": float(z)}
                for lab, f, z in zip(self.labels, self.frequencies_hz, self.damping_ratios, strict=True)]

    def __str__(self) -> str:
        rows = [f"{'mode':<12}{'f (Hz)':>10}{'zeta (%)':>10}"]
        rows += [f"{lab:<12}{f:>10.4f}{100 * z:>10.2f}"
                 for lab, f, z in zip(self.labels, self.frequencies_hz, self.damping_ratios, strict=True)]
        return "\n".join(rows)


@dataclass(frozen=True)
class LinearSystem:
    """Continuous-time system ``x' = A x + B u``, ``y = C x + D u`` of a model at one load case (SI, outputs in
    OpenFAST units). ``op`` is the rotor operating point (None when parked)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    channels: tuple[str, ...]
    op: OperatingPoint | None
    rotor_speed: float  # rad/s mean
    effects: dict[str, float]
    structure: Structure = field(repr=False)
    drag: DragStrips | None = field(default=None, repr=False)
    """The Morison drag strips with the equivalent linearisation held in ``A`` (and in the wave forcing)."""
    mean_pitch: float = 0.0
    """Mean platform pitch (rad) under the operating point's mean loads: the ``PtfmRoll``/``PtfmYaw`` rows map the
    platform's body-axes roll and yaw to ElastoDyn's Euler angles about it (``simulate`` adds the rest of that
    map at the instantaneous pitch)."""
    mean_moments: dict[str, tuple[np.ndarray, np.ndarray]] | None = field(default=None, repr=False)
    """Per tower section (``"TwrBs"``, ``"TwHt1"`` ...): its mean rotation (rad) and mean bending-moment vector
    (N m, fixed axes) under the operating point's mean loads (:func:`local_moment_rows`)."""

    def equilibrium(self, nonlinear_force=None, tol: float = 1e-10) -> np.ndarray:
        """Static equilibrium state under the mean loads (and an optional ``nonlinear_force(x) -> (N_DOF,)``)."""
        a_qq = self.A[N_DOF:2 * N_DOF, :N_DOF]
        b_c = self.B[N_DOF:2 * N_DOF, 0]
        b_nl = self.B[N_DOF:2 * N_DOF, INPUT_BLOCKS["nonlinear"]]
        x = np.zeros(N_STATE)
        for _ in range(200):
            f = np.zeros(N_DOF) if nonlinear_force is None else nonlinear_force(x)
            q_new = -np.linalg.solve(a_qq, b_c + b_nl @ f)
            done = np.max(np.abs(q_new - x[:N_DOF])) < tol * (1.0 + np.max(np.abs(q_new)))
            x[:N_DOF] = 0.5 * (x[:N_DOF] + q_new) if nonlinear_force is not None else q_new
            if done:
                break
        return x


def _as_case(case: int | LoadCase | None) -> LoadCase | None:
    if case is None or isinstance(case, LoadCase):
        return case
    if isinstance(case, (int, np.integer)) and not isinstance(case, bool):
        return load_case(int(case))
    raise ValueError(f"case must be an OLC number, a LoadCase or None, got {case!r}")


class FOWTModel:
    """Reduced model of the NREL 5 MW turbine on the OC3 Hywind spar with switchable named effects.

    Parameters
    ----------
    effects : {"all", "none"} or mapping, optional
        Strength of each effect in :data:`surrogates.EFFECTS` (1.0 nominal, 0.0 off). ``"all"`` (default) sets
        every effect to 1.0, ``"none"`` gives the linear model; a mapping sets some and leaves the rest at 1.0.
    harmonics : RotorHarmonics, optional
        Nominal amplitudes of the rotor harmonic loads.
    noise : SensorNoise, optional
        Sensor noise added by :func:`surrogates.simulate`.
    accel_gravity : bool
        If False (default) the tower accelerations are OpenFAST's ``TwHt*ALxt/ALyt``: translational
        accelerations without gravity. If True they include the projection of gravity on the tilted sensor
        axis, as a physical accelerometer measures it (``ALxt = a_x - g * tilt``); such a record no longer
        follows OpenFAST's definition of those channels.
    gauge_heights : sequence of 9 floats, optional
        Heights of the tower gauges above still water (m), gauge 1 first. Default
        :data:`surrogates.channels.GAUGE_HEIGHTS` (10 ... 87.6 m, equally spaced); OpenFAST's OC3 deck with
        ``TwrGagNd = 1, 3, 6, 8, 10, 13, 15, 18, 20`` has them at :data:`OPENFAST_GAUGE_HEIGHTS`.

    Examples
    --------
    >>> import surrogates
    >>> m = surrogates.FOWTModel()
    >>> round(m.modal_analysis().frequency("heave"), 3)
    0.032
    >>> m.without("rotor_3p").effects["rotor_3p"], m.effects["rotor_3p"]
    (0.0, 1.0)
    """

    def __init__(
        self,
        effects: str | Mapping[str, float] | None = "all",
        *,
        harmonics: RotorHarmonics | None = None,
        noise: SensorNoise | None = None,
        accel_gravity: bool = False,
        gauge_heights=None,
    ) -> None:
        self._effects = resolve_effects(effects)
        heights = GAUGE_HEIGHTS if gauge_heights is None else np.asarray(gauge_heights, dtype=float)
        if heights.shape != (len(GAUGE_HEIGHTS),) or not np.all(np.isfinite(heights)):
            raise ValueError(f"gauge_heights must be {len(GAUGE_HEIGHTS)} finite heights (m), got {gauge_heights!r}")
        if np.any(heights < 10.0 - 1e-9) or np.any(heights > 87.6 + 1e-9):
            raise ValueError(f"gauge_heights must lie on the tower, 10 to 87.6 m above SWL, got {heights.tolist()}")
        self.gauge_heights = tuple(float(h) for h in heights)
        self.harmonics = harmonics if harmonics is not None else RotorHarmonics()
        self.noise = noise if noise is not None else SensorNoise()
        self.accel_gravity = bool(accel_gravity)
        for f in self.harmonics.__dataclass_fields__:
            v = getattr(self.harmonics, f)
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"harmonics.{f} must be finite and >= 0, got {v!r}")
        self.noise.std([])  # validates
        self._systems: dict[tuple[LoadCase | None, bool, float | None], LinearSystem] = {}
        # per (case, nonlinear rotor): the simulation's mean pitch, equilibrium, controller state and skew gains
        self._operating_states: dict[tuple[LoadCase | None, bool], tuple] = {}

    # ------------------------------------------------------------------------------------------- effects
    @property
    def effects(self) -> dict[str, float]:
        """Strength of every effect (a copy)."""
        return dict(self._effects)

    def with_effects(self, **strengths: float) -> FOWTModel:
        """New model with some effect strengths changed, e.g. ``m.with_effects(quadratic_drag=1.5)``."""
        checked = resolve_effects(strengths)  # validates names and values
        eff = {**self._effects, **{k: checked[k] for k in strengths}}
        return FOWTModel(eff, harmonics=self.harmonics, noise=self.noise, accel_gravity=self.accel_gravity,
                         gauge_heights=self.gauge_heights)

    def without(self, *names: str) -> FOWTModel:
        """New model with the named effects switched off."""
        return self.with_effects(**{n: 0.0 for n in names})

    def with_noise(self, noise: SensorNoise | None = None, **changes: float) -> FOWTModel:
        """New model with another sensor-noise specification (``scale=0`` for noise-free records)."""
        new_noise = replace(noise if noise is not None else self.noise, **changes)
        return FOWTModel(self._effects, harmonics=self.harmonics, noise=new_noise, accel_gravity=self.accel_gravity,
                         gauge_heights=self.gauge_heights)

    def __repr__(self) -> str:
        on = [f"{k}={v:g}" for k, v in self._effects.items() if v != 0.0]
        return f"FOWTModel(effects={{{', '.join(on)}}})" if on else "FOWTModel(effects='none')"

    def to_dict(self) -> dict:
        """JSON-friendly description (effects, harmonics, noise, accel_gravity)."""
        return {
            "effects": self.effects,
            "harmonics": {f: getattr(self.harmonics, f) for f in self.harmonics.__dataclass_fields__},
            "noise": {f: getattr(self.noise, f) for f in self.noise.__dataclass_fields__},
            "accel_gravity": self.accel_gravity,
            "gauge_heights": list(self.gauge_heights),
        }

    @classmethod
    def from_dict(cls, d: Mapping) -> FOWTModel:
        """Inverse of :meth:`to_dict`."""
        return cls(d.get("effects", "all"), harmonics=RotorHarmonics(**d.get("harmonics", {})),
                   noise=SensorNoise(**d.get("noise", {})), accel_gravity=d.get("accel_gravity", False),
                   gauge_heights=d.get("gauge_heights"))

    @cached_property
    def structure(self) -> Structure:
        """The linearised structure (shared, cached)."""
        return build_structure()

    def _drag_strips(self) -> DragStrips:
        """The spar's Morison drag strips before their linearisation about a load case (a subclass that changes the
        drag coefficient overrides this, as :class:`surrogates.parameters.ParametricModel` does)."""
        return drag_strips()

    # -------------------------------------------------------------------------------------- state space
    def system(self, case: int | LoadCase | None = None) -> LinearSystem:
        """Continuous-time state-space system at a load case (cached per case).

        Parameters
        ----------
        case : int or LoadCase or None
            Load case; None means parked (no wind, rotor locked, still water).
        """
        return self._system(case, nonlinear_rotor=False)

    def _system(self, case: int | LoadCase | None, nonlinear_rotor: bool,
                mean_pitch: float | None = None) -> LinearSystem:
        """The linear system, or (``nonlinear_rotor``) its structural part for the simulation's nonlinear rotor:
        no linearised aerodynamic or controller terms, the rotor speed and thrust evaluated per step instead.
        ``mean_pitch`` (rad): the mean platform pitch at which the pitched platform's terms are formed (the
        fixed-axes hydrodynamics, the tilted yaw's gravity stiffness, the Euler-angle output rows); default the
        pitch of the linear model's static deflection under the operating point's thrust."""
        lc = _as_case(case)
        operating = lc is not None and lc.wind_speed > 0 and lc.rotor_rpm > 0
        pitch_key = None if mean_pitch is None else round(float(mean_pitch), 9)
        key = (lc, bool(nonlinear_rotor and operating), pitch_key)
        if key not in self._systems:
            self._systems[key] = self._assemble(lc, key[1], pitch_key)
        return self._systems[key]

    def _assemble(self, lc: LoadCase | None, nonlinear_rotor: bool = False,  # noqa: C901
                  mean_pitch_override: float | None = None) -> LinearSystem:
        st = self.structure
        eff = self._effects
        s_aero, s_gyro, s_pd = eff["aero_damping"], eff["gyroscopic"], eff["p_delta"]
        operating = lc is not None and lc.wind_speed > 0 and lc.rotor_rpm > 0
        op = operating_point(lc.wind_speed, lc.rotor_rpm, st.rotor_inertia_lss) if operating else None
        omega0 = op.rotor_speed if op is not None else 0.0
        linear_rotor = op is not None and not nonlinear_rotor

        m = st.mass
        k = st.stiffness + s_pd * st.stiffness_pdelta
        # the turning blades' flap mode stiffens with the centrifugal tension (rotor speed of the operating point)
        k[_FLAP, _FLAP] += st.data.n_blades * st.data.blade_flap.centrifugal * omega0**2
        c = st.damping.copy()
        _cyclic_flap_terms(st, omega0, s_gyro, k, c)
        e_s = st.shaft_axis
        h_v = e_s @ st.hub_translation  # hub velocity along the shaft per qdot == generalised thrust direction
        r_s = e_s @ st.tower_top_rotation  # generalised force of a moment about the shaft at the tower top
        # HydroDyn's added mass acts in the fixed axes: at the mean pitch that the thrust holds, the spar's own yaw
        # is also a fixed-axes roll (surrogates.hydro_axes; the restoring stays in the body axes)
        f_static = st.gravity_load + (h_v * op.thrust + r_s * op.generator_torque_lss if op is not None else 0.0)
        q_static = np.linalg.solve(k, f_static)
        mean_pitch = float(q_static[4]) if mean_pitch_override is None else float(mean_pitch_override)
        # the weights under that pitch: the platform's own yaw y turns the tower's lateral axis by y sin(pitch) out
        # of the horizontal, so a lateral deflection d (platform axes) raises a mass m by d y sin(pitch) (ElastoDyn's
        # exact kinematics; the p_delta family of geometric stiffness)
        k += s_pd * tilted_yaw_gravity_stiffness(st, mean_pitch)
        if op is not None and eff["hydro_fixed_axes"] > 0:
            m, k = platform_in_fixed_axes(m, k, st.data.added_mass, mean_pitch, eff["hydro_fixed_axes"])
        # a turning rotor is free about its shaft: its polar inertia follows the nacelle's roll about the shaft only
        # through the generator (rotor_free_inertia); parked, it is locked to the nacelle (as in BModes)
        spin_coupling = free_spin = 0.0
        if op is not None:
            spin_coupling, free_spin = rotor_free_inertia(st)
            m = m - free_spin * np.outer(r_s, r_s)
        spin_share = 1.0 - spin_coupling / st.rotor_inertia_lss if op is not None else 0.0
        # the spar's WAMIT radiation damping at the tower modes' frequencies (surrogates.radiation)
        c += modal_radiation_damping(m, k)
        j_hub, r_tt = st.hub_translation, st.tower_top_rotation

        # thrust deviation dT and generator torque Qg as rows over [x; u]
        n_x, n_u = N_STATE, N_INPUT
        t_x, t_u = np.zeros(n_x), np.zeros(n_u)
        qa_x, qa_u = np.zeros(n_x), np.zeros(n_u)  # aerodynamic torque deviation
        qg_x, qg_u = np.zeros(n_x), np.zeros(n_u)  # generator torque deviation
        t0 = qg0 = 0.0
        iw, ia = INPUT_BLOCKS["wind"].start, INPUT_BLOCKS["action"].start
        if linear_rotor:
            t0, qg0 = op.thrust, op.generator_torque_lss
            pitch_x = np.zeros(n_x)
            pitch_x[2 * N_DOF] = op.kp
            pitch_x[2 * N_DOF + 1] = op.ki
            for row_x, row_u, dv, dw, db in ((t_x, t_u, op.dT_dV, op.dT_dOmega, op.dT_dpitch),
                                             (qa_x, qa_u, op.dQ_dV, op.dQ_dOmega, op.dQ_dpitch)):
                row_u[iw] += dv
                row_x[N_DOF:2 * N_DOF] += -s_aero * dv * h_v
                row_x[2 * N_DOF] += dw
                row_x += db * pitch_x
                row_u[ia] += db
            qg_x[2 * N_DOF] = op.dQgen_dOmega
            qg_u[ia + 1] = 1.0

        # generalised forces f = F_x x + F_u u (besides -K q - C qdot)
        f_x = np.zeros((N_DOF, n_x))
        f_u = np.zeros((N_DOF, n_u))
        f_x += np.outer(h_v, t_x) + np.outer(r_s, qg_x)
        f_u += np.outer(h_v, t_u) + np.outer(r_s, qg_u)
        if linear_rotor:  # the free rotor's share of its torque imbalance on the nacelle: (J - c) / J (Qa - Qg)
            f_x += spin_share * np.outer(r_s, qa_x - qg_x)
            f_u += spin_share * np.outer(r_s, qa_u - qg_u)
        f_u[:, 0] += st.gravity_load + h_v * t0 + r_s * qg0
        # the mean thrust follows the rotor axis as the tower top pitches and yaws (a rotation theta about axis a
        # turns e_s by theta e_a x e_s): pitch gives the platform's set-down and heave-pitch coupling under thrust,
        # yaw a side force T psi that drives sway and roll (the simulation's rotor does the same; roll, which
        # turns only the shaft's tilt component, is left out there and here)
        # The tower's and the blades' modes deflect in the axes of the platform and of the rotor, which turn with
        # the platform as the thrust does: for them (as in ElastoDyn) only the tower top's rotation relative to the
        # platform turns the thrust. With the nonlinear rotor the simulation turns it by the top's whole rotation
        # (through the hub loads); the mean thrust's share of that on these modes is taken back here.
        for axis in (1, 2):
            follow = np.outer(j_hub.T @ np.cross(np.eye(3)[axis], e_s), r_tt[axis])
            if linear_rotor:
                follow[6:, 3:6] = 0.0
                f_x[:, :N_DOF] += t0 * follow
            elif op is not None and nonlinear_rotor:
                f_x[6:, 3:6] -= op.thrust * follow[6:, 3:6]
        f_u[:6, INPUT_BLOCKS["wave"]] += np.eye(6)
        hub = INPUT_BLOCKS["hub"]
        f_u[:, hub.start:hub.start + 3] += j_hub.T
        f_u[:, hub.start + 3:hub.stop] += r_tt.T
        f_u[:, INPUT_BLOCKS["nonlinear"]] += np.eye(N_DOF)
        # rotor asymmetry: hub loads per unit disc gradient of the wind, (force, moment) per column
        # (the simulation's nonlinear rotor samples the turbulent field blade by blade instead)
        # (the blades' cyclic flap modes carry them to the hub with the lag of their response: cyclic_flap_lag)
        s_shear = 0.0 if nonlinear_rotor else eff["rotor_asymmetry"]
        shear_loads = _shear_hub_loads(op, st.data.tip_radius, s_shear)
        sh = INPUT_BLOCKS["shear"]
        for col, (force, moment) in zip(range(sh.start, sh.stop), shear_loads, strict=True):
            f_u[:, col] += j_hub.T @ force + r_tt.T @ moment
        # ... and load the cyclic flap modes: a gradient g over the disc meets blade b at the sampling radius r_s
        # as g r_s cos(psi_b) (dU/dz) or -g r_s sin(psi_b) (dU/dy); its thrust acts on the flap mode at the
        # thrust's centre (thrust_shape)
        cyc_gain = np.zeros(2)  # generalised force on (tilt, yaw) cyclic flap per unit (dU/dz, -dU/dy)
        flap = st.data.blade_flap
        v_t, w_t, v_y, w_y = cyclic_flap_aero_shares(st.data.tip_radius)
        if op is not None:
            r_sample = BLADE_SAMPLING_RADIUS * st.data.tip_radius
            cyc_gain[:] = 1.5 * op.dT_dV / 3.0 * flap.thrust_shape * r_sample * np.array([w_t, w_y])
            f_u[_CYCLIC[1], sh.start] += -s_shear * cyc_gain[1]
            f_u[_CYCLIC[0], sh.start + 1] += s_shear * cyc_gain[0]
        # advancing and retreating blades (rotor_skew; the simulation's nonlinear rotor does the same): the wind's
        # in-plane component up the disc, w_z = V sin(tilt - pitch of the top) less the hub's velocity up the disc,
        # and sideways, w_y = -V yaw of the top less the hub's lateral velocity, load the hub (yaw moment and
        # vertical force from w_z, tilt moment and side force from w_y) and the cyclic flap modes, linearised about
        # the inclination the mean thrust holds
        s_skew = eff["rotor_skew"]
        if linear_rotor and s_skew:
            theta0 = float(r_tt[1] @ q_static)
            inc0 = theta0 - st.data.shaft_tilt_rad
            g_t = skew_gains(lc.wind_speed, inc0)[0]
            # the moment from AeroDyn (skewed wake, cone), at the mean flap deflection
            m0, m1 = inclined_rotor_moment(lc.wind_speed)
            g_m = m0 + eff["blade_deflection"] * m1 * float(q_static[_FLAP])
            # the force along the in-plane wind and the moment across it (AeroDyn's skewed wake and the blades'
            # cone, M = k e_x x w), at the mean flap deflection
            f0, f1, k0, k1 = inplane_wind_loads(lc.wind_speed)
            g_f = f0 + eff["blade_deflection"] * f1 * float(q_static[_FLAP])
            g_c = k0 + eff["blade_deflection"] * k1 * float(q_static[_FLAP])
            per_wy = j_hub.T @ np.array([0.0, g_f, 0.0]) + r_tt.T @ np.array([0.0, g_m, g_c])
            # (the moment across the wind up the disc, a tilt moment, is left out and the cross moment loads the
            # hub only, not the cyclic flap modes: as in the simulation, whose kernel says why)
            per_wz = j_hub.T @ np.array([0.0, 0.0, g_f]) + r_tt.T @ np.array([0.0, 0.0, g_m])
            per_wy[_CYCLIC[0]] += flap.thrust_shape * w_t * g_t
            per_wz[_CYCLIC[1]] += flap.thrust_shape * w_y * g_t
            # the coned blades and the skewed wake meet the in-plane wind as a gradient against it: each blade's
            # in-plane force sees -eps (w . e_r), a side force from w_z and a vertical one from w_y (eps at the
            # mean flap deflection; its change with the deflection loads the hub from the flap mode)
            g_ip = blade_inplane_gain(lc.wind_speed)
            e0, e1 = inclined_rotor_inplane(lc.wind_speed)
            s_bend = eff["blade_deflection"]
            eps = e0 + s_bend * e1 * float(q_static[_FLAP])
            per_wz += j_hub.T @ np.array([0.0, g_ip * eps, 0.0])
            per_wy += j_hub.T @ np.array([0.0, 0.0, -g_ip * eps])
            v0, gain = lc.wind_speed, 1.5 * s_skew
            # the moment per m/s of in-plane wind follows the blade pitch (inclined_rotor_moment_by_pitch): its
            # slope at the operating pitch times the mean in-plane wind up the disc, on the pitch's deviation
            beta_k, k_beta = inclined_rotor_moment_by_pitch()
            h_beta = np.deg2rad(0.5)
            dk_dbeta = float(np.interp(op.pitch + h_beta, beta_k, k_beta)
                             - np.interp(max(op.pitch - h_beta, 0.0), beta_k, k_beta)) / (
                op.pitch + h_beta - max(op.pitch - h_beta, 0.0))
            m_beta = gain * v0 * np.sin(inc0) * dk_dbeta * (r_tt.T @ np.array([0.0, 0.0, 1.0]))
            f_x += np.outer(m_beta, pitch_x)
            f_u[:, ia] += m_beta
            f_x[:, _FLAP] += (gain * v0 * np.sin(inc0) * s_bend * e1 * g_ip) * (j_hub.T @ np.array([0.0, 1.0, 0.0]))
            f_x[:, _FLAP] += (gain * v0 * np.sin(inc0) * s_bend * f1) * (j_hub.T @ np.array([0.0, 0.0, 1.0]))
            e_up = st.disc_up
            f_u[:, 0] += gain * v0 * (np.sin(inc0) - np.cos(inc0) * theta0) * per_wz
            f_u[:, iw] += gain * np.sin(inc0) * per_wz
            f_x[:, :N_DOF] += gain * v0 * (np.cos(inc0) * np.outer(per_wz, r_tt[1]) - np.outer(per_wy, r_tt[2]))
            f_x[:, N_DOF:2 * N_DOF] -= gain * s_aero * (np.outer(per_wz, e_up @ j_hub) + np.outer(per_wy, j_hub[1]))
        # the rotor's aerodynamic damping of tilt and yaw: a disc turning at (pitch rate, yaw rate) meets the
        # relative-wind gradients dU/dy = +yaw rate, dU/dz = -pitch rate, loaded as any disc gradient (the
        # simulation's nonlinear rotor does the same blade by blade)
        # (the blades answer them DISC_RATE_LAG_DEG of azimuth late: the gradient turns by that angle in the disc)
        c_lag, s_lag = math.cos(DISC_RATE_LAG), math.sin(DISC_RATE_LAG)
        rate_rows = (c_lag * r_tt[2] + s_lag * r_tt[1], -c_lag * r_tt[1] + s_lag * r_tt[2])
        motion_loads = _shear_hub_loads(op, st.data.tip_radius, 0.0 if nonlinear_rotor else s_aero)
        for rows, (force, moment) in zip(rate_rows, motion_loads, strict=True):
            f_x[:, N_DOF:2 * N_DOF] += np.outer(j_hub.T @ force + r_tt.T @ moment, rows)
        # the disc's rates load the cyclic flap modes as any gradient does; the blades' own flap velocity in the
        # rotating frame, (q_t' + Omega q_y) cos psi_b + (q_y' - Omega q_t) sin psi_b at the thrust's centre, is
        # a relative wind too: it damps the cyclic modes and carries tilt and yaw moments to the hub
        cyc_x = np.zeros((N_DOF, n_x))  # generalised forces of the cyclic flap aerodynamics over [x]
        cyc_moment_x = np.zeros((3, n_x))  # and their tilt and yaw moments on the hub
        if op is not None and not nonlinear_rotor and s_aero:
            g_b = s_aero * op.dT_dV / 3.0
            r_t, r_ty = blade_load_radii(st.data.tip_radius)
            it, iy = _CYCLIC
            cyc_x[it, N_DOF:2 * N_DOF] += s_aero * cyc_gain[0] * rate_rows[1]
            cyc_x[iy, N_DOF:2 * N_DOF] += -s_aero * cyc_gain[1] * rate_rows[0]
            p_t = flap.thrust_shape
            vel_t = np.zeros(n_x)  # rotating-frame flap velocity projected on cos psi_b (tilt), then sin (yaw)
            vel_y = np.zeros(n_x)
            vel_t[N_DOF + it], vel_t[iy] = 1.0, omega0
            vel_y[N_DOF + iy], vel_y[it] = 1.0, -omega0
            cyc_x[it] += -1.5 * g_b * p_t * p_t * vel_t
            cyc_x[iy] += -1.5 * g_b * p_t * p_t * vel_y
            cyc_moment_x[1] = -1.5 * g_b * p_t * v_t * r_t * vel_t
            cyc_moment_x[2] = -1.5 * g_b * p_t * v_y * r_ty * vel_y
            cyc_x += r_tt.T @ cyc_moment_x
            f_x += cyc_x
        # tower drag: generalised force per unit V|V| of the hub wind
        itd = INPUT_BLOCKS["rotor"].start + 4
        twr_z, twr_f = _tower_drag_strips(st.data.tower_base_height, st.data.tower_top_height, eff["tower_drag"])
        for z_s, f_s in zip(twr_z, twr_f, strict=True):
            f_u[:, itd] += f_s * st.point_translation(z_s)[0]
        if op is not None and s_gyro:
            h0 = st.spin_inertia * omega0
            gyro = s_gyro * h0 * r_tt.T @ _skew(e_s) @ r_tt
            f_x[:, N_DOF:2 * N_DOF] += gyro

        minv = np.linalg.inv(m)
        a = np.zeros((n_x, n_x))
        b = np.zeros((n_x, n_u))
        a[:N_DOF, N_DOF:2 * N_DOF] = np.eye(N_DOF)
        a[N_DOF:2 * N_DOF, :N_DOF] = -minv @ k
        a[N_DOF:2 * N_DOF, N_DOF:2 * N_DOF] = -minv @ c
        a[N_DOF:2 * N_DOF] += minv @ f_x
        b[N_DOF:2 * N_DOF] = minv @ f_u
        if linear_rotor:
            j = st.rotor_inertia_lss
            # the rotor speed relative to the nacelle (OpenFAST's RotSpeed) also answers the nacelle's roll
            # about the shaft: J Omega' + c (r_s . q'') = Qa - Qg
            a[2 * N_DOF] = (qa_x - qg_x) / j - spin_coupling / j * (r_s @ a[N_DOF:2 * N_DOF])
            b[2 * N_DOF] = (qa_u - qg_u) / j - spin_coupling / j * (r_s @ b[N_DOF:2 * N_DOF])
            a[2 * N_DOF + 1, 2 * N_DOF] = 1.0

        # the Morison drag's equivalent linearisation about this load case's stationary response (sea state and
        # turbulence), solved by iteration on the linear model's own relative velocity (as RAFT does)
        drag = self._drag_strips()
        if lc is not None and (lc.hs > 0 or (lc.wind_speed > 0 and lc.turbulence_intensity > 0)):
            if nonlinear_rotor:  # the same linearisation as the linear-rotor model of this case
                drag = self._system(lc, nonlinear_rotor=False).drag
            else:
                drag = _stochastic_drag(a, b, minv, lc, drag, op)
            a[N_DOF:2 * N_DOF, N_DOF:N_DOF + 6] -= minv[:, :6] @ drag.platform_damping()

        # ------------------------------------------------------------------ outputs (55 channels)
        qdd_x, qdd_u = a[N_DOF:2 * N_DOF], b[N_DOF:2 * N_DOF]
        # ElastoDyn reports a tower moment in the axes of its section, which turn with the mean moment in them
        # (local_moment_rows): the sections' mean rotations and moments under the mean loads, from the static
        # deflection of the model whose rotor loads are linear (with the nonlinear rotor the mean loads come
        # through the inputs)
        mean_moments: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        reference = self._system(lc, nonlinear_rotor=False).mean_moments if (op is not None and nonlinear_rotor) \
            else None
        q_static = np.linalg.solve(k - f_x[:, :N_DOF], f_u[:, 0]) if reference is None else None
        thrust_x, thrust_u = t_x, t_u.copy()
        thrust_u[0] += t0
        rows_x: dict[str, np.ndarray] = {}
        rows_u: dict[str, np.ndarray] = {}
        g_acc = GRAVITY if self.accel_gravity else 0.0
        p_hub = st.hub_position
        ez = np.array([0.0, 0.0, 1.0])
        t_ref = op.thrust if op is not None else 0.0  # thrust of the geometric (deflection) moment term
        z_top = st.data.tower_top_height
        points = [(f"TwHt{gi}", h) for gi, h in enumerate(self.gauge_heights, start=1)]
        s1 = 1.5 * st.data.blade_flap.rotary_moment
        it, iy = _CYCLIC
        cyc_reaction_x = cyc_moment_x.copy()
        cyc_reaction_u = np.zeros((3, n_u))
        for axis, j, other, sign in ((1, it, iy, 1.0), (2, iy, it, -1.0)):
            cyc_reaction_x[axis] -= s1 * qdd_x[j]
            cyc_reaction_x[axis, N_DOF + other] -= s1 * sign * 2.0 * s_gyro * omega0
            cyc_reaction_u[axis] -= s1 * qdd_u[j]
        points += [("TwrBs", st.data.tower_base_height), ("YawBr", z_top)]
        for prefix, h in points:
            t_h = st.point_translation(h)
            r_h = st.point_rotation(h)
            ax_x = t_h[0] @ qdd_x
            ax_x[:N_DOF] -= g_acc * r_h[1]
            ay_x = t_h[1] @ qdd_x
            ay_x[:N_DOF] += g_acc * r_h[0]
            if prefix == "YawBr":  # ElastoDyn's YawBrTAxp/yp: without gravity whatever accel_gravity says
                rows_x["YawBrTAxp"], rows_u["YawBrTAxp"] = t_h[0] @ qdd_x, t_h[0] @ qdd_u
                rows_x["YawBrTAyp"], rows_u["YawBrTAyp"] = t_h[1] @ qdd_x, t_h[1] @ qdd_u
                continue
            if prefix.startswith("TwHt"):
                rows_x[f"{prefix}ALxt"], rows_u[f"{prefix}ALxt"] = ax_x, t_h[0] @ qdd_u
                rows_x[f"{prefix}ALyt"], rows_u[f"{prefix}ALyt"] = ay_x, t_h[1] @ qdd_u
            # bending moment vector (N m) about the gauge from everything above it
            mom_x = np.zeros((3, n_x))
            mom_u = np.zeros((3, n_u))
            p_h = np.array([0.0, 0.0, h])
            for body in st.bodies:
                if body.position[2] <= h:
                    continue
                lever = _skew(body.position - p_h)
                inertial = -(body.mass * lever @ body.translation + body.inertia @ body.rotation)  # (3, N_DOF)
                mom_x += inertial @ qdd_x
                mom_u += inertial @ qdd_u
                mom_u[:, 0] += lever @ (-body.mass * GRAVITY * ez)
                mom_x[:, :N_DOF] += s_pd * body.mass * GRAVITY * _skew(ez) @ (body.translation - t_h)
            # the cyclic flap modes' inertial and Coriolis reaction on the hub, and their aerodynamic moments
            mom_x += cyc_reaction_x
            mom_u += cyc_reaction_u
            lever_hub = _skew(p_hub - p_h)
            mom_x += np.outer(lever_hub @ e_s, thrust_x)
            mom_u += np.outer(lever_hub @ e_s, thrust_u)
            mom_x[:, :N_DOF] += -_skew(e_s * t_ref) @ (st.hub_translation - t_h)
            mom_u[:, hub.start:hub.start + 3] += lever_hub
            mom_u[:, hub.start + 3:hub.stop] += np.eye(3)
            if linear_rotor:  # the mean thrust turned with the tower top (the nonlinear rotor's hub loads carry it)
                for axis in (1, 2):
                    mom_x[:, :N_DOF] += t0 * np.outer(lever_hub @ np.cross(np.eye(3)[axis], e_s), r_tt[axis])
            for col, (force, moment) in zip(range(sh.start, sh.stop), shear_loads, strict=True):
                mom_u[:, col] += lever_hub @ force + moment
            for rows, (force, moment) in zip(rate_rows, motion_loads, strict=True):
                mom_x[:, N_DOF:2 * N_DOF] += np.outer(lever_hub @ force + moment, rows)
            for z_s, f_s in zip(twr_z, twr_f, strict=True):
                if z_s > h:
                    mom_u[1, itd] += (z_s - h) * f_s
            mom_x += np.outer(e_s, qg_x)
            mom_u += np.outer(e_s, qg_u)
            mom_u[:, 0] += e_s * qg0
            # the free rotor: its polar inertia follows the nacelle's roll only in part (rotor_free_inertia), and
            # (linear rotor) the nacelle takes (J - c) / J of its torque imbalance besides the generator's torque
            mom_x += free_spin * np.outer(e_s, r_s @ qdd_x)
            mom_u += free_spin * np.outer(e_s, r_s @ qdd_u)
            if linear_rotor:
                mom_x += spin_share * np.outer(e_s, qa_x - qg_x)
                mom_u += spin_share * np.outer(e_s, qa_u - qg_u)
            if reference is None:
                mean_moments[prefix] = (r_h @ q_static, mom_x[:, :N_DOF] @ q_static + mom_u[:, 0])
            else:
                mean_moments[prefix] = reference[prefix]
            mom_x, mom_u = local_moment_rows(mom_x, mom_u, r_h, *mean_moments[prefix])
            suffix = ("MLyt", "MLxt") if prefix.startswith("TwHt") else ("Myt", "Mxt")
            rows_x[prefix + suffix[0]], rows_u[prefix + suffix[0]] = mom_x[1] / 1e3, mom_u[1] / 1e3
            rows_x[prefix + suffix[1]], rows_u[prefix + suffix[1]] = mom_x[0] / 1e3, mom_u[0] / 1e3
        # tower-top deflection relative to the undeflected tower (tower modes only)
        t_top = st.point_translation(z_top)
        for name, axis in (("TTDspFA", 0), ("TTDspSS", 1)):
            rx = np.zeros(n_x)
            rx[6:N_DOF] = t_top[axis, 6:N_DOF]
            rows_x[name], rows_u[name] = rx, np.zeros(n_u)
        for i, name in enumerate(("PtfmSurge", "PtfmSway", "PtfmHeave", "PtfmRoll", "PtfmPitch", "PtfmYaw")):
            rx = np.zeros(n_x)
            rx[i] = 1.0 if i < 3 else np.rad2deg(1.0)
            rows_x[name], rows_u[name] = rx, np.zeros(n_u)
        # ElastoDyn's Euler angles about the mean pitch: roll r + y tan(p0), yaw y / cos(p0) (elastodyn_platform_angles)
        rows_x["PtfmRoll"][5] = np.rad2deg(math.tan(mean_pitch))
        rows_x["PtfmYaw"][5] = np.rad2deg(1.0 / math.cos(mean_pitch))
        rx = np.zeros(n_x)
        rx[2 * N_DOF] = 30.0 / np.pi
        ru = np.zeros(n_u)
        ru[0] = omega0 * 30.0 / np.pi
        rows_x["RotSpeed"], rows_u["RotSpeed"] = rx, ru
        for name, idx in (("Wave1Elev", INPUT_BLOCKS["elev"].start), ("Wind1VelX", INPUT_BLOCKS["hub_wind"].start)):
            ru = np.zeros(n_u)
            ru[idx] = 1.0
            rows_x[name], rows_u[name] = np.zeros(n_x), ru
        # rotor channels: linear expressions about the operating point, or the per-step values (rotor block)
        n_gear = st.data.gearbox_ratio
        eff_gen = DISCON["GenEff"]
        ir = INPUT_BLOCKS["rotor"].start
        pitch_x, pitch_u = np.zeros(n_x), np.zeros(n_u)
        gen_x, gen_u = qg_x / n_gear, qg_u / n_gear
        gen_u = gen_u.copy()
        gen_u[0] += qg0 / n_gear
        pow_x = eff_gen * (omega0 * qg_x)
        pow_u = eff_gen * (omega0 * qg_u)
        pow_x[2 * N_DOF] += eff_gen * qg0
        pow_u[0] += eff_gen * omega0 * qg0
        if linear_rotor:
            pitch_x[2 * N_DOF], pitch_x[2 * N_DOF + 1] = op.kp, op.ki
            pitch_u[0], pitch_u[ia] = op.pitch, 1.0
        pitch_u[ir] += 1.0
        gen_u[ir + 1] += 1.0
        pow_u[ir + 2] += 1.0
        rot_x, rot_u = thrust_x.copy(), thrust_u.copy()
        rot_u[ir + 3] += 1.0
        # ElastoDyn's RotThrust: + rotor weight and inertia along the tilted shaft (a parked rotor's too)
        m_rot = st.data.rotor_mass
        tilt = st.data.shaft_tilt_rad
        rot_u[0] += -m_rot * GRAVITY * np.sin(tilt)  # tilt < 0: the weight pushes down the shaft
        rot_x[:N_DOF] += m_rot * GRAVITY * np.cos(tilt) * st.tower_top_rotation[1]
        # inertia along the shaft: the rotor's mass with the hub, the blades' flap mode with int m phi
        inertia = m_rot * h_v
        inertia[_FLAP] = st.data.n_blades * st.data.blade_flap.first_moment
        rot_x -= inertia @ qdd_x
        rot_u -= inertia @ qdd_u
        rows_x["BldPitch1"], rows_u["BldPitch1"] = np.rad2deg(pitch_x), np.rad2deg(pitch_u)
        rows_x["GenTq"], rows_u["GenTq"] = gen_x / 1e3, gen_u / 1e3
        rows_x["GenPwr"], rows_u["GenPwr"] = pow_x / 1e3, pow_u / 1e3
        rows_x["RotThrust"], rows_u["RotThrust"] = rot_x / 1e3, rot_u / 1e3
        cmat = np.array([rows_x[ch] for ch in ALL_CHANNELS])
        dmat = np.array([rows_u[ch] for ch in ALL_CHANNELS])
        return LinearSystem(a, b, cmat, dmat, tuple(ALL_CHANNELS), op, omega0, dict(eff), st, drag, mean_pitch,
                            mean_moments)

    # ----------------------------------------------------------------------------------------- analysis
    def modal_analysis(self, case: int | LoadCase | None = None) -> ModalResult:
        """Natural frequencies, damping ratios and mode shapes of the linearised model.

        Parameters
        ----------
        case : int or LoadCase or None
            None (default): parked rotor, no wind, still water -- the conditions of the OC3 free-decay
            frequencies (Jonkman 2010). With a load case: about its operating point, with aerodynamic
            damping, gyroscopics and the pitch controller as the effects say.

        Returns
        -------
        ModalResult
            The 11 structural modes, labelled ``surge`` ... ``yaw``, ``tower_fa_1``, ``tower_ss_1``,
            ``blade_flap``, ``tower_fa_2``, ``tower_ss_2``, sorted by frequency (an overdamped mode: its undamped
            frequency, damping ratio 1).
        """
        sys = self.system(case)
        st = self.structure
        k = st.stiffness + self._effects["p_delta"] * st.stiffness_pdelta
        w2, phi = sla.eigh(k, st.mass)
        # label the undamped modes by where their potential energy sits (one label per mode)
        energy = np.abs(phi * (k @ phi))
        energy /= energy.sum(axis=0, keepdims=True)
        _, label_of = linear_sum_assignment(-energy.T)
        base_labels = [DOF_LABELS[j] for j in label_of]
        # damped eigenvalues of the full closed-loop system (rotor speed and pitch controller included), matched
        # to the undamped structural modes by MAC on q; the controller's own modes are left out
        lam, vec = np.linalg.eig(sys.A)
        keep = np.where(lam.imag > 1e-9)[0]
        lam, vec = lam[keep], vec[:N_DOF, keep]
        mac = np.abs(phi.T @ st.mass @ vec) ** 2 / (
            np.einsum("ij,ij->j", phi, st.mass @ phi)[:, None]
            * np.real(np.einsum("ij,ij->j", vec.conj(), st.mass @ vec))[None, :]
        )
        rows, cols = linear_sum_assignment(-mac)
        # a mode left without an oscillating eigenvalue is overdamped (the operating rotor's blade flap can be):
        # its undamped frequency and shape, damping ratio 1 (at least)
        freqs = np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi)
        zetas = np.ones(N_DOF)
        shapes = phi / np.max(np.abs(phi), axis=0, keepdims=True)
        for r, cidx in zip(rows, cols, strict=True):
            ev = lam[cidx]
            freqs[r] = abs(ev.imag) / (2 * np.pi)
            zetas[r] = -ev.real / abs(ev)
            v = vec[:, cidx]
            v = np.real(v * np.exp(-1j * np.angle(v[np.argmax(np.abs(v))])))
            shapes[:, r] = v / np.max(np.abs(v))
        order = np.argsort(freqs)
        labels = _tower_labels([base_labels[i] for i in order], freqs[order])
        return ModalResult(labels, freqs[order], zetas[order], shapes[:, order])

    def linearize(self, case: int | LoadCase | None = None, plane: str | None = None):
        """Linear state-space model about the operating point as a ``control.StateSpace``.

        Parameters
        ----------
        case : int or LoadCase or None
            Load case (None: parked, still water).
        plane : {"FA", "SS"} or None
            "FA"/"SS": the paper's 18 channels of that plane (accelerations at gauges 1-9, then bending
            moments at gauges 1-9); None: all 45 channels.

        Returns
        -------
        control.StateSpace
            Continuous-time; named states (:data:`STATE_NAMES`), inputs (wave excitation ``wave_Fx`` ...
            ``wave_Mz``, rotor-effective wind deviation ``wind_dev``, ``pitch_offset``, ``torque_offset``) and
            outputs (channel names). Outputs are deviations from the operating-point mean. The nonlinear
            effects do not appear (their linearisation about zero velocity and offset is zero or already in
            the linear terms).
        """
        import control

        sys = self.system(case)
        names = list(ALL_CHANNELS) if plane is None else tower_channels(plane)
        idx = [ALL_CHANNELS.index(n) for n in names]
        cols = list(range(INPUT_BLOCKS["wave"].start, INPUT_BLOCKS["wave"].stop)) + [
            INPUT_BLOCKS["wind"].start, INPUT_BLOCKS["action"].start, INPUT_BLOCKS["action"].start + 1]
        return control.ss(
            sys.A, sys.B[:, cols], sys.C[idx], sys.D[np.ix_(idx, cols)],
            states=list(STATE_NAMES), inputs=[INPUT_NAMES[c] for c in cols], outputs=names,
            name="fowt_linear",
        )

    @staticmethod
    def units(channels: list[str]) -> list[str]:
        """OpenFAST units of channels."""
        return [UNITS[c] for c in channels]


ROTOR_ASYMMETRY = {"moment": 0.17, "yaw_moment": 0.22}
"""Gains of the rotor's response to a linear wind gradient over the disc (-): tilt moment
``= moment * dT/dU * R^2 * dU/dz``, yaw moment ``= -yaw_moment * dT/dU * R^2 * dU/dy`` (blade-element scaling: the
local thrust slope times the lever squared). Calibrated against OpenFAST's OC3 Hywind runs at 8, 12 and 18 m/s:

* ``moment``: tower-top tilt moment regressed on the disc-fit gradients of the TurbSim inflow (the same within
  10 % at the three speeds); it also gives OpenFAST's mean tower-base moment under the mean shear;
* ``yaw_moment``: from the platform yaw below its 0.12 Hz mode, where the yaw is quasi-static (moment over the
  deck's yaw stiffness), replaying each run's own inflow field (``fowt-env validate --replay``, 2 seeds): with
  0.17 the yaw std below 0.05 Hz is 0.80/0.78/0.83 of OpenFAST's at 8/12/18 m/s, with 0.22 1.02/0.98/1.02, with
  0.23 1.07/1.02/1.06 (with the platform's restoring turned into the fixed axes, ``surrogates.hydro_axes``'s
  former form, 0.23 gave 0.99/0.94/1.01). A regression on the disc-fit gradient (0.17, as for tilt) is biased low:
  the fitted plane is a noisy stand-in for what the blades sample (errors in the regressor attenuate the slope).
  Why the tilt gain does not need the same correction is open (the rotor's ~10 deg inclination and the
  skewed-wake model act in the vertical plane).

The yaw and tilt rates of the disc are loaded through the same gains (the rotor's aerodynamic yaw and tilt
damping, ``aero_damping``). The rotor's in-plane (side and vertical) force is not calibrated: each blade's in-plane
force answers the wind along it as the deck's blade does (:func:`surrogates.aero.blade_inplane_sensitivity`, a
blade-element model of its AeroDyn blade; the side force under a gradient ``dU/dz`` is ``-1.5 G r_ip dU/dz`` with
``G`` one blade's gain and ``r_ip`` its mean radius, :func:`inplane_gradient_gain`). It replaced a gain regressed
on the disc-fit gradient (``side_force = 0.45`` of ``dQ/dU``), which gave 0.62-0.74 of OpenFAST's aerodynamic
side force in the 1st tower band, fed with OpenFAST's own winds (0.84-0.97 now)."""

TOWER_AERO = {"cd": 1.0, "diameter_base": 6.5, "diameter_top": 3.87, "shear_exponent": 0.2, "hub_height": 90.0}
"""Tower aerodynamic drag of the OC3 deck (AeroDyn ``TwrAero = True``: Cd = 1.0, diameter 6.5 m at the base to
3.87 m at the top) under the power-law mean profile (exponent 0.2, TurbSim's IEC default), scaled by the
instantaneous hub-height wind."""


DISC_RATE_LAG_DEG = 8.0
"""Azimuth (deg) by which the blades' aerodynamic loads lag the relative-wind gradient of the disc's own tilt and
yaw rates (``aero_damping``): the blades answer the rates' gradient turned by this angle in the disc, so a share
``sin`` of the rotor's tilt damping becomes a yaw moment against the gyroscopic one (and of its yaw damping a tilt
moment), beyond what the blades' cyclic flap modes turn (:func:`cyclic_flap_lag`). Calibrated, not derived.

OpenFAST with the platform's yaw held (``tools/openfast_yaw_locked_runs.py``, steady 12 m/s, Hs 2.5 m, Tp 10 s)
gives the yaw moment that the pitching platform puts on the rotor: per unit platform pitch rate, averaged over
0.08-0.14 Hz, 19.6 MN m s in phase and -13.7 in quadrature; the surrogate gave 31.9 / -18.2, which made its
steady-wind yaw 1.3x OpenFAST's in the wave band. The gyroscopic part is not the difference: without aerodynamics
both give 48.5 / 48.1 MN m s per unit pitch rate and 1.20 / 1.17 MN m per m/s of the tower top's deflection rate.
The difference is aerodynamic, and OpenFAST's rigid rotor already carries most of it: with its blades' flap DOFs off
(runs made by hand, like those below, not shipped) the held moment is 34.8 / -24.1, the surrogate's 69.2 / -15.9.
Neither unsteady aerodynamics (``UA_Mod = 0``), the skewed-wake model (``Skew_Mod = 0``) nor the edge DOF carries it
(each switched off in turn), and it is no quasi-static sensitivity (with the platform, the rotor speed and the blade
pitch held, the yaw moment changes by 6 kN m per m/s of wind and by -0.4 MN m per rad of platform pitch). The lag is
fitted to the operating held moment: 8 deg gives 19.9 / -13.6 (``tests/test_yaw_locked.py``; 6 deg 22.9 / -14.7, 10
deg about 16), and the steady-wind yaw 0.89x OpenFAST's in the wave band (its yaw damping, 0.215 against 0.185, is
what is left too high). It leaves the rigid rotor's moment 1.6x OpenFAST's (54.3): it stands in for a mechanism it
does not reproduce, whose cause in AeroDyn is open."""
DISC_RATE_LAG = math.radians(DISC_RATE_LAG_DEG)

BLADE_SAMPLING_RADIUS = 0.75
"""Radius of the blade-effective wind (fraction of R): the field averaged along the blade with weights
proportional to the radius over the rings at R/4, R/2, 3R/4 and R."""


def blade_load_radii(radius: float) -> tuple[float, float]:
    """Effective radii (m) of a blade's thrust for the tilt moment and for the yaw moment in the rotationally
    sampled rotor model, chosen so that under a linear wind gradient it gives exactly the calibrated gradient
    model of :data:`ROTOR_ASYMMETRY` (tilt ``= moment dT/dU R^2 dU/dz``: ``r_s r_T / 2 = moment R^2``; yaw likewise
    with ``yaw_moment``)."""
    r_s = BLADE_SAMPLING_RADIUS * radius
    r_t = 2.0 * ROTOR_ASYMMETRY["moment"] * radius**2 / r_s
    r_ty = 2.0 * ROTOR_ASYMMETRY["yaw_moment"] * radius**2 / r_s
    return r_t, r_ty


def cyclic_flap_aero_shares(radius: float) -> tuple[float, float, float, float]:
    """How the blades' cyclic flap meets the rotor's once-per-revolution aerodynamics (-): ``(v_t, w_t, v_y,
    w_y)``, multiples of the flap mode's value at the thrust's centre, for the tilt (``_t``) and yaw (``_y``) modes.

    Each blade's thrust is sampled at ``r_s`` (:data:`BLADE_SAMPLING_RADIUS`) and carries its moment at ``r_T``
    (:func:`blade_load_radii`, calibrated), so the rotor's tilt damping is ``1.5 (dT/dU / 3) r_s r_T``. A lumped
    aerodynamic point must see the flap velocity at ``v`` and load the flap mode at ``w`` with ``r_T v = r_s w``
    (the aerodynamic damping matrix of tilt and flap symmetric, hence positive semi-definite: with ``r_s != r_T``
    and ``v = w = 1`` it is indefinite and feeds energy into the whirl) and ``v w = 1`` (the flap's own damping
    is each blade's ``dT/dU / 3 thrust_shape^2``, as for the collective mode): ``v = sqrt(r_s / r_T)``,
    ``w = sqrt(r_T / r_s)``.
    """
    r_s = BLADE_SAMPLING_RADIUS * radius
    r_t, r_ty = blade_load_radii(radius)
    return math.sqrt(r_s / r_t), math.sqrt(r_t / r_s), math.sqrt(r_s / r_ty), math.sqrt(r_ty / r_s)


def inplane_gradient_gain(wind_speed: float) -> float:
    """The rotor's in-plane force per unit linear wind gradient over the disc (N·s): ``1.5 G r_ip``.

    A gradient ``g`` along the blades' plane loads each blade's in-plane force by ``G g r_ip cos(psi_b)``
    (:func:`surrogates.aero.blade_inplane_sensitivity`: ``G`` the sum of the nodes' gains, ``r_ip`` their
    gain-weighted mean radius); summed over three blades, projected on the side (vertical) direction, that is
    ``1.5 G r_ip g``: 0.52, 0.52 and 0.51 of ``dQ/dU`` at 8, 12 and 18 m/s (the regression it replaced: 0.45).
    """
    from .aero import blade_inplane_sensitivity

    r, s = blade_inplane_sensitivity(wind_speed)
    return float(1.5 * np.sum(s * r))


def cyclic_flap_lag(flap: BladeFlapMode, wind_speed_gain: float, rotor_speed: float) -> float:
    """Lag (rad) of the blades' flap response to a once-per-revolution load (closed form): the phase by which a
    blade's deflection peaks later in azimuth than a load that varies over the disc.

    A load that varies over the disc (the thrust of a wind gradient, of the disc's own tilt and yaw rates, the
    Coriolis loads of the gyroscopic moment) is seen by each blade once per revolution; the blade's flap mode
    (``omega_f`` ~0.7 Hz turning, heavily damped by its own aerodynamics: ``zeta`` ~0.5) answers ``Omega`` with
    the lag ``atan2(2 zeta r, 1 - r^2)``, ``r = Omega / omega_f`` (Johnson, *Helicopter Theory*, flapping of a
    hingeless blade): 18 deg at rated. The model does not apply it: its cyclic flap modes (multi-blade coordinates
    ``blade_flap_tilt``, ``blade_flap_yaw``, :func:`_cyclic_flap_terms`) produce it, and their whirl at
    ``omega_f +- Omega`` besides; this is their static answer, which ``tests/test_yaw_dynamics.py`` checks them
    against. Through the blades' aerodynamic moments it turns a third (sin 18 deg) of the rotor's tilt damping
    into a yaw moment that opposes the gyroscopic one: OpenFAST's steady-wind yaw answers the platform's pitch
    rate with half the rigid rotor's gain (|yaw / pitch rate| 0.48-0.54 s at 0.08-0.1 Hz).

    Parameters
    ----------
    flap : BladeFlapMode
        The blade's flap mode.
    wind_speed_gain : float
        The rotor's ``dT/dV`` (N s/m): each blade's aerodynamic flap damping is ``dT/dV / 3 * thrust_shape^2``.
    rotor_speed : float
        Rotor speed (rad/s).

    Returns
    -------
    float
        The lag (rad), 0 for a parked rotor.
    """
    omega = float(rotor_speed)
    if not np.isfinite(omega) or omega <= 0.0:
        return 0.0
    k = flap.stiffness + omega**2 * flap.centrifugal
    c = flap.structural_damping + max(float(wind_speed_gain), 0.0) / 3.0 * flap.thrust_shape**2
    omega_f = np.sqrt(k / flap.mass)
    zeta = c / (2.0 * np.sqrt(k * flap.mass))
    r = omega / omega_f
    return float(np.arctan2(2.0 * zeta * r, 1.0 - r * r))


def rotor_free_inertia(st: Structure) -> tuple[float, float]:
    """The turning rotor's coupling with the nacelle's roll about the shaft (kg m^2): ``(c, c^2 / J)``.

    With the rotor's azimuth ``phi`` relative to the nacelle a coordinate of its own and ``w`` the nacelle's rotation
    rate about the shaft, the kinetic energy is ``J_r (phi' + w)^2 / 2 + J_g (N phi' + w)^2 / 2``: the structure's
    roll inertia holds ``J_r + J_g`` (the rotor locked to the nacelle, as for a parked rotor and in BModes), the rotor
    ``J = J_r + N^2 J_g`` (``Structure.rotor_inertia_lss``), and they couple by ``c = J_r + N J_g``. Eliminating
    ``phi''`` leaves the nacelle with ``c^2 / J`` (3.4e7 of the rotor's 3.8e7 kg m^2) less roll inertia, and with
    ``(J - c) / J`` of the rotor's torque imbalance (``Qa - Qg``; the generator's inertia reaction, 12 %). OpenFAST's
    operating side-to-side tower mode shows it: its spectra peak at 0.500 Hz, the locked rotor's mode is at 0.481 Hz,
    the free rotor's at 0.497 Hz.
    """
    d = st.data
    c = d.rotor_inertia + d.gearbox_ratio * d.generator_inertia
    return c, c * c / st.rotor_inertia_lss


def _cyclic_flap_terms(st: Structure, omega: float, s_gyro: float, k: np.ndarray, c: np.ndarray) -> None:
    """Add the rotor speed's terms of the cyclic flap modes to ``k`` and ``c`` in place.

    Each blade's flap equation ``m_f q_b'' + c_f q_b' + k_r q_b + S1 (theta'' cos psi_b + psi'' sin psi_b
    - 2 Omega theta' sin psi_b + 2 Omega psi' cos psi_b) = F_b`` (``k_r`` with the centrifugal stiffening, ``S1 =
    int m phi r dr``; tools/cyclic_flap_equations.py) in the multi-blade coordinates ``q_b = q_t cos psi_b + q_y
    sin psi_b`` is time-invariant: the modes whirl at ``omega_f +- Omega`` (gyroscopic ``3 m_f Omega``, stiffness
    ``3/2 (k_r - m_f Omega^2)``, the structural damping's ``3/2 c_f Omega``) and the disc's tilt and yaw rates
    drive them through the Coriolis terms ``3 S1 Omega`` (the ``gyroscopic`` effect's strength ``s_gyro``),
    which return on the hub as their skew-symmetric reaction.
    """
    if not omega:
        return
    flap = st.data.blade_flap
    it, iy = _CYCLIC
    c_f = flap.structural_damping
    for j in _CYCLIC:
        k[j, j] += 1.5 * (flap.centrifugal - flap.mass) * omega**2
    k[it, iy] += 1.5 * c_f * omega
    k[iy, it] -= 1.5 * c_f * omega
    c[it, iy] += 3.0 * flap.mass * omega
    c[iy, it] -= 3.0 * flap.mass * omega
    g = 3.0 * s_gyro * flap.rotary_moment * omega
    r_y, r_z = st.tower_top_rotation[1], st.tower_top_rotation[2]
    e_t, e_y = np.eye(N_DOF)[it], np.eye(N_DOF)[iy]
    c += g * (np.outer(e_t, r_z) - np.outer(r_z, e_t)) - g * (np.outer(e_y, r_y) - np.outer(r_y, e_y))


def _shear_hub_loads(op: OperatingPoint | None, radius: float, strength: float):
    """(force, moment) at the hub per unit dU/dy and per unit dU/dz (N·s, N·m·s), global axes."""
    zero = (np.zeros(3), np.zeros(3))
    if op is None or strength == 0.0:
        return [zero, zero]
    k_m = strength * ROTOR_ASYMMETRY["moment"] * op.dT_dV * radius**2
    k_my = strength * ROTOR_ASYMMETRY["yaw_moment"] * op.dT_dV * radius**2
    k_f = strength * inplane_gradient_gain(op.wind_speed)
    per_gy = (np.array([0.0, 0.0, k_f]), np.array([0.0, 0.0, -k_my]))
    per_gz = (np.array([0.0, -k_f, 0.0]), np.array([0.0, k_m, 0.0]))
    return [per_gy, per_gz]


def tilted_yaw_gravity_stiffness(structure: Structure, mean_pitch: float) -> np.ndarray:
    """Geometric stiffness of the weights between the platform's yaw and the lateral deflections, at a mean pitch.

    The platform's yaw ``y`` turns about its own (pitched) axis; its lateral axis ``y_p`` then rises out of the
    horizontal by ``y sin(theta0)``. A body of mass ``m`` displaced laterally by ``d`` in the platform's axes (the
    tower's side-to-side modes) rises by ``d y sin(theta0)``: potential energy ``m g sin(theta0) d y``, the
    symmetric stiffness ``K[yaw, j] = K[j, yaw] = g sin(theta0) sum_b m_b T_b[y, j]`` (``T_b`` the body's
    translation Jacobian). At rated wind (4 deg) the weight above the tower base pushes the tower sideways by
    0.33 MN per rad of yaw (ElastoDyn's exact kinematics do the same). The platform's own coordinates (fixed-axes
    translations, rotations about the platform's axes) carry no such term: a point on the spar's axis does not
    move as it yaws.

    Parameters
    ----------
    structure : Structure
        The structural model (its bodies and their translation Jacobians).
    mean_pitch : float
        Mean platform pitch (rad).

    Returns
    -------
    ndarray, shape (N_DOF, N_DOF)
    """
    k = np.zeros((N_DOF, N_DOF))
    s0 = math.sin(float(mean_pitch))
    for body in structure.bodies:
        if body.name == "platform":
            continue
        row = GRAVITY * s0 * body.mass * body.translation[1, 6:]
        k[5, 6:] += row
        k[6:, 5] += row
    return k


def local_moment_rows(mom_x: np.ndarray, mom_u: np.ndarray, rotation: np.ndarray, theta0: np.ndarray,
                      m0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Output rows of a tower section's bending moment in the section's own axes, as ElastoDyn reports it.

    ElastoDyn's ``TwrBsMxt``/``TwrBsMyt`` are the moment vector ``M`` (fixed axes) of everything above the tower
    base projected on the platform's axes, ``M . a1`` and ``M . a2`` (``TwHt*MLxt``/``MLyt`` likewise on the
    gauge's section axes ``t1``, ``t2``). The axes turn with the section: by ``theta0`` under the mean loads
    (the mean platform pitch and tower slope) and by ``delta theta`` about it, ``delta a = delta theta x a``, so
    to first order ``M . a = dM . a0 + delta theta . (a0 x M0)`` (plus the mean ``M0 . a0``). At rated wind the
    mean fore-aft moment (~72 MN m at the tower base) turns into the side-to-side axis with the platform's yaw:
    1.2 MN m per degree, the part of OpenFAST's ``TwrBsMxt`` that follows its yaw in the wave band.

    Parameters
    ----------
    mom_x, mom_u : ndarray, shape (3, n_x) and (3, n_u)
        Rows of the moment vector in the fixed axes (N m) per state and per input (input 0: the constant one).
    rotation : ndarray, shape (3, N_DOF)
        Rotation Jacobian of the section (rad per generalised coordinate).
    theta0 : ndarray, shape (3,)
        The section's mean rotation (rad, fixed axes).
    m0 : ndarray, shape (3,)
        The mean moment vector (N m, fixed axes).

    Returns
    -------
    (ndarray, ndarray)
        The rows with components 0 and 1 in the section's axes (component 2 unchanged).
    """
    cy, sy = math.cos(theta0[1]), math.sin(theta0[1])
    axes = (np.array([cy, theta0[2], -sy]), np.array([-theta0[2], 1.0, theta0[0]]))  # a1, a2 (exact in pitch)
    out_x, out_u = mom_x.copy(), mom_u.copy()
    for i, a0 in enumerate(axes):
        out_x[i] = a0 @ mom_x
        out_u[i] = a0 @ mom_u
        out_x[i, :N_DOF] += np.cross(a0, m0) @ rotation
        out_u[i, 0] -= np.cross(a0, m0) @ theta0  # the mean stays M0 . a0
    return out_x, out_u


def _tower_drag_strips(z0: float, z1: float, strength: float, n: int = 40):
    """Strip heights (m) and drag force per unit ``V_hub |V_hub|`` (N s²/m²) of the tower."""
    from .oc3 import RHO_AIR

    edges = np.linspace(z0, z1, n + 1)
    z = 0.5 * (edges[1:] + edges[:-1])
    dz = np.diff(edges)
    ta = TOWER_AERO
    diam = ta["diameter_base"] + (ta["diameter_top"] - ta["diameter_base"]) * (z - z0) / (z1 - z0)
    profile = (z / ta["hub_height"]) ** (2 * ta["shear_exponent"])
    return z, strength * 0.5 * RHO_AIR * ta["cd"] * diam * dz * profile


def _stochastic_drag(a0: np.ndarray, b: np.ndarray, minv: np.ndarray, lc: LoadCase, strips: DragStrips,
                     op: OperatingPoint | None, iterations: int = 30) -> DragStrips:
    """Equivalent linear drag about the stationary response: iterate ``sigma_r`` (std of the relative velocity
    along the wave direction at each strip, waves and rotor-effective turbulence) and the linear model."""
    from .waves import excitation_rao, jonswap_spectrum
    from .wind import kaimal_spectrum, rotor_averaging

    f = np.linspace(0.002, 0.6, 600)
    df = f[1] - f[0]
    w = 2 * np.pi * f
    n = a0.shape[0]
    z = strips.z
    e = strips.direction
    tmat = np.zeros((z.size, 6))  # strip velocity along e per platform velocity
    tmat[:, 0], tmat[:, 4] = e[0], e[0] * z
    tmat[:, 1], tmat[:, 3] = e[1], -e[1] * z
    s_eta = jonswap_spectrum(f, lc.hs, lc.tp, lc.gamma) if lc.hs > 0 else np.zeros_like(f)
    u_w = wave_velocity_rao(z, f)  # along e, per m of amplitude
    x_rao = excitation_rao(f, lc.wave_dir_deg) if lc.hs > 0 else np.zeros((f.size, 6), complex)
    wave_cols = INPUT_BLOCKS["wave"]
    b_wave = b[:, wave_cols]
    b_wind = b[:, INPUT_BLOCKS["wind"].start]
    turbulent = op is not None and lc.turbulence_intensity > 0 and np.any(b_wind)
    if turbulent:
        h2, _ = rotor_averaging(f, lc.wind_speed)
        s_wind = kaimal_spectrum(f, lc.wind_speed, lc.turbulence_intensity) * h2
    sigma = np.sqrt(np.maximum(np.sum(np.abs(u_w) ** 2 * s_eta[:, None], axis=0) * df, 0.0))
    current = with_relative_velocity_std(strips, sigma)
    for _ in range(iterations):
        a = a0.copy()
        a[N_DOF:2 * N_DOF, N_DOF:N_DOF + 6] -= minv[:, :6] @ current.platform_damping()
        mats = current.strip_matrices()
        # generalised drag excitation per unit amplitude: sum_j T_j^T D_j e u_w,j
        fd = np.zeros((f.size, 6), complex)
        dv = np.einsum("sij,j->si", mats, e)  # (strips, 2) force per unit along-velocity
        fd[:, 0] = u_w @ dv[:, 0]
        fd[:, 1] = u_w @ dv[:, 1]
        fd[:, 3] = -(u_w * z) @ dv[:, 1]
        fd[:, 4] = (u_w * z) @ dv[:, 0]
        var = np.zeros(z.size)
        for i, wi in enumerate(w):
            lhs = 1j * wi * np.eye(n) - a
            if lc.hs > 0 and s_eta[i] > 0:
                xw = np.linalg.solve(lhs, b_wave @ (x_rao[i] + fd[i]))
                rel = u_w[i] - tmat @ xw[N_DOF:N_DOF + 6]
                var += np.abs(rel) ** 2 * s_eta[i] * df
            if turbulent:
                xv = np.linalg.solve(lhs, b_wind)
                var += np.abs(tmat @ xv[N_DOF:N_DOF + 6]) ** 2 * s_wind[i] * df
        new_sigma = np.sqrt(var)
        done = np.max(np.abs(new_sigma - sigma)) < 1e-3 * (np.max(sigma) + 1e-9)
        sigma = 0.5 * (sigma + new_sigma)
        current = with_relative_velocity_std(strips, sigma)
        if done:
            break
    return current


def _tower_labels(labels: list[str], freqs: np.ndarray) -> list[str]:
    """Order-consistent tower labels: the lower FA/SS mode of each pair is _1, the higher _2."""
    out = list(labels)
    for plane in ("fa", "ss"):
        idx = [i for i, lab in enumerate(out) if lab.startswith(f"tower_{plane}")]
        for n, i in enumerate(sorted(idx, key=lambda i: freqs[i]), start=1):
            out[i] = f"tower_{plane}_{n}"
    return out


def _skew(p: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])

