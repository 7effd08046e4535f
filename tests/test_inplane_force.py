"""The blades' in-plane force sensitivity (surrogates.aero) and its blade winds: properties and clear errors."""

from __future__ import annotations

import numpy as np
import pytest

import surrogates
from surrogates.aero import blade_inplane_sensitivity, inplane_ring_weights, operating_point
from surrogates.model import inplane_gradient_gain
from surrogates.replay import MeasuredWind, blade_effective_wind, stepper_blade_winds
from surrogates.simulate import N_BLADE_AZIMUTH, N_BLADE_COLUMNS
from surrogates.wind import synthesize_rotor_wind


def test_ring_weights_share_every_nodes_gain_between_its_neighbouring_rings():
    rings = np.array([0.0, 15.75, 31.5, 47.25, 63.0])
    w, gain = inplane_ring_weights(rings, 12.0)
    r, s = blade_inplane_sensitivity(12.0)
    assert gain == pytest.approx(float(s.sum()))
    assert np.all(w >= 0.0) and w.sum() == pytest.approx(1.0)
    # linear interpolation keeps the first moment: the weights' mean radius is the nodes' gain-weighted one
    assert float(w @ rings) == pytest.approx(float(np.sum(s * r) / s.sum()), abs=0.5)
    # a single ring carries everything
    one, g1 = inplane_ring_weights([63.0], 12.0)
    assert one.tolist() == [1.0] and g1 == pytest.approx(gain)


def test_the_blades_in_plane_gain_grows_with_pitch_above_rated_and_its_gradient_gain_is_about_half_dq_du():
    gains = [inplane_ring_weights([0.0, 63.0], v)[1] for v in (8.0, 12.0, 18.0, 24.0)]
    assert np.all(np.diff(gains) > 0)  # more pitch, more in-plane response to the wind
    for v in (8.0, 12.0, 18.0):
        assert 0.4 < inplane_gradient_gain(v) / operating_point(v).dQ_dV < 0.65


@pytest.mark.parametrize(("args", "match"), [
    (([0.0, 10.0, 5.0], 12.0), "increasing"),
    (([0.0, np.nan], 12.0), "increasing"),
    (([0.0, 63.0], 0.0), "wind_speed"),
    (([0.0, 63.0], float("nan")), "wind_speed"),
])
def test_bad_ring_weights_arguments_are_named(args, match):
    with pytest.raises(ValueError, match=match):
        inplane_ring_weights(*args)


def test_blade_winds_with_weights_and_their_errors():
    w = synthesize_rotor_wind(12.0, 0.15, duration=20.0, dt=0.1, seed=1, n_azimuth=16)
    radial = blade_effective_wind(w.polar_u, w.polar_radii, w.polar_azimuth_rad, 24)
    on_tip = blade_effective_wind(w.polar_u, w.polar_radii, w.polar_azimuth_rad, 24, weights=[0, 0, 0, 0, 1])
    assert radial.shape == on_tip.shape == (200, 24) and not np.allclose(radial, on_tip)
    np.testing.assert_allclose(on_tip[:, ::3], w.polar_u[:, 4, ::2], atol=1e-5)  # azimuths shared by both grids
    for bad in ([1, 1], [0, 0, 0, 0, 0], [0, 0, 0, -1, 2], [0, 0, 0, np.nan, 1]):
        with pytest.raises(ValueError, match="weights"):
            blade_effective_wind(w.polar_u, w.polar_radii, w.polar_azimuth_rad, 24, weights=bad)
    with pytest.raises(ValueError, match="grid_spacing"):
        synthesize_rotor_wind(12.0, 0.15, duration=20.0, dt=0.1, grid_spacing=-4.8)


def test_a_measured_wind_without_in_plane_winds_lets_the_blade_winds_stand_in():
    t = np.arange(0.0, 200.0, 0.1)
    blade = 12.0 + 0.5 * np.sin(t[:, None] * 0.3 + np.arange(12)[None, :])
    cols = stepper_blade_winds(blade.astype(np.float32))
    assert cols.shape == (t.size, N_BLADE_COLUMNS)
    np.testing.assert_array_equal(cols[:, :N_BLADE_AZIMUTH], cols[:, N_BLADE_AZIMUTH:])
    hub = np.full(t.size, 12.0)
    wind = MeasuredWind(t, hub, hub, blade=blade, level="field", x_ref=None)
    assert wind.blade_inplane is None
    lc = surrogates.operating_case(12.0, 0.0, 10.0, turbulence_intensity=0.0)
    rec = surrogates.simulate(surrogates.FOWTModel(), lc, wind=wind, transient=20.0, noise=False)
    assert np.all(np.isfinite(rec.y))
    with pytest.raises(ValueError, match="blade_inplane needs blade"):
        MeasuredWind(t, hub, hub, blade_inplane=blade, level="field")
    with pytest.raises(ValueError, match="shape of blade"):
        MeasuredWind(t, hub, hub, blade=blade, blade_inplane=blade[:, :6], level="field")
