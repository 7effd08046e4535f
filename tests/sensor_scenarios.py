"""Shared set-up of the virtual-sensor tests on surrogate data: the seed paper's scenarios and fault checks.

Imported by tests/test_kalman.py, test_koopman_kalman.py and test_dmd_sensor.py (tests/ is on sys.path in
pytest's default prepend import mode). The scenarios come from :data:`fowt_env.faults.SCENARIOS` and the training
OLCs from :data:`fowt_env.compare.PAPER_TRAIN_CASES`, so the tests use the same definitions as the environment and
the comparison harness.
"""

from __future__ import annotations

import copy

import numpy as np

from estimators.metrics import r2_score
from fowt_env.compare import PAPER_TRAIN_CASES
from fowt_env.faults import SCENARIOS as _FAULT_SCENARIOS

SCENARIOS = {name: (s["olc"], tuple(s["hidden"])) for name, s in _FAULT_SCENARIOS.items()}
"""Scenario name -> (test OLC, hidden fore-aft channel indices)."""
PAPER_TRAIN = tuple(PAPER_TRAIN_CASES)
HIDDEN_B = list(SCENARIOS["B"][1])


def hidden_b_mask(n: int) -> np.ndarray:
    """(n, 18) mask with scenario B's channels lost throughout."""
    mask = np.ones((n, 18), dtype=bool)
    mask[:, HIDDEN_B] = False
    return mask


def scenario_record(surrogates, model, name: str, duration: float, seed: int = 7):
    """Noisy and true fore-aft records of a scenario's OLC, its (18,) mask and hidden indices."""
    case, hidden = SCENARIOS[name]
    noisy, truth = surrogates.simulate(model, case, duration=duration, seed=seed, return_truth=True)
    mask = np.ones(18, dtype=bool)
    mask[list(hidden)] = False
    return noisy.planar("FA").y, truth.planar("FA").y, mask, list(hidden)


def check_spikes_are_gated(sensor, y: np.ndarray, truth: np.ndarray) -> None:
    """Spikes (30 std) on 0.5 % of the live samples of scenario B: the fault screen and the gate catch them and
    keep the hidden channels as good as on clean data; without either they are worse."""
    mask = hidden_b_mask(y.shape[0])
    rng = np.random.default_rng(7)
    spikes = (rng.random(y.shape) < 0.005) & mask
    y_spiky = y + spikes * rng.choice([-1.0, 1.0], size=y.shape) * 30.0 * sensor.scale_
    clean = r2_score(truth, sensor.reconstruct(y, mask))[HIDDEN_B]
    gated = r2_score(truth, sensor.reconstruct(y_spiky, mask))[HIDDEN_B]
    assert sensor.gated_counts_.sum() >= 0.9 * spikes.sum()  # by the screen or the gate
    assert (sensor.rejected_samples_ & spikes).sum() >= 0.9 * spikes.sum()  # and flagged where they are
    ungated_sensor = copy.deepcopy(sensor)
    ungated_sensor.gate_sigma = None
    ungated_sensor.screen_.active = False
    ungated = r2_score(truth, ungated_sensor.reconstruct(y_spiky, mask))[HIDDEN_B]
    assert ungated_sensor.n_gated_ == 0 and ungated_sensor.gated_counts_.sum() == 0
    print(f"\nspikes on 0.5% of live samples: hidden R2 clean {np.round(clean, 5)}, gated {np.round(gated, 5)}, "
          f"ungated {np.round(ungated, 5)}")
    assert np.all(gated > clean - 0.002)
    assert np.all(ungated < gated)


def check_stuck_sensor_is_rejected(sensor, y: np.ndarray, truth: np.ndarray) -> None:
    """A live accelerometer frozen from t = 10 s (still reported available) is gated out."""
    mask = hidden_b_mask(y.shape[0])
    y_stuck = y.copy()
    y_stuck[800:, 4] = y[800, 4]  # gauge-5 accelerometer frozen from t = 10 s, still reported available
    est = sensor.reconstruct(y_stuck, mask)
    assert np.all(np.isfinite(est))
    assert sensor.gated_counts_[4] > 0.5 * (y.shape[0] - 800)
    assert r2_score(truth, est)[HIDDEN_B].min() > 0.99
