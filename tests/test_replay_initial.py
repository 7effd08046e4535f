"""A replay starts from the record's platform rates as well as its positions (closed forms)."""

from __future__ import annotations

import numpy as np
import pytest

import surrogates
from fowt_env.replay import record_initial


def test_record_initial_estimates_the_platform_rates_from_the_positions():
    t = np.arange(0.0, 30.0, 0.1)
    surge = 20.0 + 0.3 * t - 0.002 * t**2          # m: rate 0.3 m/s at t = 0
    pitch = 4.0 + 0.5 * np.sin(2 * np.pi * t / 30.0)  # deg: rate 0.5 * 2 pi / 30 deg/s at t = 0
    rec = surrogates.Record(t, np.column_stack([surge, pitch]), ["PtfmSurge", "PtfmPitch"], ["m", "deg"], {})
    init = record_initial(rec)
    assert init["PtfmSurge"] == pytest.approx(20.0) and init["PtfmPitch"] == pytest.approx(4.0)
    assert init["PtfmTVxi"] == pytest.approx(0.3, rel=1e-6)
    # a quadratic over the first 2 s of a 30 s sine: the cubic term costs ~ (2 pi 2 / 30)^2 / 6 ~ 3 %
    assert init["PtfmRVyi"] == pytest.approx(0.5 * 2 * np.pi / 30.0, rel=0.03)
    assert "PtfmTVzi" not in init  # no heave channel, no heave rate


def test_record_rate_channels_are_taken_as_they_are():
    t = np.arange(0.0, 10.0, 0.1)
    rec = surrogates.Record(t, np.column_stack([np.full_like(t, 5.0), np.full_like(t, -0.2)]),
                            ["PtfmSurge", "PtfmTVxi"], ["m", "m/s"], {})
    assert record_initial(rec)["PtfmTVxi"] == pytest.approx(-0.2)


def test_simulation_starts_with_the_given_platform_velocity():
    model = surrogates.FOWTModel(effects="none")
    v0 = 0.4  # m/s surge, in still water and no wind: a free surge decay from the equilibrium with that velocity
    rec = surrogates.simulate(model, None, duration=4.0, dt=0.0125, transient=0.0, noise=False, seed=0,
                              initial={"PtfmTVxi": v0})
    surge = np.asarray(rec["PtfmSurge"])
    slope = np.polyfit(rec.t[:40] - rec.t[0], surge[:40], 2)[1]
    assert slope == pytest.approx(v0, rel=0.02)
    with pytest.raises(ValueError, match="unknown channel"):
        surrogates.simulate(model, None, duration=1.0, initial={"PtfmTVxx": 1.0})
