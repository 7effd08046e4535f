"""fowt-env: composition of the surrogate and the estimators (environment, experiments, CLI)."""

__version__ = "0.1.0"
