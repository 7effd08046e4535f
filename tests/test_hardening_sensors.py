"""Hardening of the virtual sensors (issue 18): one fault screen for every sensor, so a stuck or wild channel that
still reports live degrades one channel, not the whole estimate; no finite input makes an estimate NaN.

Truth here is the noise-free response of a known two-mass oscillator (tests/test_kalman.py), not the sensors' own
output: the stuck-sensor runs are scored against it, as are the clean runs they are compared with.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_kalman import DT, simulate_two_dof, two_dof_system  # tests/ is on sys.path (pytest prepend mode)

from estimators import FaultScreen, HankelDMDSensor, HoldLastValue, KalmanSensor, KoopmanKalmanSensor

SENSORS = {
    "hold": lambda sys: HoldLastValue(fill="mean"),
    "dmd": lambda sys: HankelDMDSensor(delays=40, rank=12, update_interval=0.25, dt=DT),
    "kalman": lambda sys: KalmanSensor(sys, dt=DT, em_iter=3),
    "koopman": lambda sys: KoopmanKalmanSensor(delays=40, rank=12, dt=DT, em_iter=3),
}
HIDDEN = 1  # x2 lost throughout: the sensors have to estimate it
STUCK = 3  # a2: frozen from ONSET on, still reported live
ONSET = 400


def _nrmse(truth, est):
    return np.sqrt(np.mean((truth - est) ** 2, axis=0)) / np.ptp(truth, axis=0)


@pytest.fixture(scope="module")
def data():
    sys = two_dof_system()
    train, _ = simulate_two_dof(sys, 12000, seed=21)
    test, truth = simulate_two_dof(sys, 1600, seed=22)
    return sys, train, test, truth


@pytest.fixture(scope="module", params=sorted(SENSORS))
def fitted(request, data):
    sys, train, _, _ = data
    return request.param, SENSORS[request.param](sys).fit(train)


def _mask(n):
    mask = np.ones((n, 4), dtype=bool)
    mask[:, HIDDEN] = False
    return mask


@pytest.mark.parametrize("hidden", [False, True])
@pytest.mark.parametrize("stuck_at", ["last", "far"])
def test_stuck_live_sensor_degrades_one_channel_only(fitted, data, stuck_at, hidden):
    """a2 frozen from ONSET on while its mask says live. Every other channel is estimated within 10 % of the
    run where a2 is honestly reported lost from ONSET (in this 4-channel system losing a2 is itself a real loss,
    up to +50 % on x1 for the Kalman filter; the stuck value must cost nothing more), with or without x2 hidden."""
    name, sensor = fitted
    _, _, y, truth = data
    mask = _mask(y.shape[0]) if hidden else np.ones(y.shape, dtype=bool)
    reference_mask = mask.copy()
    reference_mask[ONSET:, STUCK] = False
    reference = np.asarray(sensor.reconstruct(y, reference_mask))
    value = {"last": y[ONSET, STUCK], "zero": 0.0, "far": y[ONSET, STUCK] + 3.0 * np.std(y[:, STUCK])}[stuck_at]
    y_stuck = y.copy()
    y_stuck[ONSET:, STUCK] = value
    est = np.asarray(sensor.reconstruct(y_stuck, mask))
    others = [c for c in range(4) if c != STUCK]
    after = slice(ONSET, None)
    nrmse_ref = _nrmse(truth[after], reference[after])[others]
    nrmse_stuck = _nrmse(truth[after], est[after])[others]
    assert np.all(nrmse_stuck <= 1.10 * nrmse_ref), (name, nrmse_ref, nrmse_stuck)
    # the stuck channel is flagged (from the screen's flat-line limit on) and nothing else is, for long
    flags = sensor.rejected_samples_
    limit = int(sensor.screen_.flat_limit_[STUCK])
    assert flags[ONSET + limit + 1:, STUCK].mean() > 0.99, name
    assert flags[:, others].mean() < 0.01, name
    assert sensor.screen_.counts_["flat"][STUCK] > 0.9 * (y.shape[0] - ONSET - limit)


@pytest.fixture(scope="module")
def kalman_pair(data):
    sys, train, _, _ = data
    return (KalmanSensor(sys, dt=DT, em_iter=0).fit(train),
            KoopmanKalmanSensor(delays=40, rank=12, dt=DT, em_iter=0).fit(train))


def _poison(y, k, channel, value):
    out = y.copy()
    out[k, channel] = value
    return out


@pytest.mark.parametrize("value", [1e307, -1.7976931348623157e308, 1e200])
@pytest.mark.parametrize("screen", [True, False])
def test_huge_finite_sample_leaves_every_later_estimate_finite(kalman_pair, data, value, screen):
    """One absurd sample on a live channel: every later estimate and std is finite and, 200 samples on, the
    estimate is back on the clean run's (1e307 made every later Kalman/Koopman-Kalman value NaN). With the
    screen off, the filters' own gate and update must hold the line."""
    _, _, y, _ = data
    y = y[:1000]
    mask = _mask(y.shape[0])
    for sensor in kalman_pair:
        sensor.screen_.active = screen
        clean = sensor.reconstruct(y, mask)
        est, std = sensor.reconstruct(_poison(y, 500, 2, value), mask, return_std=True)
        assert np.all(np.isfinite(est)) and np.all(np.isfinite(std)), type(sensor).__name__
        scale = np.std(y, axis=0)
        np.testing.assert_allclose(est[700:] / scale, clean[700:] / scale, rtol=0, atol=0.05,
                                   err_msg=type(sensor).__name__)


@pytest.mark.parametrize("name", ["dmd", "hold"])
def test_huge_finite_sample_output_only_sensors(fitted, data, name):
    sensor_name, sensor = fitted
    if sensor_name != name:
        pytest.skip("parametrised over the fixture")
    _, _, y, _ = data
    mask = _mask(y.shape[0])
    est = np.asarray(sensor.reconstruct(_poison(y, 500, 2, 1e307), mask))
    assert np.all(np.isfinite(est)) and np.all(np.abs(est) < 1e3 * np.abs(y).max())


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=1, max_size=6),
       where=st.lists(st.integers(0, 299), min_size=1, max_size=6),
       channels=st.lists(st.integers(0, 3), min_size=1, max_size=6),
       screen=st.booleans())
def test_filter_state_stays_finite_for_any_finite_input(kalman_pair, data, values, where, channels, screen):
    """Invariant: finite in, finite out (estimate and std), for any finite values anywhere on live channels."""
    _, _, y, _ = data
    y = y[:300].copy()
    for v, k, c in zip(values, where, channels, strict=False):
        y[k, c] = v
    for sensor in kalman_pair:
        sensor.screen_.active = screen
        est, std = sensor.reconstruct(y, return_std=True)
        assert np.all(np.isfinite(est)) and np.all(np.isfinite(std)), type(sensor).__name__


def test_fault_screen_flags_by_reason():
    rng = np.random.default_rng(3)
    t = np.arange(3000)
    train = np.column_stack([rng.standard_normal(3000), rng.standard_normal(3000), np.sin(t / 10.0)])
    screen = FaultScreen(flat_samples=5).fit([train])
    assert screen.flat_limit_.tolist() == [5, 5, 5]  # continuous data never repeats
    assert screen.max_step_[2] == pytest.approx(0.1, rel=0.01)  # |d sin(t/10)| <= 0.1 per sample
    y = np.column_stack([rng.standard_normal(200), rng.standard_normal(200), np.sin(t[:200] / 10.0)])
    y[50:, 0] = y[50, 0]  # stuck
    y[100, 1] = 1e6  # out of range
    y[150, 2] += 2.0  # a jump of 20 x the largest training step, within the range (10 x 1)
    ok = screen.screen_block(y, np.ones_like(y, dtype=bool))
    assert ok[:55, 0].all() and not ok[55:, 0].any()  # 5 repeats allowed, the 5th and later rejected
    assert not ok[100, 1] and ok[np.arange(200) != 100, 1].all()
    assert not ok[150, 2] and ok[np.arange(200) != 150, 2].all()
    assert screen.counts_["flat"].tolist() == [145, 0, 0]
    assert screen.counts_["range"].tolist() == [0, 1, 0] and screen.counts_["spike"].tolist() == [0, 0, 1]
    assert screen.rejected_samples_.sum(axis=0).tolist() == [145, 1, 1]


def test_fault_screen_accepts_a_new_level_and_repeats_seen_in_training():
    t = np.arange(4000)
    quantised = np.round(np.sin(2 * np.pi * t / 800), 1)  # repeats for ~80 samples at the peaks
    screen = FaultScreen().fit([np.column_stack([quantised, np.sin(t / 10.0)])])
    assert screen.flat_limit_[0] > 100 and screen.flat_limit_[1] == 10
    y = np.column_stack([quantised[:800], np.sin(t[:800] / 10.0)])
    y[400:, 1] += 5.0  # a step of 5 (the training range is +-1, 50 x its largest step): a spike, then a level
    ok = screen.screen_block(y, np.ones_like(y, dtype=bool))
    assert ok[:, 0].all()  # training-like repeats are not a stuck sensor
    assert not ok[400, 1] and ok[410:, 1].all()
    assert 1 <= screen.counts_["spike"][1] <= 10


def test_screen_argument_is_validated(data):
    sys, train, _, _ = data
    with pytest.raises(ValueError, match="screen must be True, False or an estimators.FaultScreen"):
        KalmanSensor(sys, dt=DT, em_iter=0, screen="yes").fit(train)
    with pytest.raises(ValueError, match="flat_samples must be >= 2"):
        HankelDMDSensor(delays=10, rank=4, dt=DT, screen=FaultScreen(flat_samples=1)).fit(train)
