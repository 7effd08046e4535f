"""Largest Lyapunov exponent (Rosenstein et al. 1993) against independent truths.

- Lorenz system (sigma=10, rho=28, beta=8/3), x component at dt = 0.01 s: 0.9056 1/s (Sprott 2003, "Chaos and
  Time-Series Analysis", Table A.1); integrated here with scipy's DOP853 at tight tolerances.
- Hénon map (a=1.4, b=0.3): 0.419 per iteration; logistic map at r=4: ln 2 per iteration (exact).
- A sine, with and without noise: 0. The tolerance |lambda| < 0.05 1/s is 5.5 % of the Lorenz value and, for the
  1.37 Hz sine used, 0.036 e-folds per period: a visible trend over the 7 s divergence curve would be ~0.35 nats.
"""

import doctest
import subprocess
import sys
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.distance import cdist

import estimators.lyapunov as ly
from estimators.lyapunov import (
    LyapunovResult,
    delay_embedding,
    delay_embedding_lag,
    embedding_dimension,
    false_nearest_neighbours,
    lyapunov_exponent,
    lyapunov_time,
    mean_period,
)

LORENZ_LAMBDA = 0.9056  # 1/s, Sprott (2003)
HENON_LAMBDA = 0.41922  # per iteration, Sprott (2003)
DT = 0.01


def _lorenz(t, s, sigma=10.0, rho=28.0, beta=8.0 / 3.0):
    x, y, z = s
    return [sigma * (y - x), x * (rho - z) - y, x * y - beta * z]


@pytest.fixture(scope="module")
def lorenz_x():
    """20,000 samples of Lorenz x at dt = 0.01 s after a 25 s transient (about 3 s to integrate)."""
    n, transient = 20_000, 25.0
    t_eval = transient + DT * np.arange(n)
    sol = solve_ivp(_lorenz, (0.0, t_eval[-1]), [1.0, 1.0, 1.0], method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t_eval)
    assert sol.success
    return sol.y[0]


def henon_x(n=3000, discard=100):
    x = np.zeros(n + discard)
    for i in range(2, x.size):  # x[n+1] = 1 - a x[n]^2 + b x[n-1]
        x[i] = 1.0 - 1.4 * x[i - 1] ** 2 + 0.3 * x[i - 2]
    return x[discard:]


def logistic_x(n=3000, discard=100):
    x = np.empty(n + discard)
    x[0] = 0.3
    for i in range(x.size - 1):
        x[i + 1] = 4.0 * x[i] * (1.0 - x[i])
    return x[discard:]


def sine(n=10_000, f_hz=1.37, noise=0.0, seed=0):
    """A sine whose period (72.99 samples) is not a whole number of samples, plus optional white noise."""
    t = DT * np.arange(n)
    rng = np.random.default_rng(seed)
    return np.sin(2 * np.pi * f_hz * t + 0.3) + noise * rng.standard_normal(n)


# ----------------------------------------------------------------------------------------------- chaotic truths


def test_lorenz_exponent_matches_the_literature_within_15_percent(lorenz_x):
    res = lyapunov_exponent(lorenz_x, DT, return_details=True)
    assert isinstance(res, LyapunovResult)
    assert res.exponent == pytest.approx(LORENZ_LAMBDA, rel=0.15)
    # the embedding the data chose: 3 dimensions (the attractor's), delay near the usual 0.15-0.25 s
    assert res.dim == 3
    assert 15 <= res.lag <= 25
    # a clean linear region before saturation, inside the curve, no diagnostic
    assert res.diagnostic == ""
    assert res.r2 > 0.99
    t0, t1 = res.fit_range
    assert 0.0 <= t0 < t1 <= res.times[-1]
    assert t1 - t0 >= 1.0  # over a second of exponential growth
    assert res.divergence[-1] - res.divergence[0] > 3.0  # several e-folds from neighbours to attractor size
    assert res.lyapunov_time == pytest.approx(1.0 / res.exponent)
    assert res.times.shape == res.divergence.shape == res.fit_line.shape == (res.max_steps + 1,)
    assert res.n_pairs > 10_000


def test_lorenz_with_a_given_embedding_and_fit_range(lorenz_x):
    res = lyapunov_exponent(lorenz_x, DT, dim=3, lag=17, fit_range=(1.0, 2.5), return_details=True)
    assert res.fit_range == pytest.approx((1.0, 2.5))
    assert (res.dim, res.lag) == (3, 17)
    assert res.exponent == pytest.approx(LORENZ_LAMBDA, rel=0.15)
    # the fitted line is the least-squares line over exactly those samples
    k = np.flatnonzero((res.times >= 1.0 - 1e-9) & (res.times <= 2.5 + 1e-9))
    slope = np.polyfit(res.times[k], res.divergence[k], 1)[0]
    assert res.exponent == pytest.approx(slope, rel=1e-9)


def test_henon_and_logistic_maps_per_iteration():
    # same method, embedding from the data: lag 1 (the information has no minimum), dims 2 and 1
    h = lyapunov_exponent(henon_x(), 1.0, return_details=True)
    assert (h.lag, h.dim) == (1, 2)
    assert h.exponent == pytest.approx(HENON_LAMBDA, rel=0.05)
    lg = lyapunov_exponent(logistic_x(), 1.0, return_details=True)
    assert (lg.lag, lg.dim) == (1, 1)
    assert lg.exponent == pytest.approx(np.log(2.0), rel=0.03)


def test_exponent_scales_with_dt_and_ignores_the_signal_unit():
    x = henon_x(2000)
    lam = lyapunov_exponent(x, 1.0)
    # the same samples said to be 0.01 s apart diverge 100 times faster per second
    assert lyapunov_exponent(x, 0.01) == pytest.approx(100 * lam, rel=1e-9)
    # scaling by a power of two is exact in floating point: same neighbours, log shifted by a constant
    assert lyapunov_exponent(4.0 * x, 1.0) == pytest.approx(lam, rel=1e-9)
    # and a column vector is a signal too
    assert lyapunov_exponent(x[:, None], 1.0) == lam


# ------------------------------------------------------------------------------------------- non-chaotic truths


def test_pure_sine_has_zero_exponent():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a flat curve is a clean answer, not a warning
        res = lyapunov_exponent(sine(), DT, return_details=True)
    assert abs(res.exponent) < 0.05
    assert res.diagnostic.startswith("no exponential divergence")
    assert res.dim == 2
    assert res.lyapunov_time == np.inf or res.lyapunov_time > 20.0


def test_exactly_periodic_sine_with_repeated_samples_has_zero_exponent():
    # 200 samples per period: samples repeat exactly; the exact copies are skipped as neighbours
    t = DT * np.arange(6000)
    assert abs(lyapunov_exponent(np.sin(2 * np.pi * 0.5 * t), DT)) < 0.05


@pytest.mark.parametrize("noise", [0.01, 0.1])
def test_sine_plus_noise_has_near_zero_exponent_and_says_why(noise):
    with pytest.warns(RuntimeWarning, match="no linear region resolved"):
        res = lyapunov_exponent(sine(noise=noise), DT, return_details=True)
    assert abs(res.exponent) < 0.05
    assert res.diagnostic.startswith("no linear region resolved")
    # the noise jump itself: the curve reaches its plateau within a few samples
    jump = res.divergence[3] - res.divergence[0]
    assert jump > 0.5


def test_lyapunov_time():
    assert lyapunov_time(0.5) == 2.0
    assert lyapunov_time(0.0) == np.inf
    assert lyapunov_time(-0.3) == np.inf
    with pytest.raises(ValueError, match="exponent"):
        lyapunov_time(float("nan"))


# ---------------------------------------------------------------------------------------------- embedding helpers


def test_delay_embedding_lag_from_mutual_information_and_autocorrelation(lorenz_x):
    assert 15 <= delay_embedding_lag(lorenz_x[:5000]) <= 25
    assert delay_embedding_lag(henon_x()) == 1
    assert delay_embedding_lag(logistic_x(500)) == 1
    # a sine: the autocorrelation crosses 1/e at arccos(1/e) / (2 pi) = 0.19 of a period (50 samples here)
    x = sine(5000, f_hz=2.0, noise=0.01)
    assert delay_embedding_lag(x, method="acf") == pytest.approx(0.19 * 50, abs=1)
    assert 8 <= delay_embedding_lag(x) <= 16  # about a quarter period


def test_embedding_dimension_by_false_nearest_neighbours(lorenz_x):
    x = lorenz_x[:5000]
    fnn = false_nearest_neighbours(x, 20, max_dim=4)
    assert fnn.shape == (4,)
    assert fnn[0] > 0.5 and fnn[2] < 0.01  # 1-D neighbours are mostly false, 3-D ones are true
    assert embedding_dimension(x, 20) == 3
    assert embedding_dimension(henon_x(), 1) == 2
    assert embedding_dimension(logistic_x(), 1) == 1


def test_embedding_dimension_of_noise_warns_and_picks_where_the_fraction_levels_off():
    x = np.random.default_rng(3).standard_normal(3000)
    with pytest.warns(RuntimeWarning, match="never fell to threshold"):
        dim = embedding_dimension(x, 1)
    assert 3 <= dim <= 10


def test_delay_embedding_and_mean_period():
    x = np.arange(10.0)
    emb = delay_embedding(x, 3, 2)
    assert emb.shape == (6, 3)
    np.testing.assert_array_equal(emb[0], [0.0, 2.0, 4.0])
    np.testing.assert_array_equal(emb[-1], [5.0, 7.0, 9.0])
    assert not emb.flags.writeable
    assert mean_period(sine(8000, f_hz=2.0), DT) == pytest.approx(0.5, rel=0.01)


def test_neighbour_search_matches_brute_force():
    # an oversampled trajectory with a Theiler window: most nearest candidates are temporal neighbours, so the
    # windowed segment-tree search does the work; both paths must give the exact constrained nearest neighbour
    rng = np.random.default_rng(7)
    for trial, w in enumerate((0, 5, 60, 150)):
        x = np.sin(0.03 * np.arange(900)) + 0.3 * np.sin(0.071 * np.arange(900)) + 1e-3 * rng.standard_normal(900)
        pts = np.ascontiguousarray(delay_embedding(x, 2 + trial % 2, 7))
        n = pts.shape[0]
        d = cdist(pts, pts)
        idx = np.arange(n)
        d[np.abs(idx[:, None] - idx[None, :]) <= w] = np.inf
        queries = idx[:: 1 + trial]
        j, dist = ly._nearest_neighbours(pts, queries, w, 0.0)
        np.testing.assert_allclose(dist, d[queries].min(axis=1))
        j2, dist2 = ly._windowed_search(pts, queries, w, 0.0, leaf=16)
        np.testing.assert_allclose(dist2, dist)
        assert np.all(np.abs(j - queries) > w)


# ------------------------------------------------------------------------------------------------- determinism


def test_deterministic():
    x = sine(4000, noise=0.05, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        a = lyapunov_exponent(x, DT, return_details=True)
        b = lyapunov_exponent(x.copy(), DT, return_details=True)
    assert a.exponent == b.exponent
    np.testing.assert_array_equal(a.divergence, b.divergence)
    assert (a.lag, a.dim, a.fit_range, a.n_pairs) == (b.lag, b.dim, b.fit_range, b.n_pairs)
    assert delay_embedding_lag(x) == delay_embedding_lag(x.copy())


# ------------------------------------------------------------------------------------------------------- errors


def test_nonfinite_samples_are_named():
    x = henon_x(500)
    x[[10, 11]] = np.nan
    with pytest.raises(ValueError, match=r"x must be finite: NaN at samples \[10, 11\]"):
        lyapunov_exponent(x, 1.0)
    x[10:12] = [0.1, np.inf]
    with pytest.raises(ValueError, match=r"inf at samples \[11\]"):
        delay_embedding_lag(x)


def test_constant_signal_is_rejected():
    with pytest.raises(ValueError, match="constant"):
        lyapunov_exponent(np.full(1000, 3.0), 0.1)
    with pytest.raises(ValueError, match="constant"):
        embedding_dimension(np.zeros(500), 1)


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), float("inf"), "0.01", None])
def test_bad_dt(dt):
    with pytest.raises(ValueError, match="dt"):
        lyapunov_exponent(henon_x(500), dt)


def test_too_short_signals_say_what_they_need():
    with pytest.raises(ValueError, match="at least 16 samples"):
        lyapunov_exponent(henon_x(10), 1.0)
    with pytest.raises(ValueError, match=r"too short for dim=5, lag=20"):
        lyapunov_exponent(henon_x(150), 1.0, dim=5, lag=20, max_steps=60)
    with pytest.raises(ValueError, match="too short to embed"):
        delay_embedding(np.arange(5.0), 3, 3)
    with pytest.raises(ValueError, match="too short for false nearest neighbours"):
        false_nearest_neighbours(henon_x(40), 5, max_dim=10, min_separation=2)


def test_bad_arguments():
    x = henon_x(500)
    with pytest.raises(ValueError, match="1-D signal"):
        lyapunov_exponent(np.c_[x, x], 1.0)
    with pytest.raises(ValueError, match="dim must be >= 1"):
        lyapunov_exponent(x, 1.0, dim=0)
    with pytest.raises(ValueError, match="lag .* must be an integer"):
        lyapunov_exponent(x, 1.0, lag=1.5)
    with pytest.raises(ValueError, match="min_separation"):
        lyapunov_exponent(x, 1.0, min_separation=-1)
    with pytest.raises(ValueError, match="max_steps"):
        lyapunov_exponent(x, 1.0, max_steps=1)
    with pytest.raises(ValueError, match="fit_range must be a pair"):
        lyapunov_exponent(x, 1.0, fit_range=3.0)
    with pytest.raises(ValueError, match="t_start < t_end"):
        lyapunov_exponent(x, 1.0, fit_range=(5.0, 2.0))
    with pytest.raises(ValueError, match="beyond the divergence curve"):
        lyapunov_exponent(x, 1.0, dim=2, lag=1, max_steps=20, fit_range=(0.0, 30.0))
    with pytest.raises(ValueError, match="fewer than two steps"):
        lyapunov_exponent(x, 1.0, dim=2, lag=1, fit_range=(0.2, 0.9))
    with pytest.raises(ValueError, match="method"):
        delay_embedding_lag(x, method="fnn")
    with pytest.raises(ValueError, match="threshold"):
        embedding_dimension(x, 1, threshold=1.5)


def test_no_delay_when_the_signal_is_a_trend():
    with pytest.raises(ValueError, match="no embedding delay found up to max_lag"):
        delay_embedding_lag(np.arange(2000.0) ** 1.5)


# ------------------------------------------------------------------------------------------ docs and packaging


def test_docstring_examples_run():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        result = doctest.testmod(ly)
    assert result.failed == 0 and result.attempted > 0


def test_estimators_lyapunov_imports_neither_surrogates_nor_gym():
    code = (
        "import sys, estimators.lyapunov; "
        "bad = [m for m in ('surrogates', 'fowt_env', 'gymnasium') if m in sys.modules]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
