"""The calibration rule for unmeasured channels (estimators.intervals), against its closed form."""

import numpy as np

from estimators.intervals import model_error_std, unmeasured_std


def test_factor_above_one_adds_a_fixed_variance_and_below_one_scales():
    k = np.array([2.0, 0.5, 1.0])
    s_loo = np.array([1.0, 4.0, 3.0])
    err = model_error_std(k, s_loo)
    np.testing.assert_allclose(err, [np.sqrt(3.0), 0.0, 0.0])
    # at the leave-one-out pattern (the filter's std equals s_loo) the rule is the factor times the std
    np.testing.assert_allclose(unmeasured_std(s_loo, k, err), k * s_loo)
    # with more channels lost the filter's std doubles: the unmodelled part stays, a shrink factor scales
    wide = unmeasured_std(2.0 * s_loo, k, err)
    np.testing.assert_allclose(wide, [np.sqrt(4.0 + 3.0), 0.5 * 8.0, 6.0])
    assert wide[0] < 2.0 * (k * s_loo)[0]  # less than proportional widening
