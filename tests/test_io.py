"""fowt_env.io: OpenFAST .out/.outb, CSV/Parquet field data and .npz records in and out, and the CLI on them."""

import doctest
import json
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest

import fowt_env.io as fio
import surrogates
from fowt_env.cli import main
from fowt_env.io import (
    MissingDependencyError,
    RecordFileError,
    load_channel_map,
    load_record,
    read_openfast,
    read_table,
    rename_channels,
    save_record,
    write_openfast,
    write_table,
)
from surrogates.record import Record

FEW = "TwHt1ALxt,TwHt5ALxt,TwHt9ALxt,TwHt1MLyt,TwHt5MLyt,TwHt9MLyt"


@pytest.fixture(scope="module")
def sim():
    """120 s of OLC 4 at 80 Hz, all 45 channels (moments of ~8e4 kN-m, accelerations of ~1 m/s^2)."""
    return surrogates.simulate(surrogates.FOWTModel(), 4, duration=120.0, seed=5)


def _one_line(exc_or_text) -> str:
    text = str(exc_or_text)
    assert "\n" not in text and "Traceback" not in text
    return text


def _col_scaling(raw: bytes, n_chan: int, file_id: int) -> tuple[np.ndarray, np.ndarray]:
    """ColScl, ColOff of an OpenFAST int16 binary file, read straight from the header bytes."""
    at = 2 + (2 if file_id == 4 else 0) + 4 + 4 + 8 + 8
    scl = np.frombuffer(raw, "<f4", n_chan, at).astype(float)
    off = np.frombuffer(raw, "<f4", n_chan, at + 4 * n_chan).astype(float)
    return scl, off


# ------------------------------------------------------------------------------------------------ OpenFAST text
def test_text_out_round_trip_in_openfast_layout(sim, tmp_path):
    path = write_openfast(sim, tmp_path / "run.out", description="OLC 4 seed 5")
    lines = path.read_text().splitlines()
    assert lines[0] == "" and lines[1].startswith("Predictions were generated on ") and lines[3] == ""
    assert lines[4] == "Description from fowt-env: OLC 4 seed 5" and lines[5] == ""
    assert lines[6].split("\t") == ["Time", *sim.channels]
    assert lines[7].split("\t") == ["(s)", *[f"({u})" for u in sim.units]]
    assert lines[8].split("\t")[0] == "    0.0000"

    back = read_openfast(path)
    assert back.channels == sim.channels and back.units == sim.units
    assert back.meta["format"] == "openfast-text" and "OLC 4 seed 5" in back.meta["description"]
    np.testing.assert_allclose(back.t, sim.t, rtol=0, atol=1e-9)
    # %.6E keeps 7 significant digits: each value within half a unit of its 7th digit
    assert np.all(np.abs(back.y - sim.y) <= 0.5e-6 * np.abs(sim.y) * (1 + 1e-9) + 1e-300)

    coarse = read_openfast(write_openfast(sim.select(["TwHt9ALxt", "TwHt1MLyt"]), tmp_path / "c.out", precision=3))
    ref = sim.select(["TwHt9ALxt", "TwHt1MLyt"]).y
    assert np.all(np.abs(coarse.y - ref) <= 0.5e-3 * np.abs(ref) * (1 + 1e-9) + 1e-300)


def test_text_out_agrees_with_openfast_io(sim, tmp_path):
    reader = pytest.importorskip("openfast_io.FAST_output_reader")
    path = write_openfast(sim.slice_time(0.0, 20.0), tmp_path / "run.out")
    data, info = reader.load_ascii_output(str(path))
    ours = read_openfast(path)
    assert info["attribute_names"] == ["Time", *ours.channels]
    assert info["attribute_units"] == ["s", *ours.units]
    np.testing.assert_array_equal(data[:, 1:], ours.y)
    np.testing.assert_allclose(data[:, 0], ours.t, rtol=0, atol=1e-12)


def _openfast_like_text(t, y, names, units, time_fmt="%10.4f", fmt="%10.3E"):
    """Text in OpenFAST's FAST_InitOutput layout (tab delimiter, ES10.3E2 values), written independently."""
    head = ["", "Predictions were generated on 01-Jan-2025 at 00:00:00 using OpenFAST, compiled as a 64-bit "
                "application using double precision at commit v3.5.3",
            " linked with  NWTC Subroutine Library; ElastoDyn; InflowWind; AeroDyn; ServoDyn; HydroDyn; MoorDyn",
            "", "Description from the FAST input file: OC3 Hywind", "",
            "\t".join(["Time", *names]), "\t".join(f"({u})" for u in ["s", *units])]
    rows = ["\t".join([time_fmt % ti] + [fmt % v for v in row]) for ti, row in zip(t, y, strict=True)]
    return "\n".join(head + rows) + "\n"


def test_reads_openfast_text_with_rounded_time_and_fortran_fields(tmp_path):
    n, dt = 4000, 0.00625  # F10.4 prints these times rounded to 0.1 ms: not uniform as printed
    t = np.arange(n) * dt
    rng = np.random.default_rng(1)
    y = np.column_stack([rng.normal(size=n), 5e4 + 100 * rng.normal(size=n)])
    text = _openfast_like_text(t, y, ["TwHt9ALxt", "TwHt1MLyt"], ["m/s^2", "kN-m"])
    printed = np.array([float(line.split("\t")[0]) for line in text.splitlines()[8:]])
    assert np.ptp(np.diff(printed)) > 5e-5
    path = tmp_path / "ofst.out"
    path.write_text(text)
    rec = read_openfast(path)
    assert rec.channels == ["TwHt9ALxt", "TwHt1MLyt"] and rec.units == ["m/s^2", "kN-m"]
    assert rec.meta["description"].startswith("Predictions were generated") and "OC3 Hywind" in rec.meta[
        "description"]
    np.testing.assert_allclose(rec.t, t, rtol=0, atol=1e-12)
    assert np.all(np.abs(rec.y - y) <= 0.5e-3 * np.abs(y) * (1 + 1e-9))

    # Fortran writes 1.234-100 for a 3-digit exponent and asterisks on overflow
    lines = text.splitlines()
    lines[10] = lines[10].split("\t")[0] + "\t 1.234-100\t**********"
    path.write_text("\n".join(lines) + "\n")
    rec = read_openfast(path)
    assert rec.y[2, 0] == pytest.approx(1.234e-100) and np.isnan(rec.y[2, 1])
    assert rec.meta["overflow_values"] == 1


@pytest.mark.parametrize(("edit", "message"), [
    (lambda rows: rows[:5] + rows[6:], "gap at sample 5"),                    # a missing sample
    (lambda rows: rows[:5] + [rows[6], rows[5]] + rows[7:], "not increasing"),  # two swapped samples
])
def test_non_uniform_or_decreasing_time_is_a_clear_error(tmp_path, edit, message):
    t = np.arange(50) * 0.05
    text = _openfast_like_text(t, np.ones((50, 1)), ["PtfmPitch"], ["deg"])
    lines = text.splitlines()
    path = tmp_path / "bad.out"
    path.write_text("\n".join(lines[:8] + edit(lines[8:])) + "\n")
    with pytest.raises(RecordFileError, match=message) as err:
        read_openfast(path)
    assert str(path) in _one_line(err.value)


# ------------------------------------------------------------------------------------------------ OpenFAST binary
@pytest.mark.parametrize("file_id", [1, 2, 3, 4])
def test_binary_outb_round_trip_within_the_documented_quantisation(sim, tmp_path, file_id):
    path = write_openfast(sim, tmp_path / "run.outb", file_format_id=file_id)
    back = read_openfast(path)
    assert back.channels == sim.channels and back.units == sim.units
    assert back.meta["format"] == "openfast-binary" and back.meta["file_format_id"] == file_id
    np.testing.assert_allclose(back.t, sim.t, rtol=0, atol=1e-9)
    if file_id == 3:
        np.testing.assert_array_equal(back.y, sim.y)  # float64: lossless
        return
    scl, _ = _col_scaling(path.read_bytes(), sim.n_channels, file_id)
    err = np.abs(back.y - sim.y).max(axis=0)
    assert np.all(err <= 0.5 / scl * (1 + 1e-9))  # half a quantisation step, and no clipping
    assert np.all(scl >= 0.999 * 65535 / np.ptp(sim.y, axis=0))  # the whole int16 range is used


@pytest.mark.parametrize("file_id", [1, 2, 3, 4])
def test_binary_outb_agrees_with_openfast_io(sim, tmp_path, file_id):
    reader = pytest.importorskip("openfast_io.FAST_output_reader")
    small = sim.slice_time(0.0, 10.0)
    path = write_openfast(small, tmp_path / "run.outb", file_format_id=file_id)
    data, info, _ = reader.load_binary_output(str(path))
    ours = read_openfast(path)
    assert info["attribute_names"] == ["Time", *ours.channels]
    assert info["attribute_units"] == ["s", *ours.units]
    np.testing.assert_array_equal(data[:, 1:], ours.y)
    step = small.duration / (2**32 - 1) if file_id == 1 else 1e-12  # format 1: int32-packed time, raw in theirs
    np.testing.assert_allclose(data[:, 0], ours.t, rtol=0, atol=step)


def _nint(x):
    return np.sign(x) * np.floor(np.abs(x) + 0.5)  # Fortran NINT: halves away from zero


def _wrbinfast(file_id, names, units, t, y, order="<", desc="Predictions were generated by OpenFAST"):
    """Bytes laid out as OpenFAST's NWTC_IO WrBinFAST writes them (single-precision ReKi build), independently.

    OpenFAST maps each channel's minimum to -32768 with float32 arithmetic, and packs time (FileFmtID 1) into
    -65536..65535 only.
    """
    n_t, n_c = y.shape
    names, units = ["Time", *names], [f"({u})" for u in ["s", *units]]
    yf = y.astype(np.float32)
    lo, hi = yf.min(axis=0), yf.max(axis=0)
    rng = np.where(hi == lo, np.sqrt(np.finfo(np.float32).eps), hi - lo).astype(np.float32)
    scl = (np.float32(65535.0) / rng).astype(np.float32)
    off = (np.float32(-32768.0) - scl * lo).astype(np.float32)
    packed = _nint(np.clip((scl * yf + off).astype(np.float32), -32768, 32767)).astype(np.int16)
    len_name = max(len(s) for s in names + units) if file_id == 4 else 10
    out = [struct.pack(order + "h", file_id)]
    if file_id == 4:
        out.append(struct.pack(order + "h", len_name))
    out.append(struct.pack(order + "ii", n_c, n_t))
    if file_id == 1:
        time_scl = 131071.0 / (t[-1] - t[0])
        time_off = -65536.0 - time_scl * t[0]
        out.append(struct.pack(order + "dd", time_scl, time_off))
    else:
        out.append(struct.pack(order + "dd", t[0], t[1] - t[0]))
    out.append(scl.astype(order + "f4").tobytes() + off.astype(order + "f4").tobytes())
    out.append(struct.pack(order + "i", len(desc)) + desc.encode())
    out.append("".join(s.ljust(len_name) for s in names).encode())
    out.append("".join(s.ljust(len_name) for s in units).encode())
    if file_id == 1:
        out.append(_nint(time_scl * t + time_off).astype(order + "i4").tobytes())
    out.append(packed.astype(order + "i2").tobytes())
    return b"".join(out), scl, off


@pytest.mark.parametrize(("file_id", "order"), [(1, "<"), (2, "<"), (4, "<"), (4, ">")])
def test_reads_binary_files_laid_out_like_openfast(tmp_path, file_id, order):
    n, dt = 2000, 0.0125
    t = np.arange(n) * dt
    rng = np.random.default_rng(2)
    y = np.column_stack([rng.normal(size=n), 300 * np.sin(t), np.full(n, 2.5)])
    names, units = ["NcIMUTAxs", "TwHt1MLyt", "RotSpeed"], ["m/s^2", "kN-m", "rpm"]
    raw, scl, off = _wrbinfast(file_id, names, units, t, y, order)
    path = tmp_path / "openfast.outb"
    path.write_bytes(raw)
    rec = read_openfast(path)
    assert rec.channels == names and rec.units == units
    assert rec.meta["description"] == "Predictions were generated by OpenFAST"
    np.testing.assert_allclose(rec.t, t, rtol=0, atol=1e-9)  # FileFmtID 1: time recovered from 17-bit packing
    assert rec.dt == pytest.approx(dt, abs=1e-12)
    # OpenFAST's quantisation: half a step, plus its float32 arithmetic (ColScl*y + ColOff rounded to float32)
    assert np.all(np.abs(rec.y - y).max(axis=0) <= (0.5 + 2.0**-23 * (np.abs(off) + 32768.0)) / scl)


def test_corrupt_or_truncated_binary_is_a_one_line_error(sim, tmp_path):
    raw = write_openfast(sim.slice_time(0.0, 2.0), tmp_path / "ok.outb").read_bytes()
    for name, content, message in [("cut.outb", raw[:-7], "truncated"), ("long.outb", raw + b"\0\0", "trailing"),
                                   ("head.outb", raw[:5], "truncated")]:
        path = tmp_path / name
        path.write_bytes(content)
        with pytest.raises(RecordFileError, match=message) as err:
            read_openfast(path)
        assert _one_line(err.value).startswith(str(path))


def test_write_openfast_refuses_what_the_format_cannot_hold(sim, tmp_path):
    rec = sim.select(["TwHt9ALxt", "TwHt1MLyt"])
    y = rec.y.copy()
    y[10, 0] = np.nan
    holey = rec.replace(y=y)
    with pytest.raises(ValueError, match="NaN"):
        write_openfast(holey, tmp_path / "x.outb")
    for path, kwargs in [(tmp_path / "x3.outb", {"file_format_id": 3}), (tmp_path / "x.out", {})]:
        back = read_openfast(write_openfast(holey, path, **kwargs))  # lossless float64 and text keep NaN
        assert np.isnan(back.y[10, 0]) and np.isfinite(back.y[11, 0])
    long = rec.replace(channels=["AVeryLongChannel", "TwHt1MLyt"])
    with pytest.raises(ValueError, match="file_format_id=4"):
        write_openfast(long, tmp_path / "x.outb", file_format_id=2)
    assert read_openfast(write_openfast(long, tmp_path / "x4.outb")).channels[0] == "AVeryLongChannel"
    with pytest.raises(ValueError, match="whitespace"):
        write_openfast(rec.replace(channels=["acc top", "b"]), tmp_path / "y.out")
    uneven = Record(np.array([0.0, 0.1, 0.3]), np.ones((3, 1)), ["PtfmPitch"], ["deg"])
    with pytest.raises(ValueError, match="file_format_id=1"):
        write_openfast(uneven, tmp_path / "u.outb")
    path = write_openfast(uneven, tmp_path / "u1.outb", file_format_id=1)  # format 1 stores any time stamps,
    with pytest.raises(RecordFileError, match=r"not uniform: sample 1 at 0\.1 s"):
        read_openfast(path)  # but records are uniform: the reader refuses, naming the sample


# ------------------------------------------------------------------------------------------------ tables
FIELD_CSV = """# logger export, site A
Time [s],acc_top_x [m/s^2],mom_base,temperature [degC],status
0.00,0.10,51000.5,11.5,ok
0.05,,51010.0,11.5,ok
0.10,-0.20,NA,11.6,gust
0.15,0.05,50990.25,11.6,ok
"""


def test_csv_field_data_with_a_channel_map(tmp_path):
    path = tmp_path / "field.csv"
    path.write_text(FIELD_CSV)
    cmap = {"acc_top_x": "TwHt9ALxt", "mom_base": "TwHt1MLyt"}
    rec = read_table(path, channel_map=cmap, unknown_channels="drop")
    assert rec.channels == ["TwHt9ALxt", "TwHt1MLyt"]
    assert rec.units == ["m/s^2", "kN-m"]  # from the header, then fowt-env's own table
    assert rec.dt == pytest.approx(0.05) and rec.t[-1] == pytest.approx(0.15)
    np.testing.assert_array_equal(rec["TwHt9ALxt"], [0.10, np.nan, -0.20, 0.05])  # empty cell -> NaN
    np.testing.assert_array_equal(rec["TwHt1MLyt"], [51000.5, 51010.0, np.nan, 50990.25])  # NA -> NaN
    assert rec.meta["channel_map"] == cmap and rec.meta["format"] == "csv"

    with pytest.raises(RecordFileError, match="status") as err:  # kept unknown column that is not numeric
        read_table(path, channel_map=cmap, unknown_channels="keep")
    assert "row 1" in _one_line(err.value)
    with pytest.raises(RecordFileError, match="temperature"):
        read_table(path, channel_map=cmap, unknown_channels="error")
    numeric = tmp_path / "numeric.csv"
    numeric.write_text("\n".join(line.rsplit(",", 1)[0] for line in FIELD_CSV.splitlines()) + "\n")
    with pytest.warns(UserWarning, match="temperature"):
        rec = read_table(numeric, channel_map=cmap)
    assert rec.channels[-1] == "temperature" and rec.units[-1] == "degC"
    assert rec.meta["unknown_channels"] == ["temperature"]
    with pytest.raises(RecordFileError, match=r"'acc_top_y' \(did you mean 'acc_top_x'\?\)") as err:
        read_table(numeric, channel_map={"acc_top_y": "TwHt9ALyt"}, unknown_channels="keep")
    assert _one_line(err.value).startswith(str(numeric))


def test_csv_time_from_dt_or_iso_timestamps(tmp_path):
    path = tmp_path / "no_time.csv"
    path.write_text("TwHt9ALxt,TwHt9ALyt\n1,2\n3,4\n5,6\n")
    rec = read_table(path, dt=0.0125)
    np.testing.assert_allclose(rec.t, [0.0, 0.0125, 0.025])
    with pytest.raises(RecordFileError, match="no time column 'Time'"):
        read_table(path)
    with pytest.raises(RecordFileError, match="needs dt"):
        read_table(path, time_column=None)
    stamps = tmp_path / "stamps.csv"
    stamps.write_text("timestamp;TwHt9ALxt\n2024-05-01T12:00:00.000Z;1\n2024-05-01T12:00:00.500Z;2\n"
                      "2024-05-01T12:00:01.000Z;3\n")
    rec = read_table(stamps, time_column="timestamp")
    assert rec.dt == 0.5 and rec.meta["start_time"].startswith("2024-05-01T12:00:00")
    with pytest.raises(RecordFileError, match="disagrees"):
        read_table(stamps, time_column="timestamp", dt=0.25)


def test_csv_round_trip_is_bit_identical(sim, tmp_path):
    rec = sim.slice_time(0.0, 5.0)
    path = save_record(rec, tmp_path / "run.csv")
    assert path.read_text().splitlines()[0].startswith("Time [s],TwHt1ALxt [m/s^2],")
    back = load_record(path)
    assert back.channels == rec.channels and back.units == rec.units
    np.testing.assert_array_equal(back.y, rec.y)
    np.testing.assert_allclose(back.t, rec.t, rtol=0, atol=1e-12)


def test_parquet_round_trip_and_field_data(sim, tmp_path):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    rec = sim.slice_time(0.0, 5.0)
    assert load_record(save_record(rec, tmp_path / "run.parquet")) == rec  # arrays, units and meta
    field = pa.table({
        "time": pa.array(np.arange(4) * 0.1),
        "acc_top_x": pa.array([0.1, None, 0.3, 0.4]),
        "strain_count": pa.array([1, 2, None, 4], type=pa.int32()),
    })
    pq.write_table(field, tmp_path / "field.parquet")
    got = load_record(tmp_path / "field.parquet", channel_map={"acc_top_x": "TwHt9ALxt"}, time_column="time",
                      unknown_channels="keep", units={"strain_count": "-"})
    assert got.channels == ["TwHt9ALxt", "strain_count"] and got.units == ["m/s^2", "-"]
    np.testing.assert_array_equal(got.y, [[0.1, 1], [np.nan, 2], [0.3, np.nan], [0.4, 4]])
    assert got.meta["unknown_channels"] == ["strain_count"]


def test_parquet_without_pyarrow_says_what_to_install(tmp_path, monkeypatch, sim):
    path = tmp_path / "x.parquet"
    path.write_bytes(b"PAR1")
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'fowt-env\[io\]'") as err:
        load_record(path)
    assert isinstance(err.value, ImportError) and isinstance(err.value, ValueError)
    with pytest.raises(MissingDependencyError):
        save_record(sim.slice_time(0.0, 1.0), tmp_path / "y.parquet")


# ------------------------------------------------------------------------------------------------ dispatch, errors
def test_npz_and_channel_maps_through_load_record(sim, tmp_path):
    rec = sim.slice_time(0.0, 2.0).select(["TwHt9ALxt", "PtfmPitch"])
    assert load_record(save_record(rec, tmp_path / "rec.NPZ")) == rec
    out = save_record(rec, tmp_path / "rec.out")
    renamed = load_record(out, channel_map={"TwHt9ALxt": "accel_top"})
    assert renamed.channels == ["accel_top", "PtfmPitch"] and renamed.units == ["m/s^2", "deg"]
    assert rename_channels(renamed, {"accel_top": "TwHt9ALxt"}).channels == rec.channels
    with pytest.raises(RecordFileError, match="'TwHt9ALyt'"):
        load_record(out, channel_map={"TwHt9ALyt": "x"})
    cmap = tmp_path / "map.json"
    cmap.write_text(json.dumps({"a": "TwHt9ALxt"}))
    assert load_channel_map(cmap) == {"a": "TwHt9ALxt"}
    cmap.write_text("[1, 2]")
    with pytest.raises(RecordFileError, match="not a channel map"):
        load_channel_map(cmap)


def test_bad_files_give_one_line_errors_naming_the_file(tmp_path):
    cases = {
        "missing.out": (None, "no such file"),
        "notes.txt": (b"hello", "unknown file extension '.txt'"),
        "corrupt.npz": (b"PK\x03\x04garbage", "not a Record file"),
        "random.outb": (b"\xff\xfe" + bytes(range(256)) * 4, "not an OpenFAST output file"),
        "header.outb": (bytes(range(256)) * 4, "not a valid OpenFAST binary file"),
        "words.out": (b"just some words\nand more words\n", "no line of channel names"),
        "empty.csv": (b"", "empty"),
        "latin.csv": (b"Time,x\n0,\xff\n", "not UTF-8"),
        "short.csv": (b"Time,TwHt9ALxt\n0,1\n", "at least 2"),
    }
    for name, (content, message) in cases.items():
        path = tmp_path / name
        if content is not None:
            path.write_bytes(content)
        with pytest.raises(RecordFileError, match=message) as err:
            load_record(path)
        assert _one_line(err.value).startswith(str(path))
    (tmp_path / "folder.npz").mkdir()
    with pytest.raises(RecordFileError, match="directory"):
        load_record(tmp_path / "folder.npz")
    with pytest.raises(RecordFileError, match="unknown file extension"):
        save_record(Record([0.0, 1.0], [[1.0], [2.0]], ["PtfmPitch"], ["deg"]), tmp_path / "x.mat")


def test_module_examples_run():
    assert doctest.testmod(fio, optionflags=doctest.ELLIPSIS).failed == 0


# ------------------------------------------------------------------------------------------------ CLI
def test_cli_identify_on_openfast_and_field_files(sim, tmp_path, capsys):
    write_openfast(sim, tmp_path / "run.out")
    write_openfast(sim, tmp_path / "run.outb")
    for name, options in (("run.out", []), ("run.outb", ["--no-ssi"])):
        out = tmp_path / f"{name}.json"
        assert main(["identify", str(tmp_path / name), "--channels", FEW, "--json", str(out), *options]) == 0
        modes = json.loads(out.read_text())
        assert modes["channels"] == FEW.split(",") and modes["dmd"]["modes"]
    # field data: CSV with its own column names, mapped by --channel-map
    field = sim.select(FEW.split(",")).replace(channels=[f"gauge_{i}" for i in range(6)])
    write_table(field, tmp_path / "field.csv")
    cmap = tmp_path / "map.json"
    cmap.write_text(json.dumps({f"gauge_{i}": name for i, name in enumerate(FEW.split(","))}))
    assert main(["identify", str(tmp_path / "field.csv"), "--channel-map", str(cmap), "--channels", FEW,
                 "--no-ssi", "--json", str(tmp_path / "field.json")]) == 0
    assert json.loads((tmp_path / "field.json").read_text())["channels"] == FEW.split(",")
    capsys.readouterr()


def test_cli_errors_are_one_line_and_non_zero(sim, tmp_path, capsys):
    corrupt = tmp_path / "corrupt.outb"
    corrupt.write_bytes(b"\x04\x00\x0a\x00" + b"\x01" * 30)
    odd = tmp_path / "run.xyz"
    odd.write_text("x")
    for argv, message in [(["identify", str(tmp_path / "missing.out")], "no such file"),
                          (["identify", str(odd)], "unknown file extension"),
                          (["identify", str(corrupt)], "truncated"),
                          (["discrepancy", str(corrupt), "--case", "7"], "truncated"),
                          (["identify", str(corrupt), "--channel-map", str(tmp_path / "nomap.json")],
                           "no such file")]:
        with pytest.raises(SystemExit) as exit_:
            main(argv)
        text = _one_line(exit_.value.code)
        assert text.startswith("fowt-env: ") and message in text
    run = write_openfast(sim.slice_time(0.0, 10.0), tmp_path / "run.out")
    capsys.readouterr()
    assert main(["identify", str(run), "--channels", "TwHt9ALxt,TwHt10ALxt"]) == 2  # unknown channel
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "TwHt10ALxt" in err and "Traceback" not in err


def test_cli_process_prints_no_traceback(tmp_path):
    corrupt = tmp_path / "corrupt.out"
    corrupt.write_bytes(b"Time\tTwHt9ALxt\n(s)\t(m/s^2)\n0.0\t1.0\n0.1\tabc\n")
    with warnings.catch_warnings():
        proc = subprocess.run([sys.executable, "-m", "fowt_env.cli", "identify", str(corrupt)],
                              capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "'abc' is not a number" in proc.stderr
