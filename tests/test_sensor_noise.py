"""The simulation's sensor noise: white plus AR(1) coloured noise per channel, drawn as the one ARMA(1,1) process
their sum is (:func:`surrogates.simulate.arma_sensor_noise`). Independent truth: the closed-form autocovariance of
the sum of a white and an AR(1) sequence, ``w^2 + col^2`` at lag 0 and ``col^2 a^k`` at lag ``k``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surrogates
from surrogates.channels import ALL_CHANNELS
from surrogates.simulate import _sensor_noise, arma_sensor_noise


def _arma_autocovariance(sigma: float, theta: float, a: float, lag: int) -> float:
    """Autocovariance of the stationary ARMA(1,1) ``s = a s[-1] + sigma (eta + theta eta[-1])`` (Box & Jenkins)."""
    g0 = sigma**2 * (1.0 + theta**2 + 2.0 * a * theta) / (1.0 - a * a)
    g1 = sigma**2 * (1.0 + a * theta) * (a + theta) / (1.0 - a * a)
    return g0 if lag == 0 else g1 * a ** (lag - 1)


@pytest.mark.parametrize(("white", "col", "a"), [(1.0, 0.5, 0.9975), (0.2, 2.0, 0.99), (1.0, 1.0, 0.5),
                                                 (0.0, 1.0, 0.9), (1.0, 0.0, 0.9)])
def test_the_arma_has_the_autocovariance_of_white_plus_ar1(white, col, a):
    sigma, theta = arma_sensor_noise(np.array([white]), np.array([col]), a)
    assert abs(theta[0]) < 1.0  # invertible
    for lag in (0, 1, 2, 10):
        target = white**2 + col**2 if lag == 0 else col**2 * a**lag
        assert _arma_autocovariance(float(sigma[0]), float(theta[0]), a, lag) == pytest.approx(target, rel=1e-9,
                                                                                               abs=1e-12)


def test_the_generated_noise_has_that_autocovariance():
    """Sample autocovariance of a long generated sequence (after its start from zero state) within its scatter."""
    white, col = np.array([0.5, 1.0]), np.array([1.0, 0.0])
    a = math.exp(-0.05 / 1.0)
    sigma, theta = arma_sensor_noise(white, col, a)
    n = 400_000
    eta = np.random.default_rng(3).standard_normal((n, 2))
    out = np.empty((n, 2))
    _sensor_noise(np.zeros((n, 2)), eta, white, col > 0, sigma, theta, a, out)
    s = out[2000:, 0]
    for lag, tol in ((0, 0.02), (1, 0.03), (20, 0.06)):
        target = white[0] ** 2 + col[0] ** 2 if lag == 0 else col[0] ** 2 * a**lag
        got = float(np.mean(s[lag:] * s[: s.size - lag]))
        assert got == pytest.approx(target, rel=tol), lag
    # a channel without coloured noise is the white noise itself: its draws times its std, nothing else
    np.testing.assert_array_equal(out[:, 1], eta[:, 1] * white[1])


def test_simulated_noise_has_the_models_levels():
    """``simulate`` adds per channel noise of standard deviation ``sqrt(w^2 + col^2)`` (model.noise), measured on
    the noisy record less the truth."""
    model = surrogates.FOWTModel()
    rec, truth = surrogates.simulate(model, surrogates.load_case(7), 600.0, seed=4, return_truth=True)
    white, col = model.noise.std(list(ALL_CHANNELS))
    expected = np.sqrt(np.asarray(white) ** 2 + np.asarray(col) ** 2)
    for k, name in enumerate(ALL_CHANNELS):
        if name not in rec.channels:
            continue
        e = np.asarray(rec[name]) - np.asarray(truth[name])
        e = e[int(60.0 / rec.dt):]  # after the coloured part's rise from zero state (correlation time 5 s)
        # the coloured part (5 s correlation) leaves ~100 independent values in 600 s: 20 % is ~2 sigma of it
        assert float(np.std(e)) == pytest.approx(float(expected[k]), rel=0.2), name
