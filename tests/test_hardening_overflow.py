"""Hardening against overflow (issue 18 item 5): data whose statistics overflow float64 get one clear error naming
the channel and its magnitude, instead of all-zero preprocessing, "Internal Error" or a NaN-to-int crash; data
just inside the limit give the same (scale-free) result as unscaled data."""

from __future__ import annotations

import numpy as np
import pytest
from test_kalman import DT, simulate_two_dof, two_dof_system  # tests/ is on sys.path (pytest prepend mode)

from estimators import (
    HankelDMD,
    HankelDMDSensor,
    KoopmanKalmanSensor,
    Preprocessor,
    SSICov,
    lyapunov_exponent,
    preprocess,
)
from estimators.validation import MAX_ABS


@pytest.fixture(scope="module")
def y():
    noisy, _ = simulate_two_dof(two_dof_system(), 3000, seed=5)
    return noisy


FITS = {
    "preprocess": lambda Y: preprocess(Y, fs=1 / DT, band=(0.25, 5.0)),
    "Preprocessor": lambda Y: Preprocessor(fs=1 / DT).fit(Y),
    "HankelDMD": lambda Y: HankelDMD(delays=20, rank=8, dt=DT).fit(Y),
    "SSICov": lambda Y: SSICov(dt=DT).fit(Y),
    "lyapunov_exponent": lambda Y: lyapunov_exponent(Y[:, 0], DT),
    "HankelDMDSensor": lambda Y: HankelDMDSensor(delays=20, rank=8, dt=DT).fit(Y),
    "KoopmanKalmanSensor": lambda Y: KoopmanKalmanSensor(delays=20, rank=8, dt=DT, em_iter=0).fit(Y),
}


@pytest.mark.parametrize("name", sorted(FITS))
@pytest.mark.parametrize("factor", [1e300, 1e160])
def test_overflowing_data_is_a_clear_error_naming_the_channel(y, name, factor):
    Y = y.copy()
    Y[:, 0] *= factor
    with pytest.raises(ValueError, match=r"channel 0 reaches .* beyond 1e\+150") as err:
        FITS[name](Y)
    assert "\n" not in str(err.value)


def test_overflow_limit_is_scale_free_inside(y):
    """preprocess z-scores each channel, so data scaled by 1e140 (inside MAX_ABS) give the unscaled result."""
    assert np.abs(y).max() * 1e140 < MAX_ABS
    ref = preprocess(y, fs=1 / DT)
    big = preprocess(y * 1e140, fs=1 / DT)
    assert np.any(ref != 0.0)
    np.testing.assert_allclose(big, ref, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize(("edit", "message"), [
    (lambda Y: Y.astype(complex) + 1j, "must be real"),
    (lambda Y: np.where(np.arange(Y.shape[0])[:, None] == 7, np.inf, Y), r"must be finite \(no ±inf\): channel 0"),
    (lambda Y: Y * 1e300, "beyond 1e\\+150"),
])
def test_one_input_contract_for_every_estimator_fit(y, edit, message):
    """KalmanSensor.fit dropped the imaginary part of complex input and took ±inf that the others refuse."""
    from estimators import KalmanSensor

    bad = edit(y)
    for fit in (lambda Y: KalmanSensor(two_dof_system(), dt=DT, em_iter=0).fit(Y),
                lambda Y: KoopmanKalmanSensor(delays=20, rank=8, dt=DT, em_iter=0).fit(Y),
                lambda Y: HankelDMDSensor(delays=20, rank=8, dt=DT).fit(Y)):
        with pytest.raises(ValueError, match=message):
            fit(bad)
