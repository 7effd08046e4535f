"""Output-only and model-based estimators on plain ``(n_samples, n_channels)`` arrays.

Never imports :mod:`surrogates` or Gymnasium.
"""

__all__: list[str] = []
