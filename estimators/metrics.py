"""Reconstruction scores of the seed paper (Section 4): R² and NRMSE per channel, physical and band-passed.

Both take the truth and the estimate as ``(n_samples, n_channels)`` arrays (or 1-D for one channel) and return
one score per channel:

* ``R² = 1 - sum (y - y_hat)² / sum (y - mean(y))²`` (coefficient of determination; 1 is perfect, 0 is the
  mean, negative is worse than the mean);
* ``NRMSE = sqrt(mean (y - y_hat)²) / (max(y) - min(y))`` (the paper's range normalisation, a fraction: 0.05 =
  5 %).

:func:`reconstruction_scores` computes both on the physical, full-band signals (what a fatigue engineer needs)
and on the paper's form -- zero-phase band-pass and z-score, with the statistics of the truth applied to both
signals -- for comparability with its tables.
"""

from __future__ import annotations

import numpy as np

from .preprocess import band_sos
from .validation import check_number

__all__ = ["nrmse", "r2_score", "reconstruction_scores"]


def _pair(truth: object, estimate: object) -> tuple[np.ndarray, np.ndarray]:
    y = np.asarray(truth, dtype=float)
    e = np.asarray(estimate, dtype=float)
    if y.shape != e.shape:
        raise ValueError(f"truth and estimate must have the same shape, got {y.shape} and {e.shape}")
    if y.ndim not in (1, 2) or y.shape[0] < 2:
        raise ValueError(f"truth must be (n_samples,) or (n_samples, n_channels) with n_samples >= 2, got {y.shape}")
    bad = ~(np.isfinite(y) & np.isfinite(e))
    if bad.any():
        raise ValueError(f"truth or estimate is not finite at {int(bad.sum())} entries (first at index "
                         f"{tuple(int(i) for i in np.argwhere(bad)[0])})")
    return y, e


def r2_score(truth: object, estimate: object) -> np.ndarray | float:
    """Coefficient of determination per channel (the seed paper's R²).

    Parameters
    ----------
    truth, estimate : array_like (n_samples,) or (n_samples, n_channels)
        Same units.

    Returns
    -------
    float or ndarray (n_channels,)
        ``1 - SSE / SST``; ``-inf`` for a constant truth that the estimate misses, 1.0 if it matches it.

    Examples
    --------
    >>> import numpy as np
    >>> float(r2_score([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]))
    1.0
    >>> float(r2_score([1.0, 2.0, 3.0], [2.0, 2.0, 2.0]))
    0.0
    """
    y, e = _pair(truth, estimate)
    sse = np.sum((y - e) ** 2, axis=0)
    sst = np.sum((y - y.mean(axis=0)) ** 2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(sst > 0, 1.0 - sse / np.where(sst > 0, sst, 1.0), np.where(sse > 0, -np.inf, 1.0))
    return float(out) if out.ndim == 0 else out


def nrmse(truth: object, estimate: object) -> np.ndarray | float:
    """Root-mean-square error over the range of the truth, per channel (the seed paper's NRMSE, a fraction).

    Parameters
    ----------
    truth, estimate : array_like (n_samples,) or (n_samples, n_channels)
        Same units.

    Returns
    -------
    float or ndarray (n_channels,)
        ``inf`` for a constant truth that the estimate misses, 0.0 if it matches it.

    Examples
    --------
    >>> float(nrmse([0.0, 1.0, 0.0, 1.0], [0.5, 0.5, 0.5, 0.5]))
    0.5
    """
    y, e = _pair(truth, estimate)
    rmse = np.sqrt(np.mean((y - e) ** 2, axis=0))
    rng = np.ptp(y, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(rng > 0, rmse / np.where(rng > 0, rng, 1.0), np.where(rmse > 0, np.inf, 0.0))
    return float(out) if out.ndim == 0 else out


def reconstruction_scores(
    truth: object,
    estimate: object,
    fs: float,
    *,
    band: tuple[float | None, float | None] = (0.25, 5.0),
    order: int = 4,
) -> dict[str, np.ndarray]:
    """R² and NRMSE on the physical signals and on the paper's band-passed, z-scored form.

    Parameters
    ----------
    truth, estimate : array_like (n_samples, n_channels)
        Physical units.
    fs : float
        Sampling rate (Hz).
    band : (low, high)
        Pass band (Hz) of the zero-phase Butterworth filter of the paper's form (0.25-5 Hz there).
    order : int
        Filter order.

    Returns
    -------
    dict
        ``r2``, ``nrmse`` (physical) and ``r2_band``, ``nrmse_band`` (both signals filtered with the same
        zero-phase filter, then centred and scaled by the filtered truth's mean and standard deviation), each an
        ndarray (n_channels,).
    """
    from scipy.signal import sosfiltfilt

    y, e = _pair(truth, estimate)
    if y.ndim == 1:
        y, e = y[:, None], e[:, None]
    fs = check_number("fs", fs, positive=True)
    sos = band_sos(fs, band, order)
    yf = sosfiltfilt(sos, y, axis=0)
    ef = sosfiltfilt(sos, e, axis=0)
    mu, sd = yf.mean(axis=0), yf.std(axis=0)
    sd = np.where(sd > 0, sd, 1.0)
    zy, ze = (yf - mu) / sd, (ef - mu) / sd
    return {"r2": r2_score(y, e), "nrmse": nrmse(y, e), "r2_band": r2_score(zy, ze), "nrmse_band": nrmse(zy, ze)}
