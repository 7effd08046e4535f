"""OC3 Hywind catenary mooring table against independent truth.

Truth used here: the OpenFAST MAP++ deck of the OC3 Hywind case (geometry), an independent ``moorpy.System``
assembled from that geometry (static loads), and the published linearised mooring matrix of Jonkman 2010
(NREL/TP-500-47535, Table 4-1 geometry, Sec. 4 / Table 4-2 region "mooring system stiffness"): K11 = K22 =
41,180 N/m, K33 = 11,940 N/m, K44 = K55 = 3.11e8 N·m/rad, K15 = -K24 = -2.82e6 N, K66 = 1.156e7 N·m/rad (lines
only; the crow-foot's extra 9.834e7 N·m/rad yaw spring is not part of three single lines).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from surrogates.mooring import OC3_LINES, mooring_loads, mooring_table, read_map_deck, solve_loads, tangent_stiffness

DECK = Path("/work/shared/reference/openfast/decks/5MW_OC3Spar_DLL_WTurb_WavesIrr")
MAP_FILE = DECK / "NRELOffshrBsline5MW_OC3Hywind_MAP.dat"
FST_FILE = DECK / "5MW_OC3Spar_DLL_WTurb_WavesIrr.fst"

# Jonkman 2010, Table 4-1, typed from the report: the fallback when the shared deck is absent.
TABLE_4_1 = dict(depth=320.0, anchor=(853.87, 0.0), fairlead=(5.2, 0.0, -70.0), length=902.2, diameter=0.09,
                 mass=77.7066, ea=384.243e6, repeats=(240.0, 120.0))


def _deck_geometry() -> dict:
    """Line geometry read straight from the MAP++ and .fst text (its own minimal parser), else Table 4-1."""
    if not MAP_FILE.exists():
        return TABLE_4_1
    lines = MAP_FILE.read_text(errors="replace").splitlines()
    tok = [s.split() for s in lines]
    mat = next(t for t in tok if t and t[0] == "Material")
    fix = next(t for t in tok if len(t) > 1 and t[1] == "fix")
    ves = next(t for t in tok if len(t) > 1 and t[1] == "Vessel")
    line = next(t for t in tok if len(t) > 2 and t[0] == "1" and t[1] == "Material")
    rep = next(t for t in tok if t and t[0] == "repeat")
    depth = float(re.search(r"^\s*(\S+)\s+WtrDpth", FST_FILE.read_text(), re.M).group(1))
    return dict(depth=depth, anchor=(float(fix[2]), float(fix[3])),
                fairlead=(float(ves[2]), float(ves[3]), float(ves[4])), length=float(line[2]),
                diameter=float(mat[1]), mass=float(mat[2]), ea=float(mat[3]), repeats=tuple(map(float, rep[1:])))


def _moorpy_system():
    """Three-line MoorPy System with a coupled body whose reference point is the fairlead centre."""
    import moorpy as mp

    g = _deck_geometry()
    ms = mp.System(depth=g["depth"], rho=1025.0, g=9.80665)
    ms.setLineType(dnommm=1000 * g["diameter"], name="oc3", mass=g["mass"], d_vol=g["diameter"], EA=g["ea"])
    zc = g["fairlead"][2]
    ms.addBody(-1, [0, 0, zc, 0, 0, 0])
    for rot in (0.0, *g["repeats"]):
        c, s = np.cos(np.deg2rad(rot)), np.sin(np.deg2rad(rot))
        ax, ay = g["anchor"]
        fx, fy = g["fairlead"][:2]
        ms.addPoint(1, [c * ax - s * ay, s * ax + c * ay, -g["depth"]])
        ms.addPoint(1, [c * fx - s * fy, s * fx + c * fy, 0.0], body=1)
        ms.addLine(g["length"], "oc3", pointA=len(ms.pointList) - 1, pointB=len(ms.pointList))
    ms.initialize()
    return ms, zc


def _moorpy_loads(ms, zc, dx, dy, yaw):
    body = ms.bodyList[0]
    body.setPosition(np.array([dx, dy, zc, 0.0, 0.0, yaw]))
    for line in ms.lineList:
        line.staticSolve()
    return body.getForces(lines_only=True)


@pytest.fixture(scope="module")
def system():
    return _moorpy_system()


@pytest.fixture(scope="module")
def table():
    return mooring_table()


@pytest.mark.skipif(not MAP_FILE.exists(), reason="shared OpenFAST reference decks not present")
def test_layout_constants_match_the_map_deck():
    deck = read_map_deck(MAP_FILE)
    own = _deck_geometry()
    for key in ("fairlead_depth", "anchor_radius", "fairlead_radius", "unstretched_length", "diameter",
                "mass_density", "extensional_stiffness", "seabed_friction", "n_lines"):
        assert OC3_LINES[key] == pytest.approx(deck[key], rel=1e-9), key
    assert sorted(a % 360 for a in OC3_LINES["angles_deg"]) == pytest.approx(deck["angles_deg"])
    # line 1 anchored downwind at (853.87, 0), the others at +-120 deg
    assert OC3_LINES["angles_deg"][0] == 0.0 and own["anchor"] == (853.87, 0.0)
    assert OC3_LINES["anchor_depth"] == own["depth"] == 320.0
    assert OC3_LINES["fairlead_depth"] == -own["fairlead"][2]


@pytest.mark.parametrize("direction_deg", range(0, 360, 45))
@pytest.mark.parametrize("distance", [10.0, 25.0])
def test_static_loads_match_an_independent_moorpy_system(system, table, direction_deg, distance):
    ms, zc = system
    a = np.deg2rad(direction_deg)
    dx, dy = distance * np.cos(a), distance * np.sin(a)
    truth = _moorpy_loads(ms, zc, dx, dy, 0.0)
    truth0 = _moorpy_loads(ms, zc, 0.0, 0.0, 0.0)
    ours = table.loads(dx, dy, 0.0)
    restoring_truth = truth[:2] - truth0[:2]
    restoring_ours = ours[:2] - table.loads0[:2]
    assert np.linalg.norm(restoring_ours - restoring_truth) <= 0.02 * np.linalg.norm(restoring_truth)
    assert np.dot(restoring_truth, [dx, dy]) < 0  # restoring
    assert ours[2] == pytest.approx(truth[2], rel=0.02)  # total vertical pull (pretension + set-down)
    assert np.max(np.abs(ours[3:] - truth[3:])) <= 0.02 * max(np.linalg.norm(truth[3:]), 1e5)


def test_pretension_matches_moorpy_system(system, table):
    ms, zc = system
    truth = _moorpy_loads(ms, zc, 0.0, 0.0, 0.0)
    assert table.loads0[2] == pytest.approx(truth[2], rel=0.005)
    assert np.abs(table.loads0[[0, 1, 3, 4, 5]]).max() < 1.0


@pytest.mark.parametrize("yaw_deg", [-5.0, -2.0, 2.0, 5.0])
def test_yaw_restoring_sign_and_size(system, table, yaw_deg):
    ms, zc = system
    psi = np.deg2rad(yaw_deg)
    mz = table.loads(0.0, 0.0, psi)[5]
    assert np.sign(mz) == -np.sign(psi)
    # Jonkman 2010 lines-only K66 = 1.156e7 N m/rad: same order (the crow-foot spring is extra)
    assert 0.7 < -mz / (1.156e7 * psi) < 1.3
    assert mz == pytest.approx(_moorpy_loads(ms, zc, 0.0, 0.0, psi)[5], rel=0.02)


def test_tangent_stiffness_matches_oc3_published():
    """Jonkman 2010 (NREL/TP-500-47535) mooring matrix about SWL, 1 % (values are published to 3-4 digits)."""
    k = tangent_stiffness(ref_z=0.0)
    assert k[0, 0] == pytest.approx(41_180, rel=0.01)
    assert k[1, 1] == pytest.approx(41_180, rel=0.01)
    assert k[2, 2] == pytest.approx(11_940, rel=0.01)
    assert k[3, 3] == pytest.approx(3.11e8, rel=0.01)
    assert k[4, 4] == pytest.approx(3.11e8, rel=0.01)
    assert k[0, 4] == pytest.approx(-2.82e6, rel=0.01)
    assert k[4, 0] == pytest.approx(-2.82e6, rel=0.01)
    assert k[1, 3] == pytest.approx(2.82e6, rel=0.01)
    assert k[5, 5] == pytest.approx(1.156e7, rel=0.02)
    uncoupled = k.copy()
    for i, j in ((0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (0, 4), (4, 0), (1, 3), (3, 1)):
        uncoupled[i, j] = 0.0
    assert np.abs(uncoupled).max() < 1e-6 * k[3, 3]


def _tolerance(direct, loads0):
    """0.5 % of the restoring load, with a floor of 50 kN / 1 MN m where the restoring load vanishes."""
    d = direct - loads0
    tf = 0.005 * max(np.linalg.norm(d[:3]), 5e4)
    tm = 0.005 * max(np.linalg.norm(d[3:]), 1e6)
    return np.array([tf] * 3 + [tm] * 3)


def test_numba_interpolation_equals_table_and_direct_solve(table):
    rng = np.random.default_rng(7)
    out = np.empty(6)
    for _ in range(60):
        r, a = rng.uniform(0.0, 25.0), rng.uniform(0.0, 2 * np.pi)
        dx, dy, psi = r * np.cos(a), r * np.sin(a), np.deg2rad(rng.uniform(-15.0, 15.0))
        mooring_loads(table.grid_dx, table.grid_dy, table.grid_yaw, table.table, dx, dy, psi, out)
        np.testing.assert_allclose(out, table.loads(dx, dy, psi), rtol=1e-12, atol=1e-6)
        direct = solve_loads((dx, dy, 0.0, 0.0, 0.0, psi))
        assert np.all(np.abs(out - direct) <= _tolerance(direct, table.loads0)), (dx, dy, psi)


def test_extrapolation_is_linear_and_consistent(table):
    out = np.empty(6)
    for dx, dy, psi in [(70.0, 0.0, 0.0), (-45.0, 45.0, 0.3), (0.0, 0.0, -0.4)]:
        mooring_loads(table.grid_dx, table.grid_dy, table.grid_yaw, table.table, dx, dy, psi, out)
        np.testing.assert_allclose(out, table.loads(dx, dy, psi), rtol=1e-12, atol=1e-6)
    # linear beyond the last grid line: equal steps give equal increments
    f = table.loads(np.array([61.0, 62.0, 63.0]), 0.0, 0.0)
    np.testing.assert_allclose(f[2] - f[1], f[1] - f[0], rtol=1e-9, atol=1e-6)


@pytest.mark.parametrize("dx, dy, psi", [(0.0, 15.0, 0.0), (12.0, 20.0, 0.0), (-8.0, 5.0, 0.1)])
def test_mirror_symmetry_about_the_wind_axis(table, dx, dy, psi):
    """The layout is symmetric about the x-z plane: y -> -y, yaw -> -yaw mirrors (Fy, Mx, Mz), keeps (Fx, Fz, My)."""
    mirror = np.array([1, -1, 1, -1, 1, -1])
    for f in (lambda x, y, p: table.loads(x, y, p), lambda x, y, p: solve_loads((x, y, 0, 0, 0, p))):
        np.testing.assert_allclose(f(dx, -dy, -psi), mirror * f(dx, dy, psi), rtol=1e-9, atol=1e-3)
    assert table.loads(dx, dy, psi)[1] < 0 < table.loads(dx, -dy, -psi)[1]


def test_line_one_is_downwind():
    """Line 1 is anchored at +x: a downwind (+x) offset slackens it, an upwind (-x) offset pulls straight into it,
    so the upwind offset meets the larger restoring force (the mirrored layout would give the opposite)."""
    fwd = solve_loads((20.0, 0.0, 0.0, 0.0, 0.0, 0.0))[0]
    back = solve_loads((-20.0, 0.0, 0.0, 0.0, 0.0, 0.0))[0]
    assert back > -fwd > 0


@pytest.mark.parametrize("surge, sway, roll, pitch", [(24.5, -0.4, 0.0045, 0.085), (15.0, 3.0, -0.01, 0.05)])
def test_line_loads_on_the_pitched_platforms_own_axes(table, surge, sway, roll, pitch):
    """The simulation's generalised mooring loads on the platform's roll and yaw are the moments of the exact
    catenary solve (:func:`solve_loads`, an independent direct solve of the three lines at the displaced fairleads)
    about the platform's own axes: the yaw about the spar's axis ``R_y(pitch) R_x(roll) e_z``, the roll about the
    pitched longitudinal axis. The lines act at the fairlead centre, on the spar's axis, so about that axis only
    their spread (5.2 m fairlead radius) counts: a few kN m, where the moment about the fixed vertical is 120-190
    kN m (the mean line force times the fairlead's sideways shift as the spar rolls), which the simulation once
    took for its yaw."""
    from scipy.spatial.transform import Rotation

    from surrogates.mooring import FAIRLEAD_Z
    from surrogates.simulate import N_STATE, _mooring_generalised

    exact = solve_loads(np.array([surge, sway, 0.0, roll, pitch, 0.0]), ref_z=0.0)
    rot = Rotation.from_euler("ZYX", [0.0, pitch, roll]).as_matrix()  # Rz Ry Rx, as solve_loads turns the platform
    spar_axis = rot @ np.array([0.0, 0.0, 1.0])
    roll_axis = Rotation.from_euler("y", pitch).as_matrix() @ np.array([1.0, 0.0, 0.0])
    x = np.zeros(N_STATE)
    x[[0, 1, 3, 4]] = surge, sway, roll, pitch
    out = np.zeros(12)
    _mooring_generalised(x, table.grid_dx, table.grid_dy, table.grid_yaw, table.table, FAIRLEAD_Z, out)
    assert abs(exact[5]) > 1e5  # the moment about the fixed vertical is large ...
    assert abs(spar_axis @ exact[3:]) < 1e4  # ... about the spar's own axis it is not
    assert out[11] == pytest.approx(spar_axis @ exact[3:], abs=5e3)
    assert out[9] == pytest.approx(roll_axis @ exact[3:], rel=0.01, abs=1e4)
