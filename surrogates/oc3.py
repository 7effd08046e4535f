"""Reference data of the NREL 5 MW turbine on the OC3 Hywind spar, read from the decks that ``pybmodes`` ships.

Nothing here is retyped from a report when a deck holds it: the tower's distributed properties and mode-shape
polynomials come from the ElastoDyn tower file ``NRELOffshrBsline5MW_OC3Hywind_Tower.dat``, the masses and
geometry of the rotor-nacelle assembly (RNA) and platform from ``NRELOffshrBsline5MW_OC3Hywind_ElastoDyn.dat``
and the blade file beside it, and the platform's hydrodynamic added mass, hydrostatic and mooring matrices
from the BModes deck ``07_nrel5mw_oc3hywind_spar_tower.bmi`` (Jonkman 2010, NREL/TP-500-47535, sections 3-4).

The few values that are in no deck are constants of this module with their source: the additional linear
platform damping (Jonkman 2010, Table 5-1 and section 5) and the crow-foot yaw spring (Jonkman 2010, section 4,
already inside the BModes deck's hydrostatic yaw term).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

__all__ = ["OC3Data", "BladeFlapMode", "load_oc3", "GRAVITY", "RHO_WATER", "RHO_AIR", "WATER_DEPTH"]

GRAVITY = 9.80665
"""Gravitational acceleration (m/s²), as in the OC3 ElastoDyn deck."""
RHO_WATER = 1025.0
"""Sea-water density (kg/m³), Jonkman 2010."""
RHO_AIR = 1.225
"""Air density (kg/m³), Jonkman et al. 2009."""
WATER_DEPTH = 320.0
"""Water depth at the OC3 Hywind site (m), Jonkman 2010."""

# Jonkman 2010, section 5 ("additional linear damping" to match Statoil's Hywind data).
EXTRA_LINEAR_DAMPING = np.diag([1.0e5, 1.0e5, 1.3e5, 0.0, 0.0, 1.3e7])


@dataclass(frozen=True)
class BladeFlapMode:
    """Generalised properties of one blade's first flapwise bending mode (ElastoDyn's assumed mode).

    The mode shape ``phi(x) = sum_k c_k x^k`` (``BldFl1Sh(2..6)``, ``x`` the fraction of the flexible span from
    the root, ``phi(1) = 1``) scales the out-of-plane deflection: its coordinate is the tip deflection (m).

    Attributes
    ----------
    mass : float
        Generalised mass ``int m phi^2 dr`` (kg).
    stiffness : float
        Elastic generalised stiffness ``int EI_flap phi''^2 dr`` (N/m).
    centrifugal : float
        Centrifugal stiffening per squared rotor speed, ``int N(r) phi'^2 dr`` with ``N(r) = int_r^R m s ds``
        (kg): the rotating blade's stiffness is ``stiffness + Omega^2 centrifugal``.
    first_moment : float
        ``int m phi dr`` (kg): couples the mode with the hub's motion along the shaft.
    rotary_moment : float
        ``int m phi r dr`` (kg m), ``r`` from the rotor's centre: couples the blade's flap with the rotor plane's
        tilt and yaw (the cyclic flap modes, :mod:`surrogates.structure`).
    shape_coefficients : tuple of float
        ``BldFl1Sh(2..6)``: ``phi(x) = sum_k c_k x^(k+2)``.
    span : (float, float)
        Root and tip radii (m) from the rotor's centre.
    thrust_shape : float
        Mode value at the thrust's centre, ``int phi r dr / int r dr`` (-) for a thrust growing linearly with
        radius: the generalised force of the rotor thrust on the mode per newton, and the share of the tip's
        flap velocity the blade's relative wind sees.
    damping_ratio : float
        Structural damping ratio (-), ``BldFlDmp(1)``.

    Examples
    --------
    >>> mode = load_oc3().blade_flap  # NREL 5 MW: 0.68 Hz parked (Jonkman et al. 2009, Table 9-1: 0.67-0.70)
    >>> bool(0.66 < mode.frequency_hz(0.0) < 0.70 and mode.frequency_hz(12.1) > mode.frequency_hz(0.0))
    True
    """

    mass: float
    stiffness: float
    centrifugal: float
    first_moment: float
    thrust_shape: float
    damping_ratio: float
    rotary_moment: float = 0.0
    shape_coefficients: tuple[float, ...] = ()
    span: tuple[float, float] = (0.0, 1.0)

    def shape(self, radius: np.ndarray) -> np.ndarray:
        """The mode shape (tip = 1) at radii from the rotor's centre (m); 0 inboard of the root."""
        r0, r1 = self.span
        x = np.clip((np.asarray(radius, dtype=float) - r0) / (r1 - r0), 0.0, 1.0)
        return _flap_shape(np.asarray(self.shape_coefficients, dtype=float), x)

    @property
    def structural_damping(self) -> float:
        """One blade's structural damping coefficient on the mode (N s/m): ElastoDyn's ``BldFlDmp``, the damping
        ratio of the blade's own mode on a rigid hub at its parked stiffness, ``2 zeta sqrt(k m)``."""
        return 2.0 * self.damping_ratio * float(np.sqrt(self.stiffness * self.mass))

    def frequency_hz(self, rotor_rpm: float) -> float:
        """Natural frequency of the blade's flap mode on a rigid hub (Hz) at a rotor speed (rpm)."""
        omega = rotor_rpm * np.pi / 30.0
        return float(np.sqrt((self.stiffness + omega**2 * self.centrifugal) / self.mass) / (2.0 * np.pi))


def _flap_shape(coeffs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """ElastoDyn's flap mode shape ``sum_k c_k x^(k+2)`` (``BldFl1Sh(2..6)``) at span fractions ``x``."""
    powers = np.arange(2, 2 + coeffs.size)
    return (coeffs * np.asarray(x, dtype=float)[..., None] ** powers).sum(axis=-1)


def _blade_flap_mode(bl: dict[str, str], blade: np.ndarray, hub_r: float, tip: float) -> BladeFlapMode:
    """The first flap mode's generalised properties from the ElastoDyn blade file (5-column table: ``BlFract,
    StrcTwst, BMassDen, FlpStff, EdgStff``)."""
    coeffs = np.array([_number(bl, f"BldFl1Sh({p})") for p in range(2, 7)])
    powers = np.arange(2, 7)
    length = tip - hub_r
    x = np.linspace(0.0, 1.0, 2001)
    r = hub_r + x * length
    m = np.interp(x, blade[:, 0], blade[:, 2]) * _number(bl, "AdjBlMs")
    ei = np.interp(x, blade[:, 0], blade[:, 3]) * _number(bl, "AdjFlSt") * _number(bl, "FlStTunr(1)")
    phi = _flap_shape(coeffs, x)
    d1 = (coeffs * powers * x[:, None] ** (powers - 1)).sum(axis=1) / length
    d2 = (coeffs * powers * (powers - 1) * x[:, None] ** (powers - 2)).sum(axis=1) / length**2
    tension = np.trapezoid(m * r, r) - cumulative_trapezoid(m * r, r, initial=0.0)  # N(r) = int_r^R m s ds
    return BladeFlapMode(
        mass=float(np.trapezoid(m * phi**2, r)),
        stiffness=float(np.trapezoid(ei * d2**2, r)),
        centrifugal=float(np.trapezoid(tension * d1**2, r)),
        first_moment=float(np.trapezoid(m * phi, r)),
        thrust_shape=float(np.trapezoid(phi * r, r) / np.trapezoid(r, r)),
        damping_ratio=_number(bl, "BldFlDmp(1)") / 100.0,
        rotary_moment=float(np.trapezoid(m * phi * r, r)),
        shape_coefficients=tuple(float(c) for c in coeffs),
        span=(float(hub_r), float(tip)),
    )


@dataclass(frozen=True)
class OC3Data:
    """Raw reference data of the OC3 Hywind system (SI units).

    Attributes
    ----------
    tower_base_height, tower_top_height : float
        Heights of the flexible tower's base and top above still water level (m).
    tower_station : ndarray
        Fractional height of the tower stations (-).
    tower_mass_density : ndarray
        Mass per unit length at the stations (kg/m).
    tower_fa_stiffness, tower_ss_stiffness : ndarray
        Bending stiffness EI at the stations (N·m²).
    tower_damping_ratio : tuple of float
        Structural damping ratios of FA1, FA2, SS1, SS2 (-).
    fa_shape_coeffs, ss_shape_coeffs : ndarray, shape (2, 5)
        ElastoDyn polynomial coefficients of x², ..., x⁶ for the 1st and 2nd mode shapes.
    nacelle_mass, nacelle_cm : float, ndarray
        Nacelle mass (kg) and its CM relative to the tower top, (downwind, lateral, up) (m).
    nacelle_yaw_inertia : float
        Nacelle inertia about the yaw axis (kg·m²).
    hub_mass, hub_inertia : float
        Hub mass (kg) and its inertia about the shaft (kg·m²).
    blade_mass : float
        Mass of one blade (kg).
    blade_second_moment : float
        Second moment of one blade's mass about the rotor apex, ∫ m r² dr (kg·m²).
    blade_first_moment : float
        First moment of one blade's mass about the rotor apex, ∫ m r dr (kg·m).
    blade_flap : BladeFlapMode
        One blade's first flapwise mode (ElastoDyn's ``BldFl1Sh`` polynomial, ``FlpStff``, ``BldFlDmp(1)``).
    n_blades : int
    tip_radius, hub_radius : float
        Rotor radius and blade-root radius (m).
    overhang, shaft_tilt_rad, twr2shft, precone_rad : float
        Rotor-apex overhang along the shaft (m, negative upwind), shaft tilt (rad), vertical distance tower top
        to shaft (m), precone (rad).
    gearbox_ratio, generator_inertia : float
        Gearbox ratio (-) and generator inertia about the high-speed shaft (kg·m²).
    platform_mass, platform_cm_z : float
        Platform mass (kg) and CM height (m, negative below still water level).
    platform_inertia : ndarray, shape (3,)
        Platform roll, pitch, yaw inertia about its CM (kg·m²).
    added_mass : ndarray, shape (6, 6)
        Hydrodynamic added mass about the platform reference point at still water level (kg, kg·m, kg·m²).
    hydrostatic_stiffness : ndarray, shape (6, 6)
        Hydrostatic restoring from buoyancy and water-plane area, *without* the platform weight (N/m, N·m/rad).
    mooring_stiffness : ndarray, shape (6, 6)
        Linearised mooring stiffness at the undisplaced position, *without* the platform weight that the BModes
        deck folds into K44/K55 (N/m, N, N·m/rad).
    extra_damping : ndarray, shape (6, 6)
        Additional linear platform damping (N·s/m, N·m·s/rad).
    """

    tower_base_height: float
    tower_top_height: float
    tower_station: np.ndarray
    tower_mass_density: np.ndarray
    tower_fa_stiffness: np.ndarray
    tower_ss_stiffness: np.ndarray
    tower_damping_ratio: tuple[float, float, float, float]
    fa_shape_coeffs: np.ndarray
    ss_shape_coeffs: np.ndarray
    nacelle_mass: float
    nacelle_cm: np.ndarray
    nacelle_yaw_inertia: float
    hub_mass: float
    hub_inertia: float
    blade_mass: float
    blade_second_moment: float
    blade_first_moment: float
    blade_flap: BladeFlapMode
    n_blades: int
    tip_radius: float
    hub_radius: float
    overhang: float
    shaft_tilt_rad: float
    twr2shft: float
    precone_rad: float
    gearbox_ratio: float
    generator_inertia: float
    platform_mass: float
    platform_cm_z: float
    platform_inertia: np.ndarray
    added_mass: np.ndarray
    hydrostatic_stiffness: np.ndarray
    mooring_stiffness: np.ndarray
    extra_damping: np.ndarray

    @property
    def tower_length(self) -> float:
        """Length of the flexible tower (m)."""
        return self.tower_top_height - self.tower_base_height

    @property
    def rotor_mass(self) -> float:
        """Hub plus blades (kg)."""
        return self.hub_mass + self.n_blades * self.blade_mass

    @property
    def rotor_inertia(self) -> float:
        """Rotor (hub + blades) inertia about the shaft (kg·m²)."""
        return self.hub_inertia + self.n_blades * self.blade_second_moment * np.cos(self.precone_rad) ** 2

    @property
    def rna_mass(self) -> float:
        """Rotor-nacelle assembly mass (kg)."""
        return self.rotor_mass + self.nacelle_mass

    @property
    def rotor_apex(self) -> np.ndarray:
        """Rotor apex relative to the tower top, (downwind, lateral, up) (m)."""
        c, s = np.cos(self.shaft_tilt_rad), np.sin(self.shaft_tilt_rad)
        # ElastoDyn: shaft tilt -5 deg lifts the upwind end; the apex lies `overhang` (negative = upwind) along
        # the tilted shaft from the point `twr2shft` above the tower top: hub height 87.6 + 2.40 = 90.0 m.
        return np.array([self.overhang * c, 0.0, self.twr2shft + self.overhang * s])

    @property
    def hub_height(self) -> float:
        """Height of the rotor apex above still water level (m)."""
        return float(self.tower_top_height + self.rotor_apex[2])


def _pybmodes_root() -> Path:
    try:
        return Path(str(resources.files("pybmodes"))) / "_examples"
    except ModuleNotFoundError as exc:  # pragma: no cover - declared dependency
        raise ImportError("surrogates needs the 'pybmodes' package for the OC3 reference decks") from exc


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _keyed_values(text: str) -> dict[str, str]:
    """Map ``Key`` -> first token of every ``value  Key  - description`` line of a FAST-style deck."""
    out: dict[str, str] = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 2 and not line.lstrip().startswith("--"):
            key = re.sub(r"\(.*\)$", "", parts[1])
            out.setdefault(parts[1], parts[0])
            out.setdefault(key, parts[0])
    return out


def _number(table: dict[str, str], key: str) -> float:
    try:
        return float(table[key])
    except (KeyError, ValueError) as exc:  # pragma: no cover - deck format is fixed
        raise ValueError(f"OC3 reference deck has no numeric value for {key!r}") from exc


def _matrix_after(text: str, header: str, rows: int = 6) -> np.ndarray:
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith(header):
            block = [list(map(float, re.findall(_NUMBER, lines[i + 1 + r]))) for r in range(rows)]
            return np.array(block, dtype=float)
    raise ValueError(f"OC3 BModes deck has no block {header!r}")  # pragma: no cover


def _tower_table(text: str) -> np.ndarray:
    return _numeric_rows(text, 4)


def _numeric_rows(text: str, width: int) -> np.ndarray:
    """Rows of a deck's table: lines made of exactly ``width`` numbers and nothing else."""
    rows = []
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == width and all(re.fullmatch(_NUMBER, p) for p in parts):
            rows.append([float(p) for p in parts])
    return np.array(rows)


@lru_cache(maxsize=1)
def load_oc3() -> OC3Data:
    """Read the OC3 Hywind reference data from the decks shipped with ``pybmodes`` (cached).

    Returns
    -------
    OC3Data
        Tower, RNA and platform properties in SI units.
    """
    root = _pybmodes_root()
    deck = root / "reference_decks" / "nrel5mw_oc3spar"
    tower_txt = (deck / "NRELOffshrBsline5MW_OC3Hywind_Tower.dat").read_text()
    ed_txt = (deck / "NRELOffshrBsline5MW_OC3Hywind_ElastoDyn.dat").read_text()
    blade_txt = (deck / "NRELOffshrBsline5MW_Blade.dat").read_text()
    bmi_txt = (
        root / "sample_inputs" / "reference_turbines" / "07_nrel5mw_oc3hywind_spar"
        / "07_nrel5mw_oc3hywind_spar_tower.bmi"
    ).read_text()

    tw = _keyed_values(tower_txt)
    table = _tower_table(tower_txt)
    coeff = {k: float(v) for k, v in tw.items() if re.fullmatch(r"Tw(FA|SS)M[12]Sh\(\d\)", k)}
    fa = np.array([[coeff[f"TwFAM{m}Sh({p})"] for p in range(2, 7)] for m in (1, 2)])
    ss = np.array([[coeff[f"TwSSM{m}Sh({p})"] for p in range(2, 7)] for m in (1, 2)])
    damp = tuple(
        _number(tw, k) / 100.0 for k in ("TwrFADmp(1)", "TwrFADmp(2)", "TwrSSDmp(1)", "TwrSSDmp(2)")
    )

    ed = _keyed_values(ed_txt)
    bl = _keyed_values(blade_txt)
    blade = _numeric_rows(blade_txt, 5)
    tip, hub_r = _number(ed, "TipRad"), _number(ed, "HubRad")
    span = blade[:, 0] * (tip - hub_r)
    mass_den = blade[:, 2] * _number(bl, "AdjBlMs")
    r = hub_r + span
    blade_mass = float(np.trapezoid(mass_den, span))
    blade_first = float(np.trapezoid(mass_den * r, span))
    blade_second = float(np.trapezoid(mass_den * r**2, span))

    hydro_m = _matrix_after(bmi_txt, "Hydrodynamic 6X6 mass matrix")
    hydro_k = _matrix_after(bmi_txt, "Hydrodynamic 6X6 stiffness matrix")
    moor_k = _matrix_after(bmi_txt, "Mooring-system 6X6 stiffness matrix")
    platform_mass = _number(ed, "PtfmMass")
    platform_cm_z = _number(ed, "PtfmCMzt")
    # The BModes deck folds the platform weight's restoring, -m g z_cm, into the mooring K44/K55;
    # this package computes every gravity term itself, so take it out again.
    weight_restoring = -platform_mass * GRAVITY * platform_cm_z
    moor_k = moor_k.copy()
    moor_k[3, 3] -= weight_restoring
    moor_k[4, 4] -= weight_restoring
    # The deck's K15/K51 and K24/K42 differ in the 4th digit (2.821e6 vs 2.816e6); use the symmetric mean.
    moor_k = 0.5 * (moor_k + moor_k.T)

    return OC3Data(
        tower_base_height=_number(ed, "TowerBsHt"),
        tower_top_height=_number(ed, "TowerHt"),
        tower_station=table[:, 0],
        tower_mass_density=table[:, 1] * _number(tw, "AdjTwMa"),
        tower_fa_stiffness=table[:, 2] * _number(tw, "AdjFASt"),
        tower_ss_stiffness=table[:, 3] * _number(tw, "AdjSSSt"),
        tower_damping_ratio=damp,  # type: ignore[arg-type]
        fa_shape_coeffs=fa,
        ss_shape_coeffs=ss,
        nacelle_mass=_number(ed, "NacMass"),
        nacelle_cm=np.array([_number(ed, "NacCMxn"), _number(ed, "NacCMyn"), _number(ed, "NacCMzn")]),
        nacelle_yaw_inertia=_number(ed, "NacYIner"),
        hub_mass=_number(ed, "HubMass"),
        hub_inertia=_number(ed, "HubIner"),
        blade_mass=blade_mass,
        blade_second_moment=blade_second,
        blade_first_moment=blade_first,
        blade_flap=_blade_flap_mode(bl, blade, hub_r, tip),
        n_blades=int(_number(ed, "NumBl")),
        tip_radius=tip,
        hub_radius=hub_r,
        overhang=_number(ed, "OverHang"),
        shaft_tilt_rad=np.deg2rad(_number(ed, "ShftTilt")),
        twr2shft=_number(ed, "Twr2Shft"),
        precone_rad=np.deg2rad(_number(ed, "PreCone(1)")),
        gearbox_ratio=_number(ed, "GBRatio"),
        generator_inertia=_number(ed, "GenIner"),
        platform_mass=platform_mass,
        platform_cm_z=platform_cm_z,
        platform_inertia=np.array([_number(ed, "PtfmRIner"), _number(ed, "PtfmPIner"), _number(ed, "PtfmYIner")]),
        added_mass=hydro_m,
        hydrostatic_stiffness=hydro_k,
        mooring_stiffness=moor_k,
        extra_damping=EXTRA_LINEAR_DAMPING.copy(),
    )
