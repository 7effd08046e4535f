"""surrogates.simulate's progress hook (for `fowt-env simulate`'s bar, issue 19 item 3): the chunked run it needs is
the same record bit for bit, and the hook hears of every simulated second exactly once."""

import threading

import numpy as np
import pytest

import surrogates


@pytest.mark.parametrize(("dt", "seed"), [(0.0125, 3), (0.05, [1, 2])])
def test_simulate_with_a_progress_hook_is_the_same_record_and_counts_every_second(dt, seed):
    model = surrogates.FOWTModel()
    heard, lock = [], threading.Lock()

    def hook(seconds: float) -> None:
        with lock:
            heard.append(seconds)

    plain = surrogates.simulate(model, 7, duration=30.0, dt=dt, seed=seed, transient=5.0)
    watched = surrogates.simulate(model, 7, duration=30.0, dt=dt, seed=seed, transient=5.0, on_progress=hook)
    plain, watched = (r if isinstance(r, list) else [r] for r in (plain, watched))
    for a, b in zip(plain, watched, strict=True):
        np.testing.assert_array_equal(a.y, b.y)
        np.testing.assert_array_equal(a.t, b.t)
    n_seeds = len(seed) if isinstance(seed, list) else 1
    assert sum(heard) == pytest.approx(35.0 * n_seeds, rel=1e-9)
    assert len(heard) >= 50 * n_seeds  # about every 1 %: a bar that moves
