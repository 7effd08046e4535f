"""Calibrated standard deviations of channels a filter does not measure: one rule for the Kalman-type sensors.

A leave-one-channel-out calibration (done in each sensor's ``fit``) finds, per channel ``i``, the factor ``k_i`` by
which the filter's standard deviation ``s_L,i`` of that channel, with every other channel measured, must be scaled
so that ``+-1.96 k_i s_L,i`` covers 95 % of its real error. The factor is learned with one channel lost and
applied to whatever set of channels is lost, where the filter's own standard deviation ``s_i`` is larger. How it
transfers depends on why it is not 1:

* ``k_i > 1``: the real error holds a part the model does not know about (an unmodelled load path, a slow sensor
  error read as response). That part does not shrink or grow with the set of channels measured, so it is added
  as a variance, ``(k_i^2 - 1) s_L,i^2``, to the filter's ``s_i^2``. Scaling ``s_i`` by ``k_i`` instead would widen
  the intervals of a scenario with many lost channels far beyond the error (on the surrogate, 99-99.9 % coverage
  for the nacelle bending moment where the calibration aims at 95 %).
* ``k_i < 1``: the filter overstates its uncertainty of the channel (too much process noise where the sensor
  noise is), by a common factor of its covariances, so ``s_i`` is scaled by ``k_i``.

Both reduce to ``k_i s_L,i`` at the calibration's own pattern (channel ``i`` alone lost).
"""

from __future__ import annotations

import numpy as np

__all__ = ["unmeasured_std", "model_error_std", "calibration_terms"]


def model_error_std(interval_scale: np.ndarray, loo_std: np.ndarray) -> np.ndarray:
    """Standard deviation of the unmodelled error per channel, ``sqrt(max(k^2 - 1, 0)) s_L``.

    Parameters
    ----------
    interval_scale : ndarray (n_channels,)
        Calibration factors ``k`` at the leave-one-out pattern (-).
    loo_std : ndarray (n_channels,)
        The filter's standard deviation of each channel with every other channel measured (channel units).

    Returns
    -------
    ndarray (n_channels,)
        Channel units; 0 where ``k <= 1``.
    """
    k = np.asarray(interval_scale, dtype=float)
    return np.sqrt(np.maximum(k * k - 1.0, 0.0)) * np.asarray(loo_std, dtype=float)


def unmeasured_std(filter_std: np.ndarray, interval_scale: np.ndarray, error_std: np.ndarray) -> np.ndarray:
    """Calibrated standard deviation of channels not measured at a sample.

    Parameters
    ----------
    filter_std : ndarray (n_channels,)
        The filter's own standard deviation of each channel at this sample (channel units).
    interval_scale : ndarray (n_channels,)
        Calibration factors ``k`` (-); only ``min(k, 1)`` scales ``filter_std``.
    error_std : ndarray (n_channels,)
        :func:`model_error_std` of the same factors (channel units).

    Returns
    -------
    ndarray (n_channels,)
        ``sqrt((min(k, 1) filter_std)^2 + error_std^2)`` (channel units).
    """
    shrunk = np.minimum(interval_scale, 1.0) * filter_std
    return np.sqrt(shrunk * shrunk + error_std * error_std)


def calibration_terms(interval_scale: object, loo_std: np.ndarray, n_channels: int) -> tuple[np.ndarray, np.ndarray]:
    """Checked factors and their :func:`model_error_std`, as a sensor's ``reset()`` reads them.

    Parameters
    ----------
    interval_scale : array_like (n_channels,)
        The sensor's ``interval_scale_`` (-).
    loo_std : ndarray (n_channels,)
        Its ``calibration_["loo_std"]`` (channel units).
    n_channels : int
        Number of channels.

    Returns
    -------
    k, error_std : ndarray (n_channels,)

    Raises
    ------
    ValueError
        If the factors are not ``n_channels`` positive finite numbers.
    """
    k = np.array(interval_scale, dtype=float)
    if k.shape != (n_channels,) or not np.all((k > 0) & np.isfinite(k)):
        raise ValueError(f"interval_scale_ must hold {n_channels} positive finite factors, got {interval_scale!r}")
    return k, model_error_std(k, loo_std)
