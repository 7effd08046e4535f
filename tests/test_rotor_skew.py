"""Advancing and retreating blades (the ``rotor_skew`` effect) and the blade table behind it.

Independent truth: closed forms (three blades at 120 deg sum ``sin^2`` to 3/2, a rotor's in-plane wind is the
wind's component normal to the shaft) and, where ``../shared`` holds them, OpenFAST's own records: the once-per-
revolution sine term of the blade-root flap moment ``RootMyc1`` at 8 and 12 m/s.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import surrogates
from surrogates.aero import (
    blade_skew_table,
    inclined_rotor_moment,
    inclined_rotor_moment_by_pitch,
    inplane_wind_loads,
    skew_gains,
)
from surrogates.load_cases import load_case
from surrogates.simulate import (
    I_HUB,
    N_EX,
    P_GIP,
    P_INCF0,
    P_INCF1,
    P_SKC0,
    P_SKC1,
    P_SKF,
    P_SKF1,
    P_SKM,
    P_SKT,
    Simulator,
)
from surrogates.structure import N_DOF

SHARED = Path(__file__).resolve().parents[2] / "shared" / "reference" / "openfast" / "runs"


def test_more_airspeed_means_more_thrust_at_fine_pitch_and_less_at_high_pitch():
    t = blade_skew_table()
    omega = 12.1 * math.pi / 30.0
    fine = t.sensitivities(10.0, omega, 0.0)
    high = t.sensitivities(20.0, omega, math.radians(17.0))
    assert fine[0] > 0 and fine[1] > 0 and high[0] < 0 and high[1] < 0
    # the moment's lever (moment over thrust) lies on the blade's outer half, where the lift is
    assert 0.5 * t.radius < fine[1] / fine[0] < t.radius
    # in-plane: more airspeed at the same axial wind lowers the angle of attack, the driving force falls
    assert fine[2] < 0 and high[2] < 0
    # dimensional gains scale with the axial wind at a fixed tip-speed ratio and pitch
    g8 = np.array(t.sensitivities(8.0, 8.0 * 7.0 / t.radius, 0.02))
    g16 = np.array(t.sensitivities(16.0, 16.0 * 7.0 / t.radius, 0.02))
    np.testing.assert_allclose(g16, 2.0 * g8, rtol=1e-12)


@pytest.mark.parametrize("bad", [0.0, -3.0, float("nan"), float("inf")])
def test_bad_wind_for_the_skew_table_is_named(bad):
    with pytest.raises(ValueError, match="wind"):
        blade_skew_table().sensitivities(bad, 1.0, 0.0)
    with pytest.raises(ValueError, match="wind_speed"):
        skew_gains(bad, 0.1)


def _hub_loads(model: surrogates.FOWTModel, case, x: np.ndarray, ctrl: np.ndarray | None = None) -> np.ndarray:
    """Hub loads at state ``x`` and controller state ``ctrl`` (default the model's steady state; pass one to compare
    two models at the same blade pitch: each model's equilibrium holds its own controller steady state)."""
    sim = Simulator(model, case)
    u_ex = np.zeros((1, N_EX))
    u_ex[0, 0] = 1.0
    vel = np.zeros((1, sim.strip_z.size, 2))
    u, _ = sim.loads(x, 0, 0.3, np.zeros(2), u_ex, vel, (sim.ctrl0 if ctrl is None else ctrl).copy())
    return u[I_HUB:I_HUB + 6]


def test_an_inclined_rotor_carries_three_halves_of_one_blades_moment_times_the_in_plane_wind():
    case = load_case(7).replace(wind_speed=12.0)
    on, off = surrogates.FOWTModel(), surrogates.FOWTModel().with_effects(rotor_skew=0.0)
    sim = Simulator(on, case)
    st = sim.system.structure
    x = np.zeros_like(sim.x_eq)
    x[4] = math.radians(4.0)  # platform pitch: the top pitches with it (rigid tower)
    theta = float(st.tower_top_rotation[1] @ x[:N_DOF])
    d = _hub_loads(on, case, x, sim.ctrl0) - _hub_loads(off, case, x, sim.ctrl0)
    g_t, g_m = sim.par[[P_SKT, P_SKM]]
    # ... the table's at the inclination of the equilibrium (found with them: a second pass moves it by ~1e-4)
    inc_eq = float(sim.x_eq[:N_DOF] @ st.tower_top_rotation[1]) - st.data.shaft_tilt_rad
    assert g_t == pytest.approx(skew_gains(12.0, inc_eq)[0], rel=1e-3)
    # the force along the in-plane wind and the moment across it are AeroDyn's (straight, and per m of bend)
    f0, f1, k0, k1 = sim.par[[P_SKF, P_SKF1, P_SKC0, P_SKC1]]
    np.testing.assert_allclose([f0, f1, k0, k1], inplane_wind_loads(12.0), rtol=1e-12)
    # the moment is AeroDyn's (its skewed wake and the blades' cone) at the equilibrium's flap deflection: between
    # the driver's straight (87 kN m per m/s of in-plane wind at 12 m/s) and 5 m-bent (62) rotors
    m0, m1 = inclined_rotor_moment(12.0)
    assert g_m == pytest.approx(m0 + m1 * float(sim.x_eq[10]), rel=0.02)
    assert 60e3 < 1.5 * g_m < 88e3
    w_z = 12.0 * math.sin(theta - st.data.shaft_tilt_rad)  # the wind's component up the disc
    assert d[5] == pytest.approx(1.5 * g_m * w_z, rel=1e-9)  # yaw moment (the advancing blades')
    assert d[2] == pytest.approx(1.5 * f0 * w_z, rel=1e-9)  # vertical in-plane force, along the wind
    # (the moment across the wind up the disc, a tilt moment, is held by the shear's calibrated tilt gain)
    assert d[4] == pytest.approx(0.0, abs=1e-6)
    # the blades' cone and the skewed wake: each blade's in-plane force sees -eps (w . e_r), three blades at
    # 120 deg sum cos^2 to 3/2: a side force 1.5 G eps w_z (blades straight here: the flap deflection is 0)
    g_ip, eps0, eps1 = sim.par[[P_GIP, P_INCF0, P_INCF1]]
    assert d[1] == pytest.approx(1.5 * g_ip * eps0 * w_z, rel=1e-9)
    # bent 5 m downwind, eps grows by 5 eps1 (the bent blades' own share, with blade_deflection on)
    x[10] = 5.0
    d_bent = _hub_loads(on, case, x, sim.ctrl0) - _hub_loads(off, case, x, sim.ctrl0)
    assert d_bent[1] == pytest.approx(1.5 * g_ip * (eps0 + 5.0 * eps1) * w_z, rel=1e-9)
    assert d_bent[2] == pytest.approx(1.5 * (f0 + 5.0 * f1) * w_z, rel=1e-9)
    x[10] = 0.0
    # a yawed rotor: sideways in-plane wind -V sin(yaw) gives a tilt moment (advancing blades), a yaw moment
    # across it and a side force instead (and the cone's vertical force)
    x[4], x[5] = 0.0, math.radians(3.0)
    yaw = float(st.tower_top_rotation[2] @ x[:N_DOF])
    d = _hub_loads(on, case, x, sim.ctrl0) - _hub_loads(off, case, x, sim.ctrl0)
    w_y = -12.0 * math.sin(yaw)
    w_z = 12.0 * math.sin(-st.data.shaft_tilt_rad)  # the shaft's own tilt still inclines the rotor
    assert d[4] == pytest.approx(1.5 * g_m * w_y, rel=1e-9)
    # across the lateral wind: M = 1.5 k e_x x w
    assert d[5] == pytest.approx(1.5 * g_m * w_z + 1.5 * k0 * w_y, rel=1e-9)
    assert d[1] == pytest.approx(1.5 * f0 * w_y + 1.5 * g_ip * eps0 * w_z, rel=1e-9)
    assert d[2] == pytest.approx(1.5 * f0 * w_z - 1.5 * g_ip * eps0 * w_y, rel=1e-9)
    # bent 5 m downwind the force and the moment grow by 5 f1 and 5 k1
    x[10] = 5.0
    d_bent = _hub_loads(on, case, x, sim.ctrl0) - _hub_loads(off, case, x, sim.ctrl0)
    assert d_bent[5] == pytest.approx(1.5 * g_m * w_z + 1.5 * (k0 + 5.0 * k1) * w_y, rel=1e-9)
    assert d_bent[1] == pytest.approx(1.5 * (f0 + 5.0 * f1) * w_y + 1.5 * g_ip * (eps0 + 5.0 * eps1) * w_z, rel=1e-9)


def test_the_inclined_rotors_moment_follows_the_blade_pitch_from_the_equilibriums():
    """At the equilibrium's pitch the moment per m/s of in-plane wind is the case's (P_SKM); 2 deg of pitch further
    it has moved along AeroDyn's operating points (inclined_rotor_moment_by_pitch) by the table's change between
    the two pitches, and falls as AeroDyn's does above rated (87 kN m per m/s at 3.1 deg, 15 at 6 deg)."""
    case = load_case(7).replace(wind_speed=14.0)
    on, off = surrogates.FOWTModel(), surrogates.FOWTModel().with_effects(rotor_skew=0.0)
    sim = Simulator(on, case)
    st = sim.system.structure
    x = np.zeros_like(sim.x_eq)
    x[4] = math.radians(4.0)
    w_z = 14.0 * math.sin(float(st.tower_top_rotation[1] @ x[:N_DOF]) - st.data.shaft_tilt_rad)
    beta, k = inclined_rotor_moment_by_pitch()
    pitch0 = float(sim.ctrl0[2])
    assert 0.1 < pitch0 < 0.2  # rad: above rated, the blades regulate (8.2 deg aligned; less inclined and bent)
    moments = []
    for dp in (0.0, math.radians(2.0)):
        ctrl = sim.ctrl0.copy()
        ctrl[2] = pitch0 + dp
        d = _hub_loads(on, case, x, ctrl) - _hub_loads(off, case, x, ctrl)
        moments.append(d[5])
    g_m = float(sim.par[P_SKM])
    assert moments[0] == pytest.approx(1.5 * g_m * w_z, rel=1e-9)
    shift = float(np.interp(pitch0 + math.radians(2.0), beta, k) - np.interp(pitch0, beta, k))
    assert shift < 0.0
    assert moments[1] == pytest.approx(1.5 * (g_m + shift) * w_z, rel=1e-9)


def test_the_linear_model_holds_the_same_mean_yaw_as_the_nonlinear_rotor():
    """The effect is linear in the in-plane wind: its share of the mean yaw is the same in ``effects="none"``."""
    linear = {k: (1.0 if e.linear else 0.0) for k, e in surrogates.EFFECTS.items()}
    for v in (8.0, 18.0):
        case = load_case(7).replace(wind_speed=v)
        lin = [surrogates.FOWTModel(effects={**linear, "rotor_skew": s}).system(case).equilibrium()[5]
               for s in (1.0, 0.0)]
        # the linear model has no blade deflection (a nonlinear effect), so neither here: the straight rotor's moment
        non = [Simulator(surrogates.FOWTModel().with_effects(rotor_skew=s, blade_deflection=0.0), case).x_eq[5]
               for s in (1.0, 0.0)]
        assert lin[0] - lin[1] == pytest.approx(non[0] - non[1], rel=0.1)
        assert np.sign(non[0] - non[1]) == (1.0 if v < 12 else -1.0)  # reverses with the blades' pitch


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_dir(), reason="needs ../shared/reference/openfast")
@pytest.mark.parametrize("run", ["c_op08_Hs2p0_Tp9", "c_op12_Hs2p5_Tp10"])
def test_the_tables_advancing_blade_moment_is_openfasts_once_per_revolution_sine_term(run):
    """OpenFAST's blade-root flap moment carries a once-per-revolution term in phase with ``sin(azimuth)`` (the
    blade on the -y side, moving down): the table, at the run's mean rotor speed, pitch and inclination, gives
    it within 25 % at 8 and 12 m/s (+22 %, -22 %: mean conditions stand in for a turbulent run's).

    At 18 m/s the table's -329 kN m has the right sign but OpenFAST's term is -34: there the shear's own
    once-per-revolution flap response, whose cosine term is 1295 kN m, lags into the sine; the steady-wind run
    (1.3 deg of pitch) likewise reads 329 for the table's 240."""
    from fowt_env.io import load_record

    rec = load_record(SHARED / run / f"{run}.outb")
    t = np.asarray(rec.t)
    keep = t >= 100.0
    az = np.deg2rad(np.asarray(rec["Azimuth"], float)[keep])
    a = np.column_stack([np.ones(az.size), np.cos(az), np.sin(az)])
    sine_of = np.linalg.lstsq(a, np.asarray(rec["RootMyc1"], float)[keep], rcond=None)[0][2]  # kN m

    def mean(name: str) -> float:
        return float(np.mean(np.asarray(rec[name], float)[keep]))

    shaft_tilt = surrogates.FOWTModel().structure.data.shaft_tilt_rad
    inclination = math.radians(mean("PtfmPitch")) - shaft_tilt
    wind = float(np.mean(np.asarray(rec["Wind1VelX"], float)[keep]))
    g_t, g_m, _ = blade_skew_table().sensitivities(wind * math.cos(inclination), mean("RotSpeed") * math.pi / 30,
                                                   math.radians(mean("BldPitch1")))
    hub_radius = 1.5  # the root moment's lever starts at the blade root
    sine_table = (g_m - hub_radius * g_t) * wind * math.sin(inclination) / 1e3
    assert sine_of > 0
    assert sine_table == pytest.approx(sine_of, rel=0.25)
