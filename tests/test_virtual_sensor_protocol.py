"""Every virtual sensor honours the one protocol: fit / reset / update / reconstruct, causal, NaN = dropout.

Run on the same small system for all of them (a two-mass oscillator driven by a random force; see
tests/test_kalman.py), so a new sensor is checked by adding one line to ``SENSORS``.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_kalman import DT, simulate_two_dof, two_dof_system  # tests/ is on sys.path (pytest prepend mode)

from estimators import HankelDMDSensor, HoldLastValue, KalmanSensor, KoopmanKalmanSensor

SENSORS = {
    "hold": lambda sys: HoldLastValue(fill="mean"),
    "dmd": lambda sys: HankelDMDSensor(delays=40, rank=12, update_interval=0.25, dt=DT),
    "kalman": lambda sys: KalmanSensor(sys, dt=DT, em_iter=3),
    "koopman": lambda sys: KoopmanKalmanSensor(delays=40, rank=12, dt=DT, em_iter=3),
}


@pytest.fixture(scope="module")
def data():
    sys = two_dof_system()
    train_a, _ = simulate_two_dof(sys, 8000, seed=11)
    train_b, _ = simulate_two_dof(sys, 8000, seed=12)
    test, truth = simulate_two_dof(sys, 1600, seed=13)
    return sys, [train_a, train_b], test, truth


@pytest.fixture(scope="module", params=sorted(SENSORS))
def fitted(request, data):
    sys, train, _, _ = data
    return request.param, SENSORS[request.param](sys).fit(train)  # a list of records


def test_streaming_equals_reconstruct_and_is_causal(fitted, data):
    name, sensor = fitted
    _, _, y, _ = data
    rng = np.random.default_rng(1)
    mask = rng.random(y.shape) < 0.75
    mask[:, 1] = False  # one channel lost throughout
    y_in = np.where(mask, y, np.nan)
    batch = np.asarray(sensor.reconstruct(y_in, mask))
    sensor.reset()
    stream = np.array([sensor.update(v, m) for v, m in zip(y_in, mask, strict=True)])
    scale = np.abs(batch).max(axis=0)
    np.testing.assert_allclose(stream / scale, batch / scale, rtol=0, atol=1e-9, err_msg=name)
    k = 900
    y2 = y_in.copy()
    y2[k + 1 :] = 100.0 * rng.standard_normal(y2[k + 1 :].shape)  # a wildly different future
    later = np.asarray(sensor.reconstruct(y2, mask))
    np.testing.assert_allclose(later[: k + 1] / scale, batch[: k + 1] / scale, rtol=0, atol=1e-9, err_msg=name)


def test_nan_on_a_live_channel_is_a_dropout(fitted, data):
    name, sensor = fitted
    _, _, y, _ = data
    rng = np.random.default_rng(2)
    mask = np.ones(y.shape, dtype=bool)
    mask[:, 2] = False
    holes = (rng.random(y.shape) < 0.05) & mask
    a = sensor.reconstruct(np.where(holes, np.nan, y), mask)  # NaN where the mask says "live"
    b = sensor.reconstruct(y, mask & ~holes)
    assert np.all(np.isfinite(a)), name
    np.testing.assert_array_equal(a, b, err_msg=name)


def test_samples_with_every_channel_lost_stay_finite(fitted, data):
    name, sensor = fitted
    _, _, y, truth = data
    mask = np.ones(y.shape, dtype=bool)
    mask[400:640] = False  # 3 s blackout
    est = sensor.reconstruct(np.where(mask, y, np.nan), mask)
    assert np.all(np.isfinite(est)), name
    # a sensor that uses the other channels beats the floor on the channel lost throughout
    mask[:, 0] = False
    if name != "hold":
        est = sensor.reconstruct(np.where(mask, y, np.nan), mask)
        floor = HoldLastValue(fill="mean").fit(data[1]).reconstruct(np.where(mask, y, np.nan), mask)
        after = slice(800, None)
        err, err_floor = (np.mean((e[after, 0] - truth[after, 0]) ** 2) for e in (est, floor))
        assert err < 0.5 * err_floor, name


def test_wrong_channel_count_is_a_clear_error(fitted, data):
    name, sensor = fitted
    _, _, y, _ = data
    with pytest.raises(ValueError, match="shape|channels"):
        sensor.update(y[0, :3], np.ones(3, dtype=bool))
    with pytest.raises(ValueError, match="shape|channels"):
        sensor.reconstruct(np.hstack([y, y[:, :1]]), np.ones((y.shape[0], 5), dtype=bool))


@pytest.mark.parametrize("name", sorted(SENSORS))
def test_a_training_mask_is_the_same_as_nan_in_the_training_data(name, data):
    sys, train, y, _ = data
    masks = [np.ones(r.shape, dtype=bool) for r in train]  # one mask per record: a sensor lost for 2.5 s in each
    masks[0][3000:3200, 2] = False
    masks[1][5000:5200, 1] = False  # channel 1 is the one reconstructed below
    with_mask = SENSORS[name](sys).fit(train, mask=masks)
    with_nan = SENSORS[name](sys).fit([np.where(m, r, np.nan) for m, r in zip(masks, train, strict=True)])
    live = np.ones(y.shape, dtype=bool)
    live[:, 1] = False
    np.testing.assert_array_equal(with_mask.reconstruct(y, live), with_nan.reconstruct(y, live), err_msg=name)
