"""The inclined rotor's in-plane wind, met by the coned blades and the skewed wake (``rotor_skew`` with
``blade_deflection``), against OpenFAST.

Independent truth:

* OpenFAST's AeroDyn driver on the deck's rotor at the shared steady-wind run's conditions (tip-speed ratio 6.65,
  blade pitch 1 and 2 deg, shaft inclined 10.2 deg), blades straight and bent 5.26 m downwind: outside the
  conditions of the table the surrogate reads (its operating points, inclined 5 and 10 deg, bent 5 m), in
  ``surrogates/data/inclined_rotor_inplane.json`` (``check_steady_run_conditions``,
  ``tools/inclined_rotor_inplane_table.py``);
* OpenFAST's shared steady-wind run (12 m/s, shear 0.2, waves, platform free): the mean side-to-side response,
  which the shear's side force drives and the inclined rotor's takes back in part.
"""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest

import surrogates
from fowt_env import validation
from surrogates.aero import blade_inplane_sensitivity, inclined_rotor_inplane


@pytest.fixture(scope="module")
def table() -> dict:
    return json.loads(resources.files("surrogates").joinpath("data/inclined_rotor_inplane.json").read_text())


def test_the_bent_blades_side_force_is_aerodyns_at_the_steady_runs_pitch(table):
    """The side force that 5.26 m of tip deflection adds to the rotor inclined 10.2 deg, per the table's linear
    growth ``1.5 G eps_per_m d W``, against AeroDyn's bent minus straight rotor at 1 and 2 deg of pitch (the table's
    operating point at 12 m/s has 3.1 deg): within 25 %."""
    chk = table["check_steady_run_conditions"]
    v = chk["wind_speed"]  # the driver's wind at 12 rpm for tip-speed ratio 6.65
    w = v * math.sin(math.radians(chk["inclination_deg"]))
    e1 = inclined_rotor_inplane(12.0)[1]
    g = float(blade_inplane_sensitivity(12.0)[1].sum()) * v / 12.0  # the gain at the driver's wind
    model = 1.5 * g * e1 * chk["tip_deflection_m"] * w
    for k in range(len(chk["pitch_deg"])):
        aerodyn = chk["side_force_N"]["bent"][k] - chk["side_force_N"]["straight"][k]
        assert aerodyn > 0.0  # the bent blades push the other way from the shear's side force (-14 kN)
        assert model == pytest.approx(aerodyn, rel=0.25)


def test_eps_is_read_and_interpolated_and_bad_wind_is_named(table):
    v = np.asarray(table["wind_speed"])
    e0, e1 = inclined_rotor_inplane(0.5 * (v[7] + v[8]))
    assert e0 == pytest.approx(0.5 * (table["eps_straight"][7] + table["eps_straight"][8]))
    assert e1 == pytest.approx(0.5 * (table["eps_per_m"][7] + table["eps_per_m"][8]))
    assert inclined_rotor_inplane(60.0) == (table["eps_straight"][-1], table["eps_per_m"][-1])
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="wind_speed"):
            inclined_rotor_inplane(bad)


@pytest.fixture(scope="module")
def steady_means():
    model = surrogates.FOWTModel(gauge_heights=surrogates.OPENFAST_GAUGE_HEIGHTS, effects={"rotor_1p": 0.0})
    report = validation.validate(model=model, seeds=2, runs=["d_steady12_Hs2p5_Tp10"], duration=300.0)
    return {c.channel: c for c in report.comparisons if c.statistic == "mean"}


def test_the_steady_wind_runs_mean_side_to_side_response_is_openfasts(steady_means):
    """OpenFAST's steady-wind run holds a mean sway of -0.33 m, roll of 0.231 deg and tower-base side-to-side
    moment of 6.23 MN m: the shaft torque's reaction, plus the shear's side force (-14 kN on straight blades
    aligned with the wind, AeroDyn), less the part the inclined rotor's coned blades and skewed wake take back
    (OpenFAST's flexible rotor puts -10.1 kN on its yaw bearing, its rigid one -19.0 kN). Without that part the
    surrogate held -0.49 m, 0.271 deg and 6.89 MN m (+49, +17 and +11 %); the bounds: roll within 13 %, moment
    within 8 %, and the sway between OpenFAST's flexible rotor's and its rigid rotor's (-0.33 and -0.55 m in still
    water, ``tools/openfast_blade_flex_runs.py``): the static bent blades take back part of the shear's side force,
    OpenFAST's flexible blades ~5 kN more through their dynamics (not modelled; 5 kN over the 41 kN/m of the lines
    is 0.12 m of sway). The roll is the platform's own, about its pitched axis: ElastoDyn's ``PtfmRoll`` less the
    share ``PtfmYaw tan(PtfmPitch)`` of the mean yaw (the next test's). Measured: -0.43 m, 0.248 against 0.223 deg
    (+11 %; ``PtfmRoll`` 0.261 against 0.231) and 6.67 MN m (+6.9 %)."""
    means = steady_means

    def own_roll(side: str) -> float:
        roll, yaw, pitch = (getattr(means[c], side) for c in ("PtfmRoll", "PtfmYaw", "PtfmPitch"))
        return roll - yaw * math.tan(math.radians(pitch))

    assert own_roll("surrogate") == pytest.approx(own_roll("openfast"), rel=0.13)
    c = means["TwrBsMxt"]
    assert c.surrogate == pytest.approx(c.openfast, rel=0.08)
    assert -0.55 < means["PtfmSway"].surrogate < means["PtfmSway"].openfast


@pytest.mark.xfail(strict=True, reason=(
    "measured 0.16 against 0.099 deg: the mean yaw is a small remainder of large moments (the torque reaction on "
    "the tilted shaft, the inclined rotor's moment, the shear's lagged flap response). OpenFAST's is its "
    "yaw-bearing moment, 0.18 MN m, over the yaw stiffness (1.1e8 N m/rad); the surrogate's rotor puts 0.27 MN m on "
    "its hub (README, Known limits)"))
def test_the_steady_wind_runs_mean_yaw_is_openfasts(steady_means):
    """With the inclined rotor's yaw moment from AeroDyn (``inclined_rotor_moment``) the mean yaw was OpenFAST's to
    0.03 deg (0.074 against 0.099)."""
    means = steady_means
    assert means["PtfmYaw"].surrogate == pytest.approx(means["PtfmYaw"].openfast, abs=0.035)
