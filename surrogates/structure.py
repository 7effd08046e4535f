"""Linearised structural model of the OC3 Hywind system in generalised coordinates (the ElastoDyn way).

Generalised coordinates ``q`` (SI, small angles in rad)::

    0 surge  1 sway  2 heave  3 roll  4 pitch  5 yaw      rigid platform, about the reference point at still
                                                           water level (SWL)
    6 tower_fa_1  7 tower_fa_2  8 tower_ss_1  9 tower_ss_2 tower modal amplitudes (m of tower-top deflection)
    10 blade_flap                                          the blades' collective first flap mode (m of tip
                                                           deflection along the shaft; ElastoDyn's BldFl1Sh)
    11 blade_flap_tilt  12 blade_flap_yaw                 the blades' cyclic flap modes in the fixed frame (m):
                                                           blade b at azimuth psi_b (0 up) deflects by
                                                           q_0 + q_tilt cos psi_b + q_yaw sin psi_b

plus the rotor azimuth relative to the nacelle, whose rate is the rotor speed (a cyclic coordinate: no
stiffness). Tower deflection shapes are ElastoDyn's polynomials (normalised to 1 at the tower top), which
NREL computed with BModes for the tower on the OC3 platform. The mass matrix is the exact Rayleigh-Ritz
projection ``sum_b T_b^T m_b T_b + R_b^T I_b R_b`` over the tower (integrated along its height), the
rotor-nacelle assembly (nacelle, hub, blades as rigid bodies at the tower top), the spinning rotor and
generator (kinetic energy ``J_r (Omega + w_s)^2 / 2 + J_g (N Omega + w_s)^2 / 2``), the platform and the
hydrodynamic added mass. Stiffness is tower bending (``int EI phi'' phi''``), hydrostatics, linear mooring and
gravity: the platform weight's restoring, and -- as the switchable ``p_delta`` effect -- the geometric
softening of everything above still water (``-g int N(z) s'(z)^T s'(z) dz``, N the weight above height z).

Everything is assembled once with numpy; nothing here depends on a load case.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from .oc3 import GRAVITY, OC3Data, load_oc3
from .tower_fe import PlaneShapes, tower_plane_modes

__all__ = ["DOF_LABELS", "N_DOF", "Structure", "build_structure", "RigidBody"]

DOF_LABELS: tuple[str, ...] = (
    "surge", "sway", "heave", "roll", "pitch", "yaw", "tower_fa_1", "tower_fa_2", "tower_ss_1", "tower_ss_2",
    "blade_flap", "blade_flap_tilt", "blade_flap_yaw",
)
N_DOF = len(DOF_LABELS)
_FA = (6, 7)
_SS = (8, 9)
_FLAP = 10  # collective first flap mode of the blades: tip deflection along the shaft (m)
_CYCLIC = (11, 12)  # cyclic flap modes (multi-blade coordinates): with the rotor plane's tilt, then its yaw


def _skew(p: np.ndarray) -> np.ndarray:
    """Matrix of the cross product: ``_skew(p) @ v == np.cross(p, v)``."""
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])


@dataclass(frozen=True)
class RigidBody:
    """A rigid body of the linearised model: mass, CM at rest, inertia about its CM and its Jacobians."""

    name: str
    mass: float
    position: np.ndarray  # (3,) m, CM at rest in the platform frame (x downwind, y port, z up from SWL)
    inertia: np.ndarray  # (3, 3) kg m^2 about the CM
    translation: np.ndarray  # (3, N_DOF) d(position)/dq
    rotation: np.ndarray  # (3, N_DOF) d(rotation vector)/dq


class TowerShapes:
    """Tower mode shapes fa1, fa2, ss1, ss2 as functions of height, from the coupled FE model.

    Each shape is the elastic part of a coupled tower-platform-RNA mode (zero deflection and slope at the
    tower base, 1 at the top), interpolated exactly as the FE model does (cubic Hermite).
    """

    def __init__(self, data: OC3Data, fa: PlaneShapes, ss: PlaneShapes):
        self.z_base = data.tower_base_height
        self.length = data.tower_length
        self.fa = fa
        self.ss = ss
        self._splines = fa.splines() + ss.splines()
        self._d1 = [sp.derivative(1) for sp in self._splines]
        self._d2 = [sp.derivative(2) for sp in self._splines]

    def _z(self, z: np.ndarray) -> np.ndarray:
        return np.clip(np.atleast_1d(np.asarray(z, dtype=float)), self.z_base, self.z_base + self.length)

    def value(self, z: np.ndarray) -> np.ndarray:
        """Shapes at heights ``z`` (m above SWL), shape (4, len(z)); zero below the tower base."""
        zz = self._z(z)
        return np.array([sp(zz) for sp in self._splines])

    def slope(self, z: np.ndarray) -> np.ndarray:
        """First derivative d(phi)/dz (1/m), shape (4, len(z))."""
        zz = self._z(z)
        return np.array([sp(zz) for sp in self._d1])

    def curvature(self, z: np.ndarray) -> np.ndarray:
        """Second derivative d²(phi)/dz² (1/m²), shape (4, len(z))."""
        zz = self._z(z)
        return np.array([sp(zz) for sp in self._d2])


@dataclass(frozen=True)
class Structure:
    """Matrices and kinematics of the linearised OC3 Hywind structure (SI units).

    Attributes
    ----------
    mass : ndarray, (N_DOF, N_DOF)
        Mass matrix including added mass (rotor polar inertia held to the nacelle, as in BModes).
    rotor_inertia_lss : float
        ``J_r + N² J_g``, drivetrain inertia about the low-speed shaft (kg·m²).
    spin_inertia : float
        ``J_r + N J_g``: angular momentum per rad/s of rotor speed (kg·m²), for the gyroscopic effect.
    stiffness : ndarray
        Hydrostatics + linear mooring + tower bending + platform weight restoring (N/m, N·m/rad, ...).
    stiffness_pdelta : ndarray
        Gravity geometric stiffness of tower and RNA (negative definite on the tilt/bending coordinates).
    damping : ndarray
        Additional linear platform damping + tower structural damping.
    gravity_load : ndarray, (N_DOF,)
        Static generalised force of the weights' lateral offsets (RNA overhang), N or N·m.
    bodies : tuple of RigidBody
        The rigid bodies (tower strips, nacelle, hub, blades, platform) used for outputs.
    tower_top_rotation : ndarray, (3, N_DOF)
        Rotation Jacobian of the tower top.
    hub_translation : ndarray, (3, N_DOF)
        Translation Jacobian of the rotor apex; its ``blade_flap`` column is where the rotor thrust acts on the
        flexible blades (the flap mode's value at the thrust's centre, along the shaft).
    shaft_axis : ndarray, (3,)
        Unit vector along the shaft, pointing downwind (tilted by the shaft tilt).
    hub_position : ndarray, (3,)
        Rotor apex at rest (m).
    """

    data: OC3Data
    shapes: TowerShapes
    mass: np.ndarray
    rotor_inertia_lss: float
    spin_inertia: float
    stiffness: np.ndarray
    stiffness_pdelta: np.ndarray
    damping: np.ndarray
    gravity_load: np.ndarray
    bodies: tuple[RigidBody, ...]
    tower_top_rotation: np.ndarray
    hub_translation: np.ndarray
    shaft_axis: np.ndarray
    hub_position: np.ndarray
    labels: tuple[str, ...] = field(default=DOF_LABELS)

    # ----------------------------------------------------------------------------------------- kinematics
    @property
    def disc_up(self) -> np.ndarray:
        """Unit vector (3,) up the rotor disc, normal to the shaft in the vertical plane (the direction of the
        wind's in-plane component under a nose-up shaft)."""
        return np.cross(self.shaft_axis, [0.0, 1.0, 0.0])

    def point_translation(self, z: float, offset: np.ndarray | None = None) -> np.ndarray:
        """Translation Jacobian (3, N_DOF) of a point rigidly attached to the tower centreline at height ``z``.

        Parameters
        ----------
        z : float
            Attachment height above SWL (m).
        offset : ndarray, optional
            Position of the point relative to the attachment point (m).
        """
        return _translation(self.shapes, z, np.zeros(3) if offset is None else np.asarray(offset, float))

    def point_rotation(self, z: float) -> np.ndarray:
        """Rotation Jacobian (3, N_DOF) of the tower cross-section at height ``z`` (m above SWL)."""
        return _rotation(self.shapes, z)


def _translation(shapes: TowerShapes, z_att: float, offset: np.ndarray) -> np.ndarray:
    p = np.array([0.0, 0.0, z_att]) + offset
    t = np.zeros((3, N_DOF))
    t[:, 0:3] = np.eye(3)
    t[:, 3:6] = -_skew(p)  # theta x p
    if z_att > shapes.z_base:
        phi = shapes.value(z_att)[:, 0]
        t[0, list(_FA)] = phi[:2]
        t[1, list(_SS)] = phi[2:]
        # a point off the centreline also moves with the section's own rotation (its slope; the platform's
        # rotations already act on the whole position p above)
        flex = _rotation(shapes, z_att)
        flex[:, 3:6] = 0.0
        t += -_skew(offset) @ flex
    return t


def _rotation(shapes: TowerShapes, z: float) -> np.ndarray:
    r = np.zeros((3, N_DOF))
    r[:, 3:6] = np.eye(3)
    if z > shapes.z_base:
        slope = shapes.slope(z)[:, 0]
        r[1, list(_FA)] = slope[:2]  # FA deflection along +x with positive slope = rotation about +y
        r[0, list(_SS)] = -slope[2:]  # SS deflection along +y with positive slope = rotation about -x
    return r


def _slope_jacobian(shapes: TowerShapes, z: np.ndarray) -> np.ndarray:
    """Jacobian of the column's (x-slope, y-slope) at heights z: shape (len(z), 2, N_DOF)."""
    z = np.atleast_1d(z)
    s = np.zeros((z.size, 2, N_DOF))
    s[:, 0, 4] = 1.0  # pitch tilts the column towards +x
    s[:, 1, 3] = -1.0  # roll tilts it towards -y
    slope = shapes.slope(z) * (z > shapes.z_base)[None, :]
    s[:, 0, 6] = slope[0]
    s[:, 0, 7] = slope[1]
    s[:, 1, 8] = slope[2]
    s[:, 1, 9] = slope[3]
    return s


@lru_cache(maxsize=1)
def build_structure(n_tower_strips: int = 80, n_fe_elements: int = 40) -> Structure:
    """Assemble the linearised OC3 Hywind structure from the reference decks (cached).

    Parameters
    ----------
    n_tower_strips : int
        Number of strips the tower mass is lumped into for the mass matrix and the bending-moment outputs.
    n_fe_elements : int
        Number of beam elements of the FE model that supplies the tower mode shapes.

    Returns
    -------
    Structure
    """
    d = load_oc3()
    z0, z1 = d.tower_base_height, d.tower_top_height

    # --- rotor-nacelle assembly parts, rigid at the tower top: (name, mass, CM offset from tower top, inertia)
    tilt = d.shaft_tilt_rad
    # downwind along the tilted shaft: ElastoDyn's ShftTilt = -5 deg lifts the upwind (rotor) end, so the shaft
    # descends downwind -- the same direction rotor_apex uses (the apex lies `overhang` < 0 along it)
    shaft = np.array([np.cos(tilt), 0.0, np.sin(tilt)])
    apex = d.rotor_apex
    nac_offset2 = d.nacelle_cm[0] ** 2 + d.nacelle_cm[1] ** 2
    nac_iner = np.diag([0.0, 0.0, d.nacelle_yaw_inertia - d.nacelle_mass * nac_offset2])  # about its own CM
    cone = d.precone_rad
    blades_cm = apex + shaft * (d.blade_first_moment / d.blade_mass) * np.sin(cone)  # precone < 0: upwind
    # Rotor inertia: polar J_r about the shaft, half of the blades' polar inertia about any diameter. The rotor
    # is held to the nacelle in tower vibration (as in BModes and a parked rotor); its speed is a separate,
    # slow DOF driven by torque (see surrogates.aero), not inertially coupled to tower roll.
    blade_polar = d.n_blades * d.blade_second_moment * np.cos(cone) ** 2
    e2 = np.cross(shaft, [0.0, 1.0, 0.0])
    e2 /= np.linalg.norm(e2)
    rotor_iner = d.rotor_inertia * np.outer(shaft, shaft) + 0.5 * blade_polar * (
        np.outer([0, 1, 0], [0, 1, 0]) + np.outer(e2, e2)
    )
    rna_parts = [
        ("nacelle", d.nacelle_mass, np.asarray(d.nacelle_cm, float), nac_iner),
        ("hub", d.hub_mass, apex, np.zeros((3, 3))),
        ("blades", d.n_blades * d.blade_mass, blades_cm, rotor_iner),
    ]
    rna_mass = sum(p[1] for p in rna_parts)
    rna_cm = sum(p[1] * p[2] for p in rna_parts) / rna_mass
    rna_iner = np.zeros((3, 3))
    for _, m, off, iner in rna_parts:
        r = off - rna_cm
        rna_iner += iner + m * (r @ r * np.eye(3) - np.outer(r, r))

    # --- tower shapes from the coupled FE model (platform in-plane mass/restoring at SWL)
    mp, zc = d.platform_mass, d.platform_cm_z
    m2 = np.array([[mp + d.added_mass[0, 0], mp * zc + d.added_mass[0, 4]],
                   [mp * zc + d.added_mass[0, 4], d.platform_inertia[1] + mp * zc**2 + d.added_mass[4, 4]]])
    k2 = np.array([[d.mooring_stiffness[0, 0], d.mooring_stiffness[0, 4]],
                   [d.mooring_stiffness[0, 4],
                    d.hydrostatic_stiffness[4, 4] + d.mooring_stiffness[4, 4] - mp * GRAVITY * zc]])
    fa = tower_plane_modes(d, "FA", rna_mass, rna_cm[[0, 2]], rna_iner[1, 1], m2, k2, n_elements=n_fe_elements)
    ss = tower_plane_modes(d, "SS", rna_mass, rna_cm[[1, 2]], rna_iner[0, 0], m2, k2, n_elements=n_fe_elements)
    shapes = TowerShapes(d, fa, ss)
    bodies: list[RigidBody] = []

    # --- tower strips (lumped at strip centres; rotary inertia of the thin shell neglected)
    edges = np.linspace(z0, z1, n_tower_strips + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    dz = np.diff(edges)
    mass_den = np.interp((centres - z0) / d.tower_length, d.tower_station, d.tower_mass_density)
    for zc_, m in zip(centres, mass_den * dz, strict=True):
        bodies.append(
            RigidBody("tower", float(m), np.array([0, 0, zc_]), np.zeros((3, 3)),
                      _translation(shapes, zc_, np.zeros(3)), _rotation(shapes, zc_))
        )
    flap = d.blade_flap
    for name, m, off, iner in rna_parts:
        t_body = _translation(shapes, z1, np.asarray(off, float))
        if name == "blades":  # the blades' centre of mass follows their collective flap deflection
            t_body[:, _FLAP] = shaft * flap.first_moment / d.blade_mass
        bodies.append(RigidBody(name, float(m), np.array([0, 0, z1]) + off, iner, t_body, _rotation(shapes, z1)))

    # --- platform
    p_cm = np.array([0.0, 0.0, d.platform_cm_z])
    t_p = np.zeros((3, N_DOF))
    t_p[:, 0:3] = np.eye(3)
    t_p[:, 3:6] = -_skew(p_cm)
    r_p = np.zeros((3, N_DOF))
    r_p[:, 3:6] = np.eye(3)
    bodies.append(RigidBody("platform", d.platform_mass, p_cm, np.diag(d.platform_inertia), t_p, r_p))

    mass = np.zeros((N_DOF, N_DOF))
    for b in bodies:
        mass += b.mass * b.translation.T @ b.translation + b.rotation.T @ b.inertia @ b.rotation
    mass[:6, :6] += d.added_mass
    # the blades' flap mode carries int m phi^2 (the lumped body above holds only its centre of mass' share)
    mass[_FLAP, _FLAP] += d.n_blades * (flap.mass - flap.first_moment**2 / d.blade_mass)

    r_top = _rotation(shapes, z1)
    # the cyclic flap modes (multi-blade coordinates, three blades; rows times 3/2 so that the mass is symmetric):
    # a blade's flap moves it along the shaft as the rotor plane's tilt (about +y) and yaw (about +z) do at
    # cos(psi_b) and sin(psi_b) r, hence the couplings 3/2 int m phi r dr (tools/cyclic_flap_equations.py)
    for j, axis in zip(_CYCLIC, (1, 2), strict=True):
        mass[j, j] += 1.5 * flap.mass
        mass[j, :] += 1.5 * flap.rotary_moment * r_top[axis]
        mass[:, j] += 1.5 * flap.rotary_moment * r_top[axis]
    n_gear = d.gearbox_ratio
    rotor_inertia_lss = d.rotor_inertia + n_gear**2 * d.generator_inertia

    # --- stiffness: hydrostatics (buoyancy + water plane), linear mooring, tower bending, platform weight
    k = np.zeros((N_DOF, N_DOF))
    k[:6, :6] += d.hydrostatic_stiffness + d.mooring_stiffness
    zq = np.linspace(z0, z1, 401)
    curv = shapes.curvature(zq)
    ei_fa = np.interp((zq - z0) / d.tower_length, d.tower_station, d.tower_fa_stiffness)
    ei_ss = np.interp((zq - z0) / d.tower_length, d.tower_station, d.tower_ss_stiffness)
    for idx, ei, rows in ((list(_FA), ei_fa, curv[:2]), (list(_SS), ei_ss, curv[2:])):
        k[np.ix_(idx, idx)] += np.trapezoid(ei[None, None, :] * rows[:, None, :] * rows[None, :, :], zq, axis=-1)
    k[3, 3] += -d.platform_mass * GRAVITY * d.platform_cm_z
    k[4, 4] += -d.platform_mass * GRAVITY * d.platform_cm_z
    k[_FLAP, _FLAP] += d.n_blades * flap.stiffness  # parked; the model adds the centrifugal stiffening
    for j in _CYCLIC:  # parked; the model adds the rotor speed's terms
        k[j, j] += 1.5 * flap.stiffness

    # --- gravity geometric (P-delta) stiffness of everything above SWL: each weight m at height h drops by
    #     (1/2) int_0^h |s(z)|^2 dz when the column tilts and bends, s the slope vector.
    k_pd = np.zeros((N_DOF, N_DOF))
    for b in bodies:
        if b.name == "platform":
            continue
        h = b.position[2]
        zz = np.linspace(0.0, min(h, z1), 121)
        s = _slope_jacobian(shapes, zz)
        sts = np.einsum("kai,kaj->kij", s, s)
        integral = np.trapezoid(sts, zz, axis=0)
        if h > z1:  # rigid part above the tower top (RNA) keeps the tower-top slope
            s_top = _slope_jacobian(shapes, np.array([z1]))[0]
            integral += (h - z1) * s_top.T @ s_top
        k_pd -= b.mass * GRAVITY * integral
    # the blades' weight, moved along the shaft by their flap deflection, drops as the tower top tilts:
    # V = -n_b int(m phi) g shaft_x theta_top q_flap
    coupling = -d.n_blades * flap.first_moment * GRAVITY * shaft[0] * r_top[1]
    coupling[_FLAP] = 0.0
    k_pd[:, _FLAP] += coupling
    k_pd[_FLAP, :] += coupling

    # --- static generalised load of the weights (lateral offsets of the RNA CM)
    gravity_load = np.zeros(N_DOF)
    for b in bodies:
        gravity_load += -b.mass * GRAVITY * b.translation[2]
    gravity_load[2] = 0.0  # heave: weight balanced by buoyancy and mooring pretension at the reference draft

    # --- damping: extra linear platform damping and 1 % tower structural damping, ElastoDyn's definition
    #     (SetTowerParameters: C = zeta K / (pi f1), f1 the mode's frequency from the tower's own generalised mass
    #     and elastic stiffness, *without* the tower-top mass and gravity), i.e. C = 2 zeta sqrt(K m_tower): the
    #     coupled mode with the RNA on top then has a damping ratio well below 1 % (OpenFAST's parked tower
    #     decay: 0.6-0.8 %)
    c = np.zeros((N_DOF, N_DOF))
    c[:6, :6] += d.extra_damping
    for i, zeta in zip(range(6, 10), d.tower_damping_ratio, strict=True):
        m_ii = sum(b.mass * b.translation[:, i] @ b.translation[:, i] for b in bodies if b.name.startswith("tower"))
        k_ii = k[i, i]
        c[i, i] = 2.0 * zeta * np.sqrt(max(k_ii, 0.0) * m_ii)
    # ElastoDyn's blade damping: zeta of the blade's own mode on a rigid hub (parked stiffness)
    c[_FLAP, _FLAP] = d.n_blades * flap.structural_damping
    for j in _CYCLIC:
        c[j, j] = 1.5 * flap.structural_damping
    # the rotor thrust acts on the blades: along the shaft at the hub, and on the flap mode through the mode's
    # value at the thrust's centre -- which is also the share of the flap velocity in the blades' relative wind
    hub_translation = _translation(shapes, z1, apex)
    hub_translation[:, _FLAP] = shaft * flap.thrust_shape

    return Structure(
        data=d,
        shapes=shapes,
        mass=0.5 * (mass + mass.T),
        rotor_inertia_lss=rotor_inertia_lss,
        spin_inertia=d.rotor_inertia + n_gear * d.generator_inertia,
        stiffness=0.5 * (k + k.T),
        stiffness_pdelta=0.5 * (k_pd + k_pd.T),
        damping=c,
        gravity_load=gravity_load,
        bodies=tuple(bodies),
        tower_top_rotation=r_top,
        hub_translation=hub_translation,
        shaft_axis=shaft,
        hub_position=np.array([0.0, 0.0, z1]) + apex,
    )
