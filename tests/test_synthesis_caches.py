"""The forcing synthesis's shortcuts give numpy's own numbers: the uniform-grid interpolation of the blade columns
against ``np.interp``, the kept wave transfer rows and coherence factors against computing them afresh (a draw
after another of the same sea or wind equals the first draw bit for bit, and equals a draw with the caches
cleared)."""

from __future__ import annotations

import numpy as np

import surrogates.waves as waves
import surrogates.wind as wind
from surrogates.simulate import _interp_columns
from surrogates.waves import synthesize_waves
from surrogates.wind import synthesize_rotor_wind


def test_interp_columns_is_np_interp_bit_for_bit():
    rng = np.random.default_rng(4)
    t_field = np.arange(400) * 0.05
    values = rng.standard_normal((400, 6))
    t = np.arange(int(21.0 / 0.0125)) * 0.0125 - 0.3  # starts before the field and ends after it
    delay = np.array([0.0, 0.05, 0.0125, -0.37, 1.234, 0.5])  # on and between the field's nodes
    out = np.empty((t.size, values.shape[1]), dtype=np.float32)
    _interp_columns(t, delay, t_field, values, out)
    for c in range(values.shape[1]):
        expected = np.interp(t - delay[c], t_field, values[:, c]).astype(np.float32)
        np.testing.assert_array_equal(out[:, c], expected)


def test_kept_wave_transfer_rows_change_nothing():
    first = synthesize_waves(2.5, 10.0, 1.0, 20.0, 300.0, 0.05, seed=3)
    again = synthesize_waves(2.5, 10.0, 1.0, 20.0, 300.0, 0.05, seed=3)
    waves._transfer_rows_on_grid.cache_clear()
    fresh = synthesize_waves(2.5, 10.0, 1.0, 20.0, 300.0, 0.05, seed=3)
    for name in ("elevation", "excitation", "velocity"):
        np.testing.assert_array_equal(getattr(first, name), getattr(again, name))
        np.testing.assert_array_equal(getattr(first, name), getattr(fresh, name))
    # another sea state on the same grid shares the rows; its loads scale with its own spectrum
    other = synthesize_waves(5.0, 10.0, 1.0, 20.0, 300.0, 0.05, seed=3)
    np.testing.assert_allclose(other.elevation, 2.0 * first.elevation, rtol=1e-12, atol=1e-12)


def test_kept_coherence_factors_change_nothing():
    kw = dict(n_azimuth=8, return_field=True, grid_spacing=10.0)
    first = synthesize_rotor_wind(11.0, 0.15, 120.0, 0.1, seed=5, **kw)
    again = synthesize_rotor_wind(11.0, 0.15, 120.0, 0.1, seed=5, **kw)
    wind._coherence_factors_of.cache_clear()
    fresh = synthesize_rotor_wind(11.0, 0.15, 120.0, 0.1, seed=5, **kw)
    for other in (again, fresh):
        np.testing.assert_array_equal(first.polar_u, other.polar_u)
        np.testing.assert_array_equal(first.rotor_effective, other.rotor_effective)
    assert wind._coherence_factors_of.cache_info().currsize <= wind._FACTOR_CACHE_SIZE
    # kept factors are read-only (a caller cannot corrupt the next draw) and come back as kept
    f_hz, dist = np.array([0.01, 0.02, 0.05]), np.array([[0.0, 5.0], [5.0, 0.0]])
    kept = wind._coherence_factors(f_hz, dist, 11.0, 340.2, None)
    assert wind._coherence_factors(f_hz, dist, 11.0, 340.2, None) is kept
    for pts, _, chol in kept:
        assert not chol.flags.writeable and not pts.flags.writeable
