"""A deliberately slow virtual sensor for the campaign tests (not a test module).

Its ``reconstruct`` (run once per task) first leaves a marker file, then sleeps, so that a test knows a task is
under way and can signal the campaign in the middle of it. Run as a script, it registers the sensor as ``slow`` and
runs the ``fowt-env`` command line::

    python campaign_slow_sensor.py SECONDS MARKER_DIR -- campaign --estimators hold,slow ...
"""

from __future__ import annotations

import os
import sys
import time
import uuid
from pathlib import Path

import numpy as np

from fowt_env import compare as C


class SlowHold:
    """The training mean, after ``seconds`` of sleep per reconstruction (and a marker file in ``markers``)."""

    def __init__(self, seconds: float, markers: str | None) -> None:
        self.seconds, self.markers = float(seconds), markers

    def fit(self, Y, mask=None):
        self.mean_ = np.mean(np.concatenate(Y), axis=0)
        return self

    def reconstruct(self, Y, mask):
        if self.markers:
            (Path(self.markers) / f"task-{os.getpid()}-{uuid.uuid4().hex[:8]}").touch()
        end = time.monotonic() + self.seconds
        while time.monotonic() < end:  # short naps: a signal lands in the middle of the task
            time.sleep(0.02)
        return np.broadcast_to(self.mean_, Y.shape).copy()


def register(seconds: float, markers: str | None = None) -> None:
    """Register (or replace) the ``slow`` estimator."""
    C.register_estimator("slow", lambda dt, ui, **_: SlowHold(seconds, markers), uses_update_interval=False,
                         replace=True)


if __name__ == "__main__":
    register(float(sys.argv[1]), sys.argv[2])
    from fowt_env.cli import main

    sys.exit(main(sys.argv[sys.argv.index("--") + 1:]))
