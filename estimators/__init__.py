"""Output-only and model-based estimators on plain ``(n_samples, n_channels)`` arrays.

Never imports :mod:`surrogates` or Gymnasium: the same code runs on surrogate, OpenFAST or field data.

* preprocessing -- :func:`preprocess`, :class:`Preprocessor` (band-pass + z-score, zero-phase or causal streaming);
* identification -- :class:`HankelDMD`, :class:`SSICov`, :func:`mac`, :func:`pair_modes`,
  :func:`probabilistic_mode_shapes`, :func:`harmonic_candidates`, :func:`lyapunov_exponent` (Rosenstein);
* order tracking -- :func:`rotor_harmonics` (rotor-locked lines by Hankel-DMD at equal azimuth steps, whatever
  the rotor speed does), :func:`resample_to_azimuth`, :func:`rotor_azimuth`;
* virtual sensors -- :class:`HankelDMDSensor` (causal rolling-horizon Hankel-DMD), :class:`KalmanSensor`
  (augmented Kalman filter on a linear model), :class:`KoopmanKalmanSensor` (Kalman filter on the identified
  Hankel-DMD operator), :class:`HoldLastValue` (floor baseline); all screen their live channels for stuck,
  spiking and out-of-range values with one :class:`FaultScreen`;
* scores -- :func:`r2_score`, :func:`nrmse`, :func:`reconstruction_scores` (the seed paper's definitions);
* errors -- :class:`NotFittedError` (a ``ValueError``).
"""

from .baseline import HoldLastValue
from .dmd_sensor import HankelDMDSensor
from .hankel_dmd import HankelDMD, harmonic_candidates, svht_omega, svht_rank
from .kalman import KalmanSensor
from .koopman_kalman import KoopmanKalmanSensor
from .lyapunov import (
    LyapunovResult,
    delay_embedding_lag,
    embedding_dimension,
    false_nearest_neighbours,
    lyapunov_exponent,
    lyapunov_time,
)
from .metrics import nrmse, r2_score, reconstruction_scores
from .modal import ModeShapeDistribution, mac, pair_modes, probabilistic_mode_shapes, real_mode_shape
from .order_tracking import AngleDomainData, resample_to_azimuth, rotor_azimuth, rotor_harmonics
from .preprocess import Preprocessor, band_sos, preprocess
from .screening import FaultScreen
from .ssi_cov import SSICov, correlation_sums
from .validation import NotFittedError

__all__ = [
    "AngleDomainData",
    "FaultScreen",
    "HankelDMD",
    "HankelDMDSensor",
    "HoldLastValue",
    "KalmanSensor",
    "KoopmanKalmanSensor",
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
    "nrmse",
    "pair_modes",
    "preprocess",
    "probabilistic_mode_shapes",
    "r2_score",
    "real_mode_shape",
    "reconstruction_scores",
    "resample_to_azimuth",
    "rotor_azimuth",
    "rotor_harmonics",
    "svht_omega",
    "svht_rank",
]
