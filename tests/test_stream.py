"""The streaming simulator behind the environment: same physics as simulate(), continuous chunk joins."""

import numpy as np
import pytest

import surrogates
from surrogates.channels import ALL_CHANNELS


def _stream(model, case, seconds, seed, chunk=60.0, overlap=10.0, step=40):
    sim = surrogates.StreamingSimulator(model, case, chunk_seconds=chunk, overlap_seconds=overlap)
    sim.reset(seed)
    out = [sim.advance(step, np.zeros(2), noise=False)[1] for _ in range(int(seconds / (step * sim.dt)))]
    return np.concatenate(out), sim


def test_streamed_response_statistics_match_batch_simulation():
    """With the default 600 s chunks the streamed tower response has the batch statistics (wave-frequency and
    tower bands, where 20 minutes hold many cycles) and the same mean offsets."""
    from scipy.signal import butter, sosfiltfilt

    model = surrogates.FOWTModel()
    streamed, sim = _stream(model, 4, 1800.0, seed=1, chunk=600.0, overlap=30.0)
    batch = surrogates.simulate(model, 4, duration=1800.0, seed=1, noise=False)
    sos = butter(4, [0.08, 1.0], btype="band", fs=1 / sim.dt, output="sos")
    for name in ("TwHt9ALxt", "TwHt5MLyt"):
        i = ALL_CHANNELS.index(name)
        s_std = np.std(sosfiltfilt(sos, streamed[:, i]))
        assert s_std == pytest.approx(np.std(sosfiltfilt(sos, batch[name])), rel=0.2)
    for name in ("PtfmPitch", "PtfmSurge", "TwHt1MLyt"):
        i = ALL_CHANNELS.index(name)
        assert np.mean(streamed[:, i]) == pytest.approx(np.mean(batch[name]), rel=0.1)


def test_chunk_joins_are_continuous():
    """Across a forcing chunk boundary the wave elevation changes no more than elsewhere."""
    model = surrogates.FOWTModel()
    y, sim = _stream(model, 7, 200.0, seed=3, chunk=60.0, overlap=10.0)
    eta = y[:, ALL_CHANNELS.index("Wave1Elev")]
    jumps = np.abs(np.diff(eta))
    per_chunk = int(round(60.0 / sim.dt))
    warm = sim.warmup
    boundaries = [k * per_chunk - warm - 1 for k in (1, 2, 3) if 0 < k * per_chunk - warm - 1 < jumps.size]
    assert boundaries
    assert max(jumps[b] for b in boundaries) < 5 * np.percentile(jumps, 99)


def test_actions_act_in_the_right_direction():
    """Pitching the blades out (4 deg) lowers the aerodynamic torque, so the rotor slows (its lowest speed in
    the first 30 s) until DISCON's pitch controller takes the offset back; more generator torque needs more
    aerodynamic torque at rated speed, so the controller pitches in, thrust rises and the platform leans further
    downwind. At 14 m/s, where the steady blade pitch (7.4 deg) leaves room both ways: at 12 m/s the inclined rotor's
    steady state is at fine pitch already (0.2 deg in steady wind without waves), so more generator torque slows
    the rotor instead."""
    model = surrogates.FOWTModel().with_noise(scale=0.0)
    rpm, pitch = [], []
    for action in (np.zeros(2), np.array([np.deg2rad(4.0), 0.0]), np.array([0.0, 4.0e5])):
        sim = surrogates.StreamingSimulator(model, load_case_steady())
        sim.reset(0)
        _, truth = sim.advance(16000, action)
        rpm.append(truth[:2400, ALL_CHANNELS.index("RotSpeed")].min())
        pitch.append(truth[-4000:, ALL_CHANNELS.index("PtfmPitch")].mean())
    assert rpm[1] < rpm[0] - 0.1
    assert pitch[2] > pitch[0] + 0.05


def load_case_steady():
    return surrogates.operating_case(14.0, 0.0, 10.0, turbulence_intensity=0.0)


def test_noise_statistics_and_determinism():
    model = surrogates.FOWTModel()
    a = surrogates.StreamingSimulator(model, 7)
    b = surrogates.StreamingSimulator(model, 7)
    a.reset(5)
    b.reset(5)
    na, ta = a.advance(8000, np.zeros(2))
    nb, tb = b.advance(8000, np.zeros(2))
    assert na.tobytes() == nb.tobytes()
    i = ALL_CHANNELS.index("TwHt3MLyt")
    expect = np.hypot(model.noise.moment_white, model.noise.moment_coloured)
    assert np.std(na[:, i] - ta[:, i]) == pytest.approx(expect, rel=0.2)


def test_bad_stream_arguments():
    with pytest.raises(ValueError, match="overlap"):
        surrogates.StreamingSimulator(surrogates.FOWTModel(), 7, chunk_seconds=10.0, overlap_seconds=20.0)
    with pytest.raises(ValueError, match="chunk_seconds"):
        surrogates.StreamingSimulator(surrogates.FOWTModel(), 7, chunk_seconds=float("nan"))
