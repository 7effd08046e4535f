"""The flexible blades' share of the rotor's loads (``blade_deflection``) and the blades' curvature in their own
wind (``sampled_wind_curvature``), against OpenFAST's own runs of the OC3 deck with and without its blade DOFs.

Truth: ``fowt_env/data/openfast_reference/blade_flex_runs.json`` (``tools/openfast_blade_flex_runs.py``: the
shared steady-wind run's inputs, platform held, still water, OpenFAST v5.0.0 of the reference build; ElastoDyn's
FlapDOF1/2 and EdgeDOF off for "rigid"). At rated the rotor's torque is the generator's rated torque, so the blade
pitch at which it settles measures how strong the rotor is.
"""

from __future__ import annotations

import importlib
import json
from importlib import resources

import numpy as np
import pytest
from scipy.optimize import brentq

import surrogates
from surrogates.aero import blade_deflection_table, rotor_table

SIM = importlib.import_module("surrogates.simulate")
MODEL = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS)
TOWER_LENGTH = 77.6  # m, ElastoDyn's TowerHt - TowerBsHt of the OC3 deck (87.6 - 10)


@pytest.fixture(scope="module")
def runs() -> dict:
    text = resources.files("fowt_env").joinpath("data/openfast_reference/blade_flex_runs.json").read_text()
    return json.loads(text)["runs"]


def _table_pitch(run: dict, deflection: float) -> float:
    """Blade pitch (deg) at which the rotor table (bent by ``deflection`` m) gives the run's shaft torque in its
    uniform wind, at its rotor speed and inclination (shaft tilt + platform pitch + the tower top's slope)."""
    inclination = np.deg2rad(5.0 + run["pitch"]) + 1.5 * run["TTDspFA"] / TOWER_LENGTH
    wind = 12.0 * np.cos(inclination)
    omega = run["RotSpeed"] * np.pi / 30.0
    radius = rotor_table().radius
    q = 0.5 * 1.225 * np.pi * radius**3 * wind**2
    tab = blade_deflection_table()
    torque = run["LSShftTq"] * 1e3  # N m: the run's own shaft torque (its generator's, in steady state)

    def excess(beta_deg: float) -> float:
        return q * tab.coefficients(omega * radius / wind, np.deg2rad(beta_deg), deflection)[1] - torque

    return brentq(excess, -2.0, 15.0, xtol=1e-5)


def _kernel_pitch(model: surrogates.FOWTModel, run: dict, deflection: float) -> float:
    """Blade pitch (deg) at which the simulation's rotor (its nonlinear kernel, over a third of a turn in the run's
    steady sheared wind) balances the rated generator torque, with the platform held where the run held it and
    the blades' collective flap deflection set to ``deflection`` m."""
    case = surrogates.load_case(7).replace(wind_speed=12.0, turbulence_intensity=0.0, hs=0.0)
    sim = SIM.Simulator(model, case, 0.0125)
    x = sim.x_eq.copy()
    labels = model.structure.labels
    x[labels.index("surge")] = run["surge"]
    x[labels.index("pitch")] = np.deg2rad(run["pitch"])
    x[labels.index("blade_flap")] = deflection
    u_ex = np.zeros((1, SIM.N_EX))
    u_ex[0, 0] = 1.0
    u_ex[0, SIM.INPUT_BLOCKS["hub_wind"].start] = 12.0
    u_ex[0, SIM.INPUT_BLOCKS["shear"].start + 1] = SIM.mean_shear_z(12.0, 0.2)
    vel = np.zeros((1, sim.strip_z.size, 2))
    blade = sim._steady_blade_wind()
    psis = np.linspace(0.0, 2.0 * np.pi / 3.0, 8, endpoint=False)

    def domega(beta_deg: float) -> float:
        ctrl = sim.ctrl0.copy()
        action = np.array([np.deg2rad(beta_deg) - ctrl[2], 0.0])
        return float(np.mean([sim.loads(x, 0, float(p), action, u_ex, vel, ctrl.copy(), blade)[1] for p in psis]))

    return brentq(domega, -2.0, 15.0, xtol=1e-4)


def test_the_straight_rotor_table_is_openfasts_rigid_rotor_in_uniform_wind(runs):
    # AeroDyn's table with rigid blades against the whole OpenFAST deck with its blade DOFs off: 2.927 vs 2.930 deg
    run = runs["uniform_rigid"]
    assert _table_pitch(run, 0.0) == pytest.approx(run["BldPitch1"], abs=0.1)


def test_the_bent_blade_table_gives_most_of_openfasts_flexible_rotor_in_uniform_wind(runs):
    """OpenFAST's flexible blades (4.7 m at the tip) pitch 0.455 deg less than its rigid ones; the bent-blade
    table at that deflection gives 0.471 deg (made at the deck's operating inclination and shear, where bending
    costs more; the same table of an aligned uniform wind gave 0.373): the blades' static shape."""
    rigid, flex = runs["uniform_rigid"], runs["uniform_flex"]
    shift_openfast = flex["BldPitch1"] - rigid["BldPitch1"]
    shift_table = _table_pitch(flex, flex["OoPDefl1"]) - _table_pitch(rigid, 0.0)
    assert shift_openfast < -0.3
    assert shift_table == pytest.approx(shift_openfast, rel=0.25)
    # and the straight blades cannot: no deflection, no shift
    assert _table_pitch(flex, 0.0) - _table_pitch(rigid, 0.0) == pytest.approx(0.0, abs=0.02)


def test_the_simulated_rotor_settles_near_openfasts_in_sheared_wind_at_the_runs_inclination(runs):
    """The steady-wind run's conditions (shear 0.2, the rotor inclined 10.3 deg): OpenFAST's flexible rotor settles
    at 0.99 deg, its rigid one at 2.04. The surrogate's kernel with the run's 5.26 m of tip deflection: 0.95 deg; with
    neither effect 1.50 deg. Known shortfall, measured: the sheared rigid rotor is 0.3 deg weak (1.74 against 2.04
    deg: AeroDyn gives a sheared rotor ~1 % more torque than the blades' sampled wind and its curvature do), and the
    bent blades take 0.80 deg where OpenFAST's take 1.05: the two nearly cancel here."""
    flex, rigid = runs["sheared_flex"], runs["sheared_rigid"]
    with_effects = _kernel_pitch(MODEL, flex, flex["OoPDefl1"])
    without = _kernel_pitch(MODEL.with_effects(blade_deflection=0.0, sampled_wind_curvature=0.0), flex,
                            flex["OoPDefl1"])
    assert abs(with_effects - flex["BldPitch1"]) < 0.25
    assert abs(with_effects - flex["BldPitch1"]) < 0.6 * abs(without - flex["BldPitch1"])
    # each effect on its own moves the rigid and the flexible rotor the way OpenFAST's do
    rigid_curved = _kernel_pitch(MODEL, rigid, 0.0)
    rigid_plain = _kernel_pitch(MODEL.with_effects(sampled_wind_curvature=0.0), rigid, 0.0)
    assert rigid_plain < rigid_curved < rigid["BldPitch1"]
    assert with_effects < rigid_curved - 0.4


def test_the_effects_are_named_switchable_and_only_in_the_nonlinear_rotor():
    from surrogates.effects import EFFECTS, resolve_effects

    for name in ("blade_deflection", "sampled_wind_curvature"):
        assert name in EFFECTS and not EFFECTS[name].linear
        assert resolve_effects("none")[name] == 0.0
    with pytest.raises(ValueError, match="blade_deflection"):
        surrogates.FOWTModel().with_effects(blade_deflection=-1.0)


def test_the_bent_table_is_quadratic_in_the_deflection_and_zero_without_it():
    tab = blade_deflection_table()
    lam, beta = 6.6, np.deg2rad(2.0)
    straight = tab.coefficients(lam, beta, 0.0)
    half = tab.coefficients(lam, beta, 0.5 * tab.tip_deflection)
    full = tab.coefficients(lam, beta, tab.tip_deflection)
    for i in (0, 1):
        assert half[i] - straight[i] == pytest.approx(0.25 * (full[i] - straight[i]), rel=1e-9)
        assert full[i] < straight[i]  # bent blades carry less thrust and torque near rated
