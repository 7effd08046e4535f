"""The rotor's quasi-static operating points near rated, against OpenFAST with the platform held.

``tools/openfast_quasi_static_runs.py`` ran the shared OC3 deck with every platform DOF off at 4.8 deg of pitch (the
shared steady 12 m/s run's mean: the rotor inclined 9.8 deg), no sea, steady wind with the deck's shear (exponent
0.2), flexible blades, DISCON; ``fowt_env/data/openfast_quasi_static.json`` holds the means of the settled runs.
The surrogate is held the same way (stiff springs about the same position, :class:`_HeldAt`) in the same wind.

Measured (OpenFAST / surrogate):

=========  =================  ===================  ===================
wind m/s   blade pitch deg    thrust kN            held yaw moment kN m
=========  =================  ===================  ===================
11.8       0 / 0              895.3 / 896.9        216 / 346
12.0       0.977 / 0.947      868.6 / 872.2        196 / 330
12.2       2.155 / 2.161      824.1 / 824.8        173 / 313
12.4       3.016 / 3.018      793.6 / 793.8        158 / 270
=========  =================  ===================  ===================
"""

from __future__ import annotations

import json
from dataclasses import replace
from importlib import resources

import numpy as np
import pytest
from test_yaw_locked import _Held  # tests/ is on sys.path (pytest prepend mode)

import surrogates
from fowt_env import validation as V
from surrogates.simulate import I_NL
from surrogates.structure import DOF_LABELS

DATA = resources.files("fowt_env") / "data"
PLATFORM = ("surge", "sway", "heave", "roll", "pitch", "yaw")


class _HeldAt(_Held):
    """:class:`test_yaw_locked._Held` with the pitch spring about ``pitch_deg`` instead of 0 (a constant force
    ``k pitch`` on the constant input)."""

    def __init__(self, pitch_deg: float, **kw) -> None:
        super().__init__(PLATFORM, **kw)
        self.pitch0 = np.deg2rad(pitch_deg)

    def _system(self, case, nonlinear_rotor, mean_pitch=None):
        sys = super()._system(case, nonlinear_rotor, mean_pitch)
        i = DOF_LABELS.index("pitch")
        b = sys.B.copy()
        b[:, 0] += self.springs[i][0] * self.pitch0 * sys.B[:, I_NL + i]
        return replace(sys, B=b)


@pytest.fixture(scope="module")
def reference() -> dict:
    return json.loads((DATA / "openfast_quasi_static.json").read_text())


@pytest.fixture(scope="module")
def surrogate_points(reference) -> dict[float, dict[str, float]]:
    """The held surrogate settled in each flexible, sheared run's steady wind (60 s after 140 s), without waves."""
    case = json.loads((DATA / "openfast_reference" / "d_steady12_Hs2p5_Tp10.case.json").read_text())
    base = V.surrogate_case(case).replace(hs=0.001)
    out = {}
    for run in reference["runs"].values():
        if run["rigid_blades"] or run["shear_exponent"] == 0.0:
            continue
        u = float(run["wind_speed"])
        model = _HeldAt(reference["platform_pitch_deg"],
                        effects={**surrogates.FOWTModel().effects, "rotor_1p": 0.0})
        sim = surrogates.simulate(model, base.replace(wind_speed=u), duration=60.0, seed=1, transient=140.0,
                                  noise=False)
        mean = {c: float(np.mean(sim[c])) for c in ("BldPitch1", "RotThrust", "GenPwr", "RotSpeed", "PtfmPitch")}
        mean["YawBrMzp"] = model.spring * np.deg2rad(float(np.mean(sim["PtfmYaw"]))) / 1e3
        out[u] = mean
    return out


def _openfast(reference: dict, u: float) -> dict[str, float]:
    return next(r["mean"] for r in reference["runs"].values()
                if r["wind_speed"] == u and not r["rigid_blades"] and r["shear_exponent"] > 0.0)


def test_the_reference_is_the_held_rotor_across_rated(reference):
    """A guard on the reading: four settled flexible runs, the lowest below rated (pitch 0, power short of 5 MW),
    the others regulating 5 MW at 12.1 rpm with the pitch rising."""
    flex = sorted((r["wind_speed"], r) for r in reference["runs"].values()
                  if not r["rigid_blades"] and r["shear_exponent"] > 0.0)
    assert [u for u, _ in flex] == [11.8, 12.0, 12.2, 12.4]
    assert flex[0][1]["mean"]["BldPitch1"] < 0.01 and flex[0][1]["mean"]["GenPwr"] < 4950.0
    pitches = [r["mean"]["BldPitch1"] for _, r in flex]
    assert all(b > a for a, b in zip(pitches[1:-1], pitches[2:], strict=True))
    assert all(r["pitch_std_deg"] < 0.02 for _, r in flex)


def test_the_platform_is_held_where_openfasts_is(surrogate_points, reference):
    for mean in surrogate_points.values():
        assert mean["PtfmPitch"] == pytest.approx(reference["platform_pitch_deg"], abs=0.01)


@pytest.mark.parametrize("u", [11.8, 12.0, 12.2, 12.4])
def test_the_steady_pitch_and_thrust_are_openfasts(u, surrogate_points, reference):
    """Blade pitch within 0.1 deg and thrust within 1.5 % of OpenFAST's, rotor speed within 0.5 % and power within
    1.5 % (measured: 0.03 deg, 0.4 %, 0.05 % and 0.5 %). The pitch's slope across rated sets the thrust's change
    with the relative wind, which sets how the operating platform surges slowly."""
    of, s = _openfast(reference, u), surrogate_points[u]
    assert s["BldPitch1"] == pytest.approx(of["BldPitch1"], abs=0.1)
    assert s["RotThrust"] == pytest.approx(of["RotThrust"], rel=0.015)
    assert s["RotSpeed"] == pytest.approx(of["RotSpeed"], rel=0.005)
    assert s["GenPwr"] == pytest.approx(of["GenPwr"], rel=0.015)


@pytest.mark.xfail(strict=True, reason="the held rotor's mean yaw moment is 1.6-1.7x OpenFAST's (330 against 196 "
                                       "kN m at 12 m/s): most of OpenFAST's comes from the shear on the inclined "
                                       "rotor (-475 kN m without it), which the surrogate does not split this way")
def test_the_held_mean_yaw_moment_is_openfasts(surrogate_points, reference):
    for u in (12.0, 12.4):
        assert surrogate_points[u]["YawBrMzp"] == pytest.approx(_openfast(reference, u)["YawBrMzp"], rel=0.25)
