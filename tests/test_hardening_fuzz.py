"""Fuzz test of every entry point that takes user data (issue 18): ``load_record``, every estimator's ``fit`` and
every virtual sensor's ``update``, and ``SparEnv``'s ``step``, driven by hypothesis with arbitrary shapes, dtypes
and values (NaN, ±inf, 1e308, subnormals, constant channels, 10^±300 scales, strings, objects, complex).

The invariant, the same everywhere: a :class:`ValueError` or :class:`TypeError` whose message is one readable line
(never another exception type, never NumPy's internals), or a documented result that is finite where the input
was finite — for the sensors, finite whatever the input (NaN is a lost sample, not an error). A sensor that refused
one sample keeps working on the next. Numpy's ``ComplexWarning`` (an imaginary part silently dropped) is an error.

The default suite runs a few dozen examples per entry point (a few seconds each); ``-m slow`` runs hundreds.
``SparEnv`` construction is fuzzed argument by argument in tests/test_hardening_env.py.
"""

from __future__ import annotations

import os
import tempfile
import warnings

import control
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import signal

import fowt_env
from estimators import (
    HankelDMD,
    HankelDMDSensor,
    HoldLastValue,
    KalmanSensor,
    KoopmanKalmanSensor,
    Preprocessor,
    SSICov,
    lyapunov_exponent,
    preprocess,
    probabilistic_mode_shapes,
    rotor_harmonics,
)
from fowt_env.io import RecordFileError, load_record, save_record
from surrogates import Record

DT = 0.0125
QUICK, LONG = 25, 400  # examples per entry point: default suite / -m slow
BUDGETS = [pytest.param(QUICK, id="quick"), pytest.param(LONG, id="long", marks=pytest.mark.slow)]
SPECIAL = [np.nan, np.inf, -np.inf, 0.0, 1e308, -1e308, 5e-324, 1e-300]
DTYPES = ["float64", "float32", "float16", "int64", "int8", "uint8", "bool", "complex128", "object", "U8", "list"]
OBSCURE = ("Internal Error", "cannot convert float NaN to integer", "could not broadcast", "setting an array element",
           "invalid literal for", "math domain error", "index ", "out of bounds", "codec can't decode",
           "not enough values", "too many values", "object of type", "unsupported operand", "has no len",
           "NoneType", "referenced before assignment", "singular matrix")


def _settings(budget: int):
    # derandomize: the same examples every run, so CI is reproducible (a fresh random draw is a different test)
    return settings(max_examples=budget, deadline=None, database=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                           HealthCheck.data_too_large])


@st.composite
def arrays(draw, max_rows: int = 300, max_cols: int = 4, ndims=(0, 1, 2, 2, 2, 2, 3)):
    """Arbitrary array-likes: mostly (n, p) numeric data of any scale with special values, sometimes anything."""
    ndim = draw(st.sampled_from(ndims))
    shape = tuple(draw(st.integers(0, max_rows if i == 0 else max_cols)) for i in range(ndim))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    with np.errstate(all="ignore"):
        x = np.asarray(rng.standard_normal(shape) * 10.0 ** draw(st.floats(-300.0, 300.0)), dtype=float)
        if x.ndim == 2 and x.shape[0] > 3 and draw(st.booleans()):  # a smooth signal, so that fits can succeed
            x = signal.lfilter([1.0], [1.0, -1.8, 0.95], x, axis=0)
    for _ in range(draw(st.integers(0, 3))):
        if x.size:
            x.flat[draw(st.integers(0, x.size - 1))] = draw(st.sampled_from(SPECIAL))
    if x.ndim == 2 and x.shape[1] and draw(st.booleans()):
        x[:, draw(st.integers(0, x.shape[1] - 1))] = draw(st.sampled_from([0.0, 1.0, np.nan]))
    kind = draw(st.sampled_from(DTYPES))
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if kind == "list":
            return x.tolist()
        if kind == "complex128":
            return x + 1j * draw(st.sampled_from([0.0, 1.0]))
        if kind == "object":
            out = x.astype(object)
            if out.size and draw(st.booleans()):
                out.flat[draw(st.integers(0, out.size - 1))] = draw(st.sampled_from([None, "x", [1.0], {}]))
            return out
        return x.astype(kind)


def _finite_input(x) -> bool:
    try:
        a = np.asarray(x, dtype=float)
    except (ValueError, TypeError):
        return False
    return bool(np.isfinite(a).all()) and not np.iscomplexobj(np.asarray(x))


def _numbers(obj) -> list[np.ndarray]:
    """Every float array or number inside a result (arrays, scalars, dicts, lists, objects' learned attributes)."""
    if isinstance(obj, (float, np.floating, complex, np.complexfloating)):
        return [np.asarray(obj)]
    if isinstance(obj, np.ndarray):
        return [obj] if obj.dtype.kind in "fc" else []
    if isinstance(obj, dict):
        return [a for v in obj.values() for a in _numbers(v)]
    if isinstance(obj, (list, tuple)):
        return [a for v in obj for a in _numbers(v)]
    return []


def clear_error_or_finite(call, *, finite_in: bool, always_finite: bool = False):
    """Run ``call``: a one-line ValueError/TypeError, or its numbers are finite (when the input was finite, or
    always). Returns the result, or None after an error."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", np.exceptions.ComplexWarning)
            out = call()
    except (ValueError, TypeError) as exc:
        msg = str(exc).strip()
        assert msg, f"{type(exc).__name__} without a message"
        assert "\n" not in msg and len(msg) < 600, f"not one readable line: {msg!r}"
        assert not any(s in msg for s in OBSCURE), f"NumPy/Python internals instead of a clear message: {msg!r}"
        return None
    if finite_in or always_finite:
        for a in _numbers(out):
            assert np.isfinite(a).all(), f"non-finite result from finite input: {a}"
    return out


# --------------------------------------------------------------------------------------------- estimators' fit
def _system3() -> control.StateSpace:
    """A stable 2-DOF oscillator with 3 outputs (two displacements, one acceleration) and 2 load inputs."""
    m, k, c = np.diag([1.0, 1.0]), np.array([[20.0, -10.0], [-10.0, 10.0]]), np.array([[0.4, -0.2], [-0.2, 0.2]])
    mi = np.linalg.inv(m)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-mi @ k, -mi @ c]])
    b = np.vstack([np.zeros((2, 2)), mi])
    cc = np.vstack([np.eye(2, 4), a[3]])
    d = np.vstack([np.zeros((2, 2)), b[3]])
    return control.ss(a, b, cc, d)


def _fit_calls(Y) -> dict:
    n = np.shape(Y)[0] if np.ndim(Y) >= 1 else 0
    return {
        "preprocess": lambda: preprocess(Y, fs=1 / DT),
        "Preprocessor": lambda: Preprocessor(fs=1 / DT).fit_transform(Y),
        "HankelDMD": lambda: _learned(HankelDMD(delays=4, rank=4, dt=DT).fit(Y),
                                      "eigenvalues_", "modes_", "frequencies_hz_"),
        "SSICov": lambda: _learned(SSICov(DT, block_rows=6, orders=(2, 4, 6)).fit(Y), "frequencies_hz_",
                                   "damping_ratios_", "modes_"),
        "lyapunov_exponent": lambda: lyapunov_exponent(Y, DT, dim=3, lag=2, max_steps=10),
        "rotor_harmonics": lambda: rotor_harmonics(Y, DT, rotor_speed=np.full(max(n, 2), 1.27), delays=(4, 5),
                                                   rank=4),
        # documented: a target no fit found has a NaN mean shape; the found ones are checked
        "probabilistic_mode_shapes": lambda: [(d.frequencies_hz, d.mean) for d in probabilistic_mode_shapes(
            Y, DT, delays=(4, 5), rank=4, target_frequencies_hz=[2.0]) if d.n_found],
        "HoldLastValue": lambda: HoldLastValue().fit(Y).update(np.full(_width(Y), np.nan)),
        "HankelDMDSensor": lambda: HankelDMDSensor(delays=4, rank=4, dt=DT).fit(Y).update(np.full(_width(Y),
                                                                                                 np.nan)),
        "KoopmanKalmanSensor": lambda: KoopmanKalmanSensor(delays=4, rank=4, dt=DT, em_iter=2).fit(Y).update(
            np.full(_width(Y), np.nan)),
        "KalmanSensor": lambda: KalmanSensor(_system3(), DT, em_iter=2).fit(Y).update(np.full(3, np.nan)),
    }


def _width(Y) -> int:
    a = np.asarray(Y, dtype=object)
    return int(a.shape[1]) if a.ndim == 2 else 1


def _learned(est, *names: str) -> dict:
    return {n: getattr(est, n) for n in names}


FIT_TARGETS = sorted(_fit_calls(np.zeros((2, 2))))


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("target", FIT_TARGETS)
def test_fuzz_estimator_fit_is_a_clear_error_or_finite(target, budget):
    @_settings(budget)
    @given(Y=arrays())
    def run(Y):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # documented diagnostics (lyapunov_exponent)
            warnings.simplefilter("ignore", UserWarning)
            clear_error_or_finite(_fit_calls(Y)[target], finite_in=_finite_input(Y))

    run()


# ------------------------------------------------------------------------------------------ sensors' update
def _training(seed: int = 0, n: int = 4000) -> np.ndarray:
    """3 channels of the 2-DOF oscillator under white loads (the Kalman model's outputs), plus noise."""
    rng = np.random.default_rng(seed)
    sysd = control.c2d(_system3(), DT)
    u = rng.standard_normal((n, 2))
    resp = control.forced_response(sysd, T=np.arange(n) * DT, U=u.T)
    return np.asarray(resp.outputs).T + 0.01 * rng.standard_normal((n, 3))


@pytest.fixture(scope="module")
def fitted_sensors() -> dict:
    y = _training()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {
            "HoldLastValue": HoldLastValue().fit(y),
            "HankelDMDSensor": HankelDMDSensor(delays=20, rank=12, dt=DT).fit(y),
            "KoopmanKalmanSensor": KoopmanKalmanSensor(delays=20, rank=12, dt=DT, em_iter=3).fit(y),
            "KalmanSensor": KalmanSensor(_system3(), DT, em_iter=3).fit(y),
        }


@st.composite
def masks(draw):
    kind = draw(st.sampled_from(["none", "bool", "bool", "int", "float", "wrong_shape", "object", "str"]))
    bits = np.array(draw(st.lists(st.booleans(), min_size=3, max_size=3)))
    return {"none": None, "bool": bits, "int": bits.astype(int) * draw(st.sampled_from([1, 2, -1])),
            "float": np.where(bits, draw(st.sampled_from([1.0, 0.5, np.nan])), 0.0),
            "wrong_shape": np.ones(draw(st.sampled_from([0, 2, 4, 9])), bool), "object": bits.astype(object),
            "str": np.array(["yes", "no", "yes"])}[kind]


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("name", ["HoldLastValue", "HankelDMDSensor", "KoopmanKalmanSensor", "KalmanSensor"])
def test_fuzz_sensor_update_is_a_clear_error_or_finite(fitted_sensors, name, budget):
    sensor = fitted_sensors[name]
    good = _training(seed=1, n=400)
    sensor.reset()
    for row in good[:100]:
        sensor.update(row)

    @_settings(budget)
    @given(y=arrays(max_rows=5, ndims=(0, 1, 1, 1, 1, 2)), mask=masks(), n_good=st.integers(0, 3))
    def run(y, mask, n_good):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            out = clear_error_or_finite(lambda: sensor.update(y, mask), finite_in=True, always_finite=True)
            if out is not None:
                assert np.shape(out) == (3,)
            for row in good[100:100 + n_good]:  # a refused or odd sample leaves the sensor working
                est = sensor.update(row)
                assert est.shape == (3,) and np.isfinite(est).all()

    run()


# ------------------------------------------------------------------------------------------------ files
_FORMATS = (".npz", ".csv", ".out", ".outb", ".parquet")


@pytest.fixture(scope="module")
def valid_files(tmp_path_factory) -> dict[str, bytes]:
    d = tmp_path_factory.mktemp("valid")
    t = np.arange(50) * 0.05
    rec = Record(t, np.c_[np.sin(t), np.cos(3 * t)], ["TwHt1ALxt", "TwHt1MLyt"], ["m/s^2", "kN-m"])
    out = {}
    for ext in _FORMATS:
        path = save_record(rec, d / f"rec{ext}")
        out[ext] = path.read_bytes()
    return out


@st.composite
def file_contents(draw, valid: dict[str, bytes]):
    ext = draw(st.sampled_from(_FORMATS + (".OUTB", ".txt", "")))
    base = valid.get(ext.lower(), valid[".csv"])
    kind = draw(st.sampled_from(["random", "truncated", "flipped", "spliced", "text", "empty"]))
    if kind == "random":
        data = draw(st.binary(max_size=2000))
    elif kind == "truncated":
        data = base[:draw(st.integers(0, len(base)))]
    elif kind == "flipped":
        b = bytearray(base)
        for _ in range(draw(st.integers(1, 20))):
            b[draw(st.integers(0, len(b) - 1))] = draw(st.integers(0, 255))
        data = bytes(b)
    elif kind == "spliced":
        at = draw(st.integers(0, len(base)))
        data = base[:at] + draw(st.binary(min_size=1, max_size=200)) + base[at:]
    elif kind == "text":
        lines = draw(st.lists(st.text(st.sampled_from("Time,TwHt1ALxt 0123456789.-e+naif\t;\"\n"), max_size=40),
                              max_size=30))
        data = "\n".join(lines).encode()
    else:
        data = b""
    return ext, data


@pytest.mark.parametrize("budget", [pytest.param(3 * QUICK, id="quick"),
                                    pytest.param(3 * LONG, id="long", marks=pytest.mark.slow)])
def test_fuzz_load_record_is_a_clear_error_or_a_valid_record(valid_files, budget):
    folder = tempfile.mkdtemp(prefix="fuzz-records-")

    @_settings(budget)
    @given(content=file_contents(valid_files))
    def run(content):
        ext, data = content
        path = os.path.join(folder, f"fuzzed{ext}")
        with open(path, "wb") as fh:
            fh.write(data)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # unknown channel names are reported, not errors
            try:
                rec = load_record(path)
            except RecordFileError as exc:
                msg = str(exc).strip()
                assert msg and "\n" not in msg and not any(s in msg for s in OBSCURE), msg
                return
        assert isinstance(rec, Record)
        assert np.isfinite(rec.t).all() and rec.dt > 0 and np.all(np.diff(rec.t) > 0)
        assert not np.isinf(rec.y).any()  # NaN is a documented missing value; inf never
        assert rec.y.shape == (rec.t.size, len(rec.channels))

    run()


# -------------------------------------------------------------------------------------------- environment
@pytest.fixture(scope="module")
def env():
    e = fowt_env.SparEnv(plane="FA", warmup_seconds=1.0, episode_seconds=None)
    e.reset(seed=0)
    return e


@st.composite
def actions(draw):
    return draw(st.one_of(
        arrays(max_rows=3, max_cols=3, ndims=(0, 1, 1, 1, 2)),
        st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3),
        st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
        st.sampled_from([None, "0,0", {"pitch": 0.0}, (0.0, None), b"\x00\x00"]),
    ))


@pytest.mark.parametrize("budget", BUDGETS)
def test_fuzz_env_step_is_a_clear_error_or_a_finite_step(env, budget):
    @_settings(budget)
    @given(action=actions())
    def run(action):
        out = clear_error_or_finite(lambda: env.step(action), finite_in=True, always_finite=True)
        if out is None:
            return
        obs, reward, terminated, truncated, info = out
        assert env.observation_space.contains(obs)
        assert np.isfinite(reward) and np.isfinite(info["truth"]).all()
        if terminated or truncated:
            env.reset(seed=1)

    run()
    obs, *_ = env.step(np.zeros(2, dtype=np.float32))  # and the env still steps
    assert np.isfinite(obs["sensors"]).all()


# ------------------------------------------------------------------ the classes the fuzzing found, pinned down
@pytest.mark.parametrize("name", ["HoldLastValue", "HankelDMDSensor", "KoopmanKalmanSensor", "KalmanSensor"])
def test_sample_contract_is_one_for_every_sensor_update(fitted_sensors, name):
    """estimators.validation.as_sample: complex samples and non-boolean masks are refused, never cast silently."""
    sensor = fitted_sensors[name]
    sensor.reset()
    with pytest.raises(TypeError, match="y must be real"):
        sensor.update(np.array([0.1 + 0.0j, 0.2, 0.3]))
    with pytest.raises(TypeError, match="y must hold real numbers"):
        sensor.update(np.array(["a", "b", "c"]))
    with pytest.raises(ValueError, match=r"mask must hold booleans or 0/1.*0.5 at channel 1"):
        sensor.update(np.zeros(3), np.array([1.0, 0.5, 1.0]))
    with pytest.raises(ValueError, match="mask must hold booleans or 0/1"):
        sensor.update(np.zeros(3), np.array([1.0, np.nan, 1.0]))
    live = sensor.update(np.array([0.01, 0.02, 0.03]), np.array([1, 0, 1]))  # 0/1 integers are a mask
    assert np.isfinite(live).all()


def test_env_action_contract():
    env = fowt_env.SparEnv(plane="FA", warmup_seconds=0.5)
    env.reset(seed=0)
    with pytest.raises(TypeError, match="action must be real"):
        env.step(np.array([0.1 + 0.5j, 0.0]))
    with pytest.raises(TypeError, match="two real numbers"):
        env.step(["a", "b"])
    assert np.isfinite(env.step(np.array([0.1, 0.0]))[0]["sensors"]).all()


def test_hold_last_value_fit_refuses_magnitudes_that_overflow_its_mean():
    y = np.ones((10, 2))
    y[3, 1] = 1e308
    with pytest.raises(ValueError, match="channel 1"):
        HoldLastValue().fit(y)


def test_lyapunov_exponent_is_scale_free_down_to_tiny_values():
    """Squared distances of 1e-160-sized data underflowed to 0 (NaN curve, 'cannot convert float NaN')."""
    x = np.empty(3000)
    x[0] = 0.3
    for k in range(x.size - 1):  # logistic map at r = 4: exponent ln 2 per step
        x[k + 1] = 4.0 * x[k] * (1.0 - x[k])
    ref = lyapunov_exponent(x, 1.0, dim=2, lag=1, max_steps=20)
    assert lyapunov_exponent(x * 1e-160, 1.0, dim=2, lag=1, max_steps=20) == pytest.approx(ref, rel=1e-6)
    spiky = np.zeros(200)
    spiky[50] = 1.0
    with pytest.raises(ValueError, match="repeats itself exactly"):
        lyapunov_exponent(spiky, 1.0, dim=2, lag=1, max_steps=10)


def test_corrupt_compressed_npz_is_a_record_file_error(tmp_path, valid_files):
    data = bytearray(valid_files[".npz"])
    start = data.index(b"y.npy") + 40  # inside the deflated stream of y
    data[start:start + 16] = b"\xff" * 16
    (tmp_path / "bad.npz").write_bytes(bytes(data))
    with pytest.raises(RecordFileError, match="bad.npz"):
        load_record(tmp_path / "bad.npz")
