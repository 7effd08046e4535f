"""Hardening of fowt_env.io (issue 18): the time axis is inferred from the data, gaps/jitter/steps back are
refused naming the row, special files are refused before anything is read, every error is one line."""

import os
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import fowt_env.io as fio
from fowt_env.io import RecordFileError, load_record, read_table, save_record
from surrogates.record import Record

LOSSLESS = (".npz", ".csv", ".parquet")
ALL_FORMATS = (".npz", ".csv", ".parquet", ".out", ".outb")


def _record(dt: float, n: int, t0: float = 0.0, seed: int = 0) -> Record:
    y = np.random.default_rng(seed).normal(size=(n, 2)) * [1.0, 5e4]
    return Record(t0 + dt * np.arange(n), y, ["TwHt9ALxt", "TwHt1MLyt"], ["m/s^2", "kN-m"])


def _one_line(exc) -> str:
    text = str(exc)
    assert "\n" not in text and "Traceback" not in text
    return text


# ------------------------------------------------------------------------------------- time-axis round trip
@settings(max_examples=80, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.one_of(st.integers(1, 1000), st.floats(1.0, 1000.0)), n=st.integers(2, 300),
       ext=st.sampled_from(ALL_FORMATS), t0=st.one_of(st.sampled_from([0.0, 0.5, 1234.0]), st.floats(-100, 5000)))
# found by a random draw (5e-12 s off at atol 4.9e-12): the .out writer printed stamps to 8 ulps, the reader took
# them as exact; and a step snapped to 11 decimals within the 8-ulp screening margin of two stamps
@example(rate=792.0, n=3, ext=".out", t0=2816.0)
@example(rate=656, n=2, ext=".outb", t0=1234.0)
def test_time_axis_round_trip_over_rate_and_length(tmp_path, rate, n, ext, t0):
    """save_record -> load_record gives back dt = 1/rate and every time stamp and sample, for every format."""
    dt = 1.0 / rate
    rec = _record(dt, n, t0)
    back = load_record(save_record(rec, tmp_path / f"r{ext}"))
    ulp = 8 * np.spacing(abs(t0) + n * dt)  # float64 cannot place stamps (so their median step) finer than this
    assert abs(back.dt - dt) <= 1e-9 * dt + ulp  # truth: the rate the record was made at
    np.testing.assert_allclose(back.t, t0 + dt * np.arange(n), rtol=0, atol=1e-9 * dt + ulp)
    if ext in LOSSLESS:
        np.testing.assert_array_equal(back.t, rec.t)
        np.testing.assert_array_equal(back.y, rec.y)
    elif ext == ".out":  # precision 6: half a unit of the 7th significant digit
        assert np.all(np.abs(back.y - rec.y) <= 0.5e-6 * np.abs(rec.y) * (1 + 1e-9))
    else:  # int16: half a quantisation step of the range
        assert np.all(np.abs(back.y - rec.y) <= np.ptp(rec.y, axis=0) / 65535 * (1 + 1e-6))


@pytest.mark.parametrize("dt", [0.0125, 0.00625, 0.05, 0.1, 0.001, 1.0, 1 / 60, 1 / 80, 1 / 3])
@pytest.mark.parametrize("n", [2, 3, 160, 300])
def test_time_axis_round_trip_csv_grid(tmp_path, dt, n):
    """The reproducer: 160 samples at 0.0125 s written by save_record(.csv) came back at dt = 0.013."""
    rec = _record(dt, n)
    back = load_record(save_record(rec, tmp_path / "r.csv"))
    np.testing.assert_array_equal(back.t, rec.t)
    assert back.dt == rec.dt


@pytest.mark.parametrize("decimals", [3, 4, 6])
@pytest.mark.parametrize("first", ["0", "0.0", None])
def test_time_axis_of_a_logger_file_starting_at_zero(tmp_path, decimals, first):
    """A 60 Hz logger that prints its first stamp as ``0`` read +20 % (the step came from the printed width)."""
    n = 600
    stamps = [f"{k / 60:.{decimals}f}" for k in range(n)]
    if first is not None:
        stamps[0] = first
    rows = "".join(f"{s},{k % 7}\n" for k, s in enumerate(stamps))
    path = tmp_path / "logger.csv"
    path.write_text("Time,TwHt9ALxt\n" + rows)
    rec = read_table(path)
    assert rec.dt == pytest.approx(1 / 60, rel=0.5 * 10.0**-decimals * 60 * 2 / n + 1e-9)
    np.testing.assert_allclose(rec.t, np.arange(n) / 60, rtol=0, atol=0.5 * 10.0**-decimals + 1e-12)


def _csv(path, stamps):
    path.write_text("Time,TwHt9ALxt\n" + "".join(f"{s!r},{k}\n" for k, s in enumerate(stamps)))
    return path


@pytest.mark.parametrize("ext", [".csv", ".out"])
@pytest.mark.parametrize("gap", [1, 20])
def test_time_gap_is_refused_naming_the_row(tmp_path, ext, gap):
    t = np.arange(200) * 0.0125
    t = np.concatenate([t[:100], t[100 + gap:]])
    rec = Record(t, np.ones((t.size, 1)), ["TwHt9ALxt"], ["m/s^2"])
    path = save_record(rec, tmp_path / f"gap{ext}")  # the writers store any increasing stamps
    with pytest.raises(RecordFileError, match=rf"gap at sample 100\b.*about {gap} missing") as err:
        load_record(path)
    assert str(path) in _one_line(err.value)


def test_time_gap_in_an_npz_record_is_refused(tmp_path):
    t = np.concatenate([np.arange(50), np.arange(70, 120)]) * 0.0125
    path = Record(t, np.zeros((t.size, 1)), ["TwHt9ALxt"], ["m/s^2"]).save(tmp_path / "gap.npz")
    with pytest.raises(RecordFileError, match=r"gap at sample 50\b.*about 20 missing"):
        load_record(path)


@pytest.mark.parametrize(("edit", "message"), [
    (lambda t: t.__setitem__(37, t[37] + 0.3 * 0.0125), r"not uniform: sample 3[78]\b"),  # jitter 30 % of dt
    (lambda t: t.__setitem__(37, t[37] + 0.01 * 0.0125), r"not uniform: sample 3[78]\b"),  # 1 % of dt, beyond 0.1 %
    (lambda t: t.__setitem__(slice(37, 39), t[[38, 37]]), r"not increasing at sample 38\b"),
    (lambda t: t.__setitem__(37, t[36]), r"not increasing at sample 37\b"),
])
def test_time_jitter_or_step_back_is_refused_naming_the_row(tmp_path, edit, message):
    t = np.arange(80) * 0.0125
    edit(t)
    with pytest.raises(RecordFileError, match=message) as err:
        read_table(_csv(tmp_path / "bad.csv", t.tolist()))
    _one_line(err.value)


def test_time_jitter_within_printed_precision_is_accepted(tmp_path):
    """Stamps printed to 1 ms at 60 Hz wobble by 6 % of dt as printed; that is the print, not the clock."""
    path = tmp_path / "ms.csv"
    path.write_text("Time,TwHt9ALxt\n" + "".join(f"{k / 60:.3f},{k}\n" for k in range(300)))
    rec = read_table(path)
    assert rec.dt == pytest.approx(1 / 60, rel=1e-5)


# ------------------------------------------------------------------------------------- special files
@pytest.mark.parametrize("ext", [".out", ".outb", ".csv", ".npz", ".parquet"])
def test_special_file_symlink_to_dev_zero_is_refused_fast(tmp_path, ext):
    link = tmp_path / f"zero{ext}"
    os.symlink("/dev/zero", link)
    start = time.perf_counter()
    with pytest.raises(RecordFileError, match="character device") as err:
        load_record(link)
    assert time.perf_counter() - start < 1.0
    _one_line(err.value)


@pytest.mark.parametrize("ext", [".out", ".csv", ".npz"])
def test_special_file_fifo_is_refused_without_blocking(tmp_path, ext):
    fifo = tmp_path / f"pipe{ext}"
    os.mkfifo(fifo)
    start = time.perf_counter()
    with pytest.raises(RecordFileError, match="FIFO"):
        load_record(fifo)  # no writer: a blocking open would hang here
    assert time.perf_counter() - start < 1.0


@pytest.mark.parametrize("ext", [".out", ".outb", ".csv", ".npz", ".parquet"])
def test_special_file_larger_than_memory_is_refused_before_reading(tmp_path, monkeypatch, ext):
    monkeypatch.setattr(fio, "_available_memory", lambda: 2**30)  # 1 GiB free, whatever this machine has
    big = tmp_path / f"big{ext}"
    with open(big, "wb") as fh:
        fh.truncate(2**33)  # sparse: 8 GiB claimed, nothing on disk
    start = time.perf_counter()
    with pytest.raises(RecordFileError, match="too large to read") as err:
        load_record(big)
    assert time.perf_counter() - start < 1.0
    _one_line(err.value)


def test_special_file_broken_symlink_and_directory(tmp_path):
    link = tmp_path / "dangling.csv"
    os.symlink(tmp_path / "nowhere.csv", link)
    with pytest.raises(RecordFileError, match="broken symbolic link"):
        load_record(link)
    folder = tmp_path / "adir.npz"
    folder.mkdir()
    with pytest.raises(RecordFileError, match="is a directory"):
        load_record(folder)
