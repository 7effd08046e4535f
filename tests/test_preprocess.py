"""Band-pass + z-score preprocessing: frequency response, statistics, causal streaming == causal batch, errors."""

import doctest
import importlib

import numpy as np
import pytest
from scipy import signal

from estimators.preprocess import Preprocessor, band_sos, preprocess
from estimators.validation import NotFittedError

# the package exports the function `preprocess`, which shadows the submodule's attribute name
pp = importlib.import_module("estimators.preprocess")

FS = 80.0


def sines(freqs_amps, n=16000, fs=FS, phase=0.3):
    t = np.arange(n) / fs
    return sum(a * np.sin(2 * np.pi * f * t + phase) for f, a in freqs_amps)


def test_magnitude_response_passes_the_band_and_stops_outside():
    sos = band_sos(FS, (0.25, 5.0), 4)
    f, h = signal.sosfreqz(sos, worN=[0.05, np.sqrt(0.25 * 5.0), 15.0], fs=FS)
    gain = np.abs(h)
    assert gain[1] == pytest.approx(1.0, abs=1e-3)  # band centre (geometric)
    # 4th order: at least (f / f_edge)^4 below the pass band one way; zero-phase applies it twice (-110/-80 dB)
    assert gain[0] < (0.05 / 0.25) ** 4 and gain[2] < (5.0 / 15.0) ** 4
    assert gain[0] ** 2 < 4e-6 and gain[2] ** 2 < 1e-4
    # Butterworth: -3 dB at both edges
    _, h_edges = signal.sosfreqz(sos, worN=[0.25, 5.0], fs=FS)
    np.testing.assert_allclose(np.abs(h_edges), 1 / np.sqrt(2), rtol=1e-6)


def test_preprocess_keeps_the_in_band_sine_and_removes_the_out_of_band_ones():
    inside = sines([(1.2, 1.0)])
    y = inside + sines([(0.05, 30.0), (15.0, 5.0)]) + 7.0
    Z = preprocess(np.c_[y, 2 * y], FS)
    ref = inside / inside.std()
    core = slice(2000, -2000)  # away from the record ends
    np.testing.assert_allclose(Z[core, 0], ref[core], atol=2e-2)
    np.testing.assert_allclose(Z[:, 0], Z[:, 1], atol=1e-9)


def test_zscore_statistics_and_batch_class_equal_the_function():
    rng = np.random.default_rng(0)
    Y = rng.standard_normal((5000, 4)) * [1.0, 1e3, 1e-3, 5.0] + [0.0, 1e4, -2.0, 3.0]
    Z = preprocess(Y, FS)
    np.testing.assert_allclose(Z.mean(axis=0), 0.0, atol=1e-12)
    np.testing.assert_allclose(Z.std(axis=0), 1.0, rtol=1e-12)
    pre = Preprocessor(FS).fit(Y)
    np.testing.assert_allclose(pre.transform(Y), Z, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(pre.fit_transform(Y), Z, rtol=1e-12, atol=1e-12)
    filtered = signal.sosfiltfilt(band_sos(FS), Y, axis=0)
    np.testing.assert_allclose(pre.inverse_scale(Z), filtered, rtol=1e-9, atol=1e-9 * np.abs(filtered).max())
    np.testing.assert_allclose(pre.mean_, filtered.mean(axis=0), atol=1e-9 * np.abs(filtered).max())


def test_streaming_equals_causal_batch_and_starts_without_a_transient():
    rng = np.random.default_rng(1)
    Y = rng.standard_normal((3000, 3)) * [1.0, 20.0, 0.1] + [5e4, -3.0, 0.0]  # a large offset on channel 0
    pre = Preprocessor(FS, zero_phase=False).fit(Y)
    batch = pre.transform(Y)
    pre.reset()
    stream = np.array([pre.step(y) for y in Y])
    np.testing.assert_allclose(stream, batch, rtol=1e-10, atol=1e-10)
    # the filter state starts at the steady state of the first sample: no step response from the 5e4 offset
    assert np.abs(batch[:200, 0]).max() < 10.0
    # the causal filter really is causal: changing the future leaves the past unchanged
    Y2 = Y.copy()
    Y2[2000:] += 100.0
    np.testing.assert_array_equal(pre.transform(Y2)[:2000], batch[:2000])
    # a new stream restarts cleanly
    pre.reset()
    np.testing.assert_allclose(np.array([pre.step(y) for y in Y[:50]]), batch[:50], rtol=1e-10, atol=1e-10)


def test_streaming_holds_a_dropped_channel_and_leaves_the_others_alone():
    rng = np.random.default_rng(2)
    Y = rng.standard_normal((800, 3))
    pre = Preprocessor(FS, zero_phase=False).fit(Y)
    ref = pre.transform(Y)
    pre.reset()
    out = []
    for k, y in enumerate(Y):
        y = y.copy()
        if 300 <= k < 320:
            y[1] = np.nan
        out.append(pre.step(y))
    out = np.array(out)
    assert np.isnan(out[300:320, 1]).all() and np.isfinite(out[320:, 1]).all()
    np.testing.assert_allclose(out[:, [0, 2]], ref[:, [0, 2]], rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(out[:300, 1], ref[:300, 1], rtol=1e-10, atol=1e-10)


def test_list_of_records_and_one_sided_bands():
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal((2000, 2)), 3 * rng.standard_normal((1500, 2))
    pre = Preprocessor(FS).fit([a, b])
    Za, Zb = pre.transform([a, b])
    Z = np.vstack([Za, Zb])
    np.testing.assert_allclose(Z.mean(axis=0), 0.0, atol=1e-12)
    np.testing.assert_allclose(Z.std(axis=0), 1.0, rtol=1e-12)
    low = band_sos(FS, (None, 5.0))
    high = band_sos(FS, (0.25, None))
    assert abs(signal.sosfreqz(low, worN=[0.0], fs=FS)[1][0]) == pytest.approx(1.0)
    assert abs(signal.sosfreqz(high, worN=[30.0], fs=FS)[1][0]) == pytest.approx(1.0, abs=1e-6)


def test_bad_input_gets_clear_errors():
    rng = np.random.default_rng(4)
    Y = rng.standard_normal((1000, 3))
    with pytest.raises(ValueError, match="band\\[1\\] = 45.0 Hz must be below the Nyquist frequency fs/2 = 40.0"):
        preprocess(Y, FS, band=(0.25, 45.0))
    with pytest.raises(ValueError, match="low < high"):
        preprocess(Y, FS, band=(5.0, 1.0))
    with pytest.raises(ValueError, match="band\\[0\\]"):
        preprocess(Y, FS, band=(-1.0, 5.0))
    with pytest.raises(ValueError, match="fs must be > 0"):
        preprocess(Y, 0.0)
    const = Y.copy()
    const[:, 2] = 4.2
    with pytest.raises(ValueError, match=r"constant channel\(s\) \[2\]"):
        preprocess(const, FS)
    with pytest.raises(ValueError, match=r"constant channel\(s\) \[2\]"):
        Preprocessor(FS).fit(const)
    bad = Y.copy()
    bad[[10, 11], 1] = np.nan
    with pytest.raises(ValueError, match=r"channel 1: NaN at samples \[10, 11\]"):
        preprocess(bad, FS)
    with pytest.raises(ValueError, match="samples; the zero-phase filter needs more than"):
        preprocess(Y[:20], FS)
    with pytest.raises(ValueError, match="2-D"):
        preprocess(Y[:, 0], FS)
    with pytest.raises(NotFittedError):
        Preprocessor(FS).transform(Y)
    pre = Preprocessor(FS, zero_phase=False).fit(Y)
    with pytest.raises(ValueError, match="3 channels"):
        pre.transform(Y[:, :2])
    with pytest.raises(ValueError, match="shape \\(3,\\)"):
        pre.step(np.zeros(2))
    with pytest.raises(ValueError, match="order"):
        band_sos(FS, order=0)


def test_docstring_examples_run():
    result = doctest.testmod(pp)
    assert result.failed == 0 and result.attempted > 0
