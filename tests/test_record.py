"""Record: validation, views and the .npz + JSON file format."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from surrogates.channels import ALL_CHANNELS, UNITS, tower_channels
from surrogates.load_cases import load_case
from surrogates.record import FORMAT_NAME, Record


def make_record(n=200, channels=None, seed=0, meta=None):
    channels = ALL_CHANNELS if channels is None else channels
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 80.0
    y = rng.normal(size=(n, len(channels)))
    return Record(t, y, channels, [UNITS[c] for c in channels], meta)


def bits(a):
    return np.ascontiguousarray(a).view(np.uint64)


# ---------------------------------------------------------------- construction
def test_properties():
    rec = make_record(n=801, meta={"seed": 0})
    assert rec.n_samples == len(rec) == 801
    assert rec.n_channels == len(ALL_CHANNELS)
    assert rec.dt == pytest.approx(0.0125)
    assert rec.fs == pytest.approx(80.0)
    assert rec.duration == pytest.approx(10.0)
    assert rec.y.dtype == np.float64 and rec.y.shape == (801, len(ALL_CHANNELS))
    assert rec.channels == ALL_CHANNELS
    assert rec.units[0] == "m/s^2"
    text = repr(rec)
    assert "n_samples=801" in text and f"n_channels={len(ALL_CHANNELS)}" in text and len(text) < 300


def test_units_none_looks_up_openfast_units():
    rec = Record([0.0, 1.0], np.zeros((2, 2)), ["PtfmPitch", "RotSpeed"], None)
    assert rec.units == ["deg", "rpm"]
    with pytest.raises(ValueError, match="unknown channel"):
        Record([0.0, 1.0], np.zeros((2, 1)), ["MyStrain"], None)


def test_record_is_immutable_from_outside():
    rec = make_record(n=10, meta={"a": [1, 2]})
    with pytest.raises(ValueError):
        rec.y[0, 0] = 1.0
    with pytest.raises(ValueError):
        rec.t[0] = 1.0
    rec.channels.append("x")
    rec.meta["a"].append(3)
    assert rec.n_channels == len(rec.channels) == len(ALL_CHANNELS)
    assert rec.meta == {"a": [1, 2]}


def test_nan_in_y_is_legal():
    y = np.ones((5, 2))
    y[2, 1] = np.nan
    rec = Record(np.arange(5.0), y, ["a", "b"], ["m", "m"])
    assert np.isnan(rec["b"][2])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(t=[[0.0, 1.0]]), "t must be 1-D"),
        (dict(t=[0.0]), "at least 2"),
        (dict(t=[0.0, np.nan, 2.0]), "t must be finite"),
        (dict(t=[0.0, 2.0, 1.0]), "strictly increasing"),
        (dict(t=[0.0, 0.0, 1.0]), "strictly increasing"),
        (dict(t=["a", "b", "c"]), "t must be"),
        (dict(y=np.zeros(3)), "y must be 2-D"),
        (dict(y=np.zeros((4, 2))), "one row per time stamp"),
        (dict(y=np.array([[0, np.inf]] * 3)), "inf"),
        (dict(y=np.zeros((3, 2), dtype=complex)), "real"),
        (dict(channels=["a"]), "channels has 1 names"),
        (dict(channels=["a", "a"]), "unique"),
        (dict(channels="ab"), "channels must be a sequence"),
        (dict(channels=["a", 2]), "channels must contain only strings"),
        (dict(units=["m"]), "units has 1"),
        (dict(meta=[1]), "meta must be a dict"),
        (dict(meta={1: "x"}), "keys must be strings"),
        (dict(meta={"x": object()}), "JSON-serialisable"),
        (dict(meta={"x": [1.0, float("nan")]}), "finite"),
        (dict(meta={"lc": load_case(1)}), "to_dict"),
    ],
)
def test_bad_inputs(kwargs, match):
    args = dict(t=[0.0, 1.0, 2.0], y=np.zeros((3, 2)), channels=["a", "b"], units=["m", "m"], meta=None)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        Record(**args)


def test_meta_normalised_to_plain_json():
    rec = make_record(n=4, channels=["PtfmPitch"], meta={"seed": np.int64(3), "h": np.arange(2.0), "p": (1, 2)})
    assert rec.meta == {"seed": 3, "h": [0.0, 1.0], "p": [1, 2]}
    assert type(rec.meta["seed"]) is int


# ---------------------------------------------------------------- views
def test_select_order_units_and_meta():
    rec = make_record(meta={"seed": 1})
    sub = rec.select(["TwHt3MLyt", "PtfmPitch"])
    assert sub.channels == ["TwHt3MLyt", "PtfmPitch"]
    assert sub.units == ["kN-m", "deg"]
    assert sub.meta == {"seed": 1}
    np.testing.assert_array_equal(sub.y[:, 1], rec["PtfmPitch"])
    np.testing.assert_array_equal(sub.t, rec.t)
    assert rec.select("Wind1VelX").n_channels == 1


def test_select_errors():
    rec = make_record()
    with pytest.raises(ValueError, match="did you mean 'PtfmPitch'"):
        rec.select(["PtfmPich"])
    with pytest.raises(ValueError, match="unique"):
        rec.select(["PtfmPitch", "PtfmPitch"])


@pytest.mark.parametrize("plane", ["FA", "SS"])
def test_planar(plane):
    rec = make_record()
    sub = rec.planar(plane)
    assert sub.channels == tower_channels(plane)
    assert sub.n_channels == 18
    for k, name in enumerate(sub.channels):
        np.testing.assert_array_equal(sub.y[:, k], rec[name])


def test_planar_errors():
    rec = make_record()
    with pytest.raises(ValueError, match="plane"):
        rec.planar("XY")
    with pytest.raises(ValueError, match="plane"):
        rec.planar(None)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="unknown channel"):
        rec.select(tower_channels("SS")).planar("FA")


def test_getitem_and_contains():
    rec = make_record()
    assert rec["TwHt9ALxt"].shape == (rec.n_samples,)
    assert "TwHt9ALxt" in rec and "nope" not in rec
    with pytest.raises(KeyError):
        rec["nope"]
    with pytest.raises(ValueError, match="unknown channel"):
        rec["nope"]
    with pytest.raises(TypeError):
        rec[0]  # type: ignore[index]


def test_slice_time_half_open():
    rec = make_record(n=801)
    part = rec.slice_time(1.0, 2.0)
    assert part.n_samples == 80
    assert part.t[0] == pytest.approx(1.0) and part.t[-1] == pytest.approx(2.0 - 0.0125)
    first, second = rec.slice_time(None, 5.0), rec.slice_time(5.0, None)
    assert first.n_samples + second.n_samples == rec.n_samples
    np.testing.assert_array_equal(np.vstack([first.y, second.y]), rec.y)


def test_slice_time_errors():
    rec = make_record(n=10)
    with pytest.raises(ValueError, match="t0 must be < t1"):
        rec.slice_time(1.0, 0.5)
    with pytest.raises(ValueError, match="sample"):
        rec.slice_time(100.0, 200.0)
    with pytest.raises(ValueError, match="finite"):
        rec.slice_time(float("nan"), 1.0)


def test_replace_and_equality():
    rec = make_record(n=10, meta={"a": 1})
    y = rec.y.copy()
    y[0, 0] = np.nan
    other = rec.replace(y=y, meta={"a": 2})
    assert other.meta == {"a": 2} and np.isnan(other.y[0, 0])
    assert rec == rec.replace()
    assert rec != other
    assert other == other.replace(y=y.copy())  # NaN compares equal in ==


# ---------------------------------------------------------------- files
def test_save_load_round_trip_bit_identical(tmp_path):
    rec = make_record(n=300, meta={"load_case": load_case(7).to_dict(), "seed": 42, "note": "Tŵr — ümlaut ✓"})
    y = rec.y.copy()
    y[10, :] = np.nan
    y[:, 3] = np.nan
    y[5, 5] = -0.0
    y.view(np.uint64)[6, 6] = 0x7FF8_0000_DEAD_BEEF  # NaN with a payload
    rec = rec.replace(y=y)
    path = rec.save(tmp_path / "rec.npz")
    assert path == tmp_path / "rec.npz"
    back = Record.load(path)
    np.testing.assert_array_equal(bits(back.t), bits(rec.t))
    np.testing.assert_array_equal(bits(back.y), bits(rec.y))
    assert back.channels == rec.channels
    assert back.units == rec.units
    assert back.meta == rec.meta
    assert back.meta["note"] == "Tŵr — ümlaut ✓"
    assert back == rec


def test_file_readable_with_plain_numpy_without_pickle(tmp_path):
    rec = make_record(n=20, channels=tower_channels("FA"), meta={"seed": 1})
    path = rec.save(tmp_path / "plain.npz")
    with np.load(path, allow_pickle=False) as data:
        assert sorted(data.files) == ["header", "t", "y"]
        assert data["header"].ndim == 0 and data["header"].dtype.kind == "U"
        header = json.loads(str(data["header"][()]))
        np.testing.assert_array_equal(data["y"], rec.y)
    assert header["format"] == FORMAT_NAME
    assert header["channels"] == tower_channels("FA")
    assert header["meta"] == {"seed": 1}


def test_save_writes_exact_path_and_overwrites(tmp_path):
    rec = make_record(n=5, channels=["PtfmPitch"])
    target = tmp_path / "noext"
    rec.save(target)
    assert target.exists() and not (tmp_path / "noext.npz").exists()
    rec.replace(meta={"v": 2}).save(str(target))
    assert Record.load(str(target)).meta == {"v": 2}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["noext"]  # no temporary left behind


def test_load_rejects_non_records(tmp_path):
    text = tmp_path / "text.npz"
    text.write_text("hello")
    with pytest.raises(ValueError, match="not a Record"):
        Record.load(text)

    single = tmp_path / "single.npy"
    np.save(single, np.zeros(3))
    with pytest.raises(ValueError, match="not a Record"):
        Record.load(single)

    other = tmp_path / "other.npz"
    np.savez(other, a=np.zeros(3))
    with pytest.raises(ValueError, match="members"):
        Record.load(other)

    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, t=np.arange(2.0), y=np.zeros((2, 1)), header=np.array([{"x": 1}], dtype=object))
    with pytest.raises(ValueError, match="not a"):
        Record.load(pickled)

    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, t=np.arange(2.0), y=np.zeros((2, 1)), header=np.array(json.dumps({"format": "x"})))
    with pytest.raises(ValueError, match="format"):
        Record.load(foreign)

    future = tmp_path / "future.npz"
    head = {"format": FORMAT_NAME, "version": 99, "channels": ["a"], "units": ["m"], "meta": {}}
    np.savez(future, t=np.arange(2.0), y=np.zeros((2, 1)), header=np.array(json.dumps(head)))
    with pytest.raises(ValueError, match="version"):
        Record.load(future)

    bad_json = tmp_path / "bad_json.npz"
    np.savez(bad_json, t=np.arange(2.0), y=np.zeros((2, 1)), header=np.array("{not json"))
    with pytest.raises(ValueError, match="JSON"):
        Record.load(bad_json)

    with pytest.raises(FileNotFoundError):
        Record.load(tmp_path / "missing.npz")


def test_load_rejects_corrupt_zip(tmp_path):
    path = make_record(n=50).save(tmp_path / "r.npz")
    raw = path.read_bytes()
    path.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ValueError, match="not a Record"):
        Record.load(path)


@pytest.mark.parametrize("offset", [40, 200, 600])
def test_load_of_corrupt_compressed_data_is_one_line(tmp_path, offset):
    """A damaged deflate stream (zlib.error) or CRC inside the archive: one line naming the file (issue 18)."""
    path = make_record(n=400).save(tmp_path / "r.npz")
    raw = bytearray(path.read_bytes())
    start = raw.find(b"y.npy") + offset
    raw[start:start + 40] = bytes(b ^ 0xFF for b in raw[start:start + 40])
    path.write_bytes(bytes(raw))
    with pytest.raises(ValueError) as err:
        Record.load(path)
    text = str(err.value)
    assert str(path) in text and "\n" not in text and "Traceback" not in text


def test_load_and_save_errors_are_one_line_and_name_the_path_not_the_temporary_file(tmp_path, monkeypatch):
    rec = make_record(n=20)
    (tmp_path / "adir").mkdir()
    cases = [(lambda: Record.load(tmp_path / "missing.npz"), FileNotFoundError, "no such file"),
             (lambda: Record.load(tmp_path / "adir"), IsADirectoryError, "is a directory"),
             (lambda: rec.save(tmp_path / "nodir" / "r.npz"), FileNotFoundError, "does not exist"),
             (lambda: rec.save(tmp_path / "adir"), IsADirectoryError, "is a directory")]
    for call, kind, words in cases:
        with pytest.raises(kind) as err:
            call()
        text = str(err.value)
        assert words in text and ".tmp" not in text and "\n" not in text, text

    def refuse(src, dst):
        raise PermissionError(13, "Permission denied", str(src))

    monkeypatch.setattr("surrogates.record.os.replace", refuse)
    with pytest.raises(PermissionError) as err:
        rec.save(tmp_path / "r.npz")
    assert str(tmp_path / "r.npz") in str(err.value) and ".tmp" not in str(err.value)
    assert [f.name for f in tmp_path.iterdir()] == ["adir"]  # the temporary file is gone


# ---------------------------------------------------------------- property test
_names = st.lists(
    st.text(min_size=1, max_size=12),
    min_size=0,
    max_size=6,
    unique=True,
)
_json_leaf = (
    st.none()
    | st.booleans()
    | st.integers(-(2**63), 2**63)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=10)
)
_meta = st.dictionaries(
    st.text(max_size=8),
    st.recursive(
        _json_leaf,
        lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
        max_leaves=8,
    ),
    max_size=4,
)


@st.composite
def records(draw):
    channels = draw(_names)
    n = draw(st.integers(2, 40))
    steps = draw(hnp.arrays(np.float64, n - 1, elements=st.floats(1e-3, 10.0, allow_nan=False, allow_infinity=False)))
    t0 = draw(st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False))
    t = t0 + np.concatenate([[0.0], np.cumsum(steps)])
    y = draw(
        hnp.arrays(
            np.float64,
            (n, len(channels)),
            elements=st.floats(allow_nan=True, allow_infinity=False, width=64),
        )
    )
    units = draw(st.lists(st.text(max_size=6), min_size=len(channels), max_size=len(channels)))
    return Record(t, y, channels, units, draw(_meta))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rec=records())
def test_round_trip_property(tmp_path, rec):
    back = Record.load(rec.save(tmp_path / "prop.npz"))
    np.testing.assert_array_equal(bits(back.t), bits(rec.t))
    assert back.y.shape == rec.y.shape
    np.testing.assert_array_equal(bits(back.y), bits(rec.y))
    assert back.channels == rec.channels
    assert back.units == rec.units
    assert back.meta == rec.meta
