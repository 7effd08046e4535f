"""Output-only and model-based estimators on plain ``(n_samples, n_channels)`` arrays.

Never imports :mod:`surrogates` or Gymnasium: the same code runs on surrogate, OpenFAST or field data.

* preprocessing -- :func:`preprocess`, :class:`Preprocessor` (band-pass + z-score, zero-phase or causal streaming);
* identification -- :class:`HankelDMD`, :class:`SSICov`, :func:`mac`, :func:`pair_modes`,
  :func:`probabilistic_mode_shapes`, :func:`harmonic_candidates`, :func:`lyapunov_exponent` (Rosenstein);
* virtual sensors -- :class:`HoldLastValue` (floor baseline);
* errors -- :class:`NotFittedError` (a ``ValueError``).
"""

from .baseline import HoldLastValue
from .hankel_dmd import HankelDMD, harmonic_candidates, svht_omega, svht_rank
from .lyapunov import (
    LyapunovResult,
    delay_embedding_lag,
    embedding_dimension,
    false_nearest_neighbours,
    lyapunov_exponent,
    lyapunov_time,
)
from .modal import ModeShapeDistribution, mac, pair_modes, probabilistic_mode_shapes, real_mode_shape
from .preprocess import Preprocessor, band_sos, preprocess
from .ssi_cov import SSICov, correlation_sums
from .validation import NotFittedError

__all__ = [
    "HankelDMD",
    "HoldLastValue",
    "LyapunovResult",
    "ModeShapeDistribution",
    "NotFittedError",
    "Preprocessor",
    "SSICov",
    "band_sos",
    "correlation_sums",
    "delay_embedding_lag",
    "embedding_dimension",
    "false_nearest_neighbours",
    "harmonic_candidates",
    "lyapunov_exponent",
    "lyapunov_time",
    "mac",
    "pair_modes",
    "preprocess",
    "probabilistic_mode_shapes",
    "real_mode_shape",
    "svht_omega",
    "svht_rank",
]
