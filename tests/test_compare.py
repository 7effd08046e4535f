"""The virtual-sensing comparison harness (fowt_env.compare) and `fowt-env compare`.

Expectations come from physics and from independent re-computation (own simulations, own formulas), never from
numbers the harness printed.
"""

import json
from concurrent.futures import ThreadPoolExecutor

import gymnasium as gym
import numpy as np
import pytest

import fowt_env
import surrogates
from fowt_env import compare as C
from fowt_env.cli import main
from fowt_env.faults import SCENARIOS
from surrogates.channels import tower_channels

TRAIN = (1, 6)
# small and quick: two training OLCs of 60 s, 30 s test records, at most 3 EM steps in the Kalman fit
SETTINGS = C.CompareSettings(train_cases=TRAIN, train_duration=60.0, duration=30.0, trace_seconds=10.0,
                             estimator_options={"kalman": {"em_iter": 3}})
SEED = 3
# the CLI flags that reproduce SETTINGS (so the CLI tests reuse the memoised fits)
CLI_SMALL = ["--train-cases", "1,6", "--train-duration", "60", "--duration", "30", "--seeds", str(SEED),
             "--option", "kalman.em_iter=3"]


def own_r2(y: np.ndarray, e: np.ndarray) -> float:
    return float(1.0 - np.sum((y - e) ** 2) / np.sum((y - y.mean()) ** 2))


def own_nrmse(y: np.ndarray, e: np.ndarray) -> float:
    return float(np.sqrt(np.mean((y - e) ** 2)) / (y.max() - y.min()))


def by_key(result, scenario, estimator, interval=None):
    hits = [r for r in result.runs
            if r["scenario"] == scenario and r["estimator"] == estimator and r["update_interval"] == interval]
    assert len(hits) == 1
    return hits[0]


@pytest.fixture(scope="module")
def small():
    C.clear_cache()
    return C.compare(["A", "B", "random"], ["hold", "kalman"], seeds=[SEED], settings=SETTINGS, lyapunov_time=2.0)


# ------------------------------------------------------------------------------------------------ physics
def test_kalman_beats_hold_on_the_hidden_channels(small):
    for sc in ("A", "B", "random"):
        hold, kal = by_key(small, sc, "hold"), by_key(small, sc, "kalman")
        # a model-based filter follows the hidden response; a held value cannot
        assert kal["median_r2"] > 0.95 and kal["worst_r2"] > 0.8, sc
        assert kal["median_r2_band"] > 0.9, sc
        assert kal["median_r2"] > hold["median_r2"] + 0.3, sc
        assert kal["median_nrmse"] < 0.5 * hold["median_nrmse"], sc
        assert kal["median_nrmse"] < 0.05, sc  # the paper's fatigue-grade bar
    # the training mean of a hidden channel explains none of its variance in the test record
    for sc in ("A", "B"):
        assert by_key(small, sc, "hold")["median_r2"] < 0.1
        # band-passed constant = 0 -> R2 = -(the band-passed truth's mean)^2 / its variance, ~0
        assert abs(by_key(small, sc, "hold")["median_r2_band"]) < 5e-3


def training_mean() -> np.ndarray:
    """The mean of the training records, simulated here (seed convention: train_seed + OLC)."""
    model = surrogates.FOWTModel()
    recs = [surrogates.simulate(model, c, duration=60.0, seed=1000 + c).planar("FA").y for c in TRAIN]
    return np.concatenate(recs).mean(axis=0)


def test_fixed_scenarios_score_exactly_their_hidden_channels(small):
    fa = tower_channels("FA")
    noisy, truth = surrogates.simulate(surrogates.FOWTModel(), SCENARIOS["A"]["olc"], duration=30.0, seed=SEED,
                                       return_truth=True)
    truth = truth.planar("FA").y
    mean = training_mean()
    for sc in ("A", "B"):
        expected = [fa[i] for i in SCENARIOS[sc]["hidden"]]
        for est in ("hold", "kalman"):
            run = by_key(small, sc, est)
            assert run["hidden"] == expected and [c["channel"] for c in run["channels"]] == expected
            assert run["case"] == SCENARIOS[sc]["olc"] and not run["case_in_training"]
            assert all(c["hidden_fraction"] == 1.0 and c["n_scored"] == truth.shape[0] for c in run["channels"])
    # hold with fill="mean" reports the training mean for a channel hidden from the start: score it ourselves
    for row in by_key(small, "A", "hold")["channels"]:
        j = fa.index(row["channel"])
        est = np.full(truth.shape[0], mean[j])
        assert row["r2"] == pytest.approx(own_r2(truth[:, j], est), rel=1e-9)
        assert row["nrmse"] == pytest.approx(own_nrmse(truth[:, j], est), rel=1e-9)
        assert row["unit"] == ("m/s^2" if "AL" in row["channel"] else "kN-m")


def forward_fill(y: np.ndarray, mask: np.ndarray, start: np.ndarray) -> np.ndarray:
    out = np.empty_like(y)
    last = start.copy()
    for k in range(y.shape[0]):
        last = np.where(mask[k], y[k], last)
        out[k] = last
    return out


def test_random_dropouts_are_scored_over_the_hidden_samples_only(small):
    n = int(round(30.0 / SETTINGS.dt))
    mask = C.scenario_mask("random", n, SETTINGS, seed=SEED, case=7)
    np.testing.assert_array_equal(mask, C.scenario_mask("random", n, SETTINGS, seed=SEED, case=7))
    assert not np.array_equal(mask, C.scenario_mask("random", n, SETTINGS, seed=SEED + 1, case=7))
    # Markov dropouts: long-run lost fraction 0.2, mean burst 2 s (loose: 30 s x 18 channels)
    long = C.scenario_mask("random", 40_000, SETTINGS, seed=0, case=7)
    assert 0.15 < (~long).mean() < 0.25
    starts = (~long[1:] & long[:-1]).sum()
    assert 1.5 < (~long[1:]).sum() * SETTINGS.dt / starts < 2.5
    noisy, truth = surrogates.simulate(surrogates.FOWTModel(), 7, duration=30.0, seed=SEED, return_truth=True)
    y, truth = noisy.planar("FA").y, truth.planar("FA").y
    est = forward_fill(y, mask, training_mean())
    run = by_key(small, "random", "hold")
    fa = tower_channels("FA")
    assert run["hidden"] == [fa[j] for j in range(18) if (~mask[:, j]).any()]
    assert run["lost_fraction"] == pytest.approx((~mask).mean())
    for row in run["channels"]:
        j = fa.index(row["channel"])
        h = ~mask[:, j]
        assert row["n_scored"] == h.sum()
        if h.sum() >= 2:  # errors where hidden, normalised by the whole record's variance and range
            y, e = truth[:, j], est[:, j]
            mse = np.mean((y[h] - e[h]) ** 2)
            assert row["r2"] == pytest.approx(1.0 - mse / np.var(y), rel=1e-9, abs=1e-12)
            assert row["nrmse"] == pytest.approx(np.sqrt(mse) / (y.max() - y.min()), rel=1e-9)


# ------------------------------------------------------------------------------------------------ determinism
def test_identical_json_twice_and_with_a_thread_pool(small):
    again = C.compare(["A", "B", "random"], ["hold", "kalman"], seeds=[SEED], settings=SETTINGS, lyapunov_time=2.0)
    C.clear_cache()  # the threads simulate and fit everything again
    with ThreadPoolExecutor(max_workers=2) as pool:
        threaded = C.compare(["A", "B", "random"], ["hold", "kalman"], seeds=[SEED], settings=SETTINGS,
                             lyapunov_time=2.0, executor=pool)
    ref = json.dumps(small.to_dict(wall_clock=False))
    assert json.dumps(again.to_dict(wall_clock=False)) == ref
    assert json.dumps(threaded.to_dict(wall_clock=False)) == ref
    full = json.loads(json.dumps(threaded.to_dict(), allow_nan=False))  # strict JSON: no NaN/inf
    # everything but the clearly named timings is the same
    timings = full.pop("wall_clock")
    assert json.dumps(full) == ref
    assert len(timings["runs"]) == len(full["runs"]) and all(w["us_per_sample"] > 0 for w in timings["runs"])
    assert json.loads(json.dumps(small.to_dict(traces=True)))["traces"][0]["channels"]


def test_the_unit_of_work_returns_plain_data():
    out = C.run_unit(5, SEED, "A", "hold", 1.0, SETTINGS)
    assert json.loads(json.dumps(out)) == out
    assert out["update_interval"] is None  # hold ignores it
    assert set(out["wall_clock"]) == {"fit_s", "reconstruct_s", "us_per_sample"}


# ------------------------------------------------------------------------------------------------ live in the env
@pytest.mark.parametrize("name", ["hold", "kalman", "dmd"])
def test_live_estimates_in_the_gym_env_equal_reconstruct(name):
    sensor = C.fit_sensor(name, SETTINGS)
    env = fowt_env.VirtualSensorWrapper(gym.make("fowt_env/SparScenarioB-v0"), sensor)
    obs, _ = env.reset(seed=11)
    sensors, masks, live = [obs["sensors"]], [obs["mask"]], [obs["estimate"]]
    zero = np.zeros(2, dtype=np.float32)
    for _ in range(299):
        obs, _, term, trunc, _ = env.step(zero)
        assert not (term or trunc)
        sensors.append(obs["sensors"])
        masks.append(obs["mask"])
        live.append(obs["estimate"])
    sensors, mask, live = np.array(sensors), np.array(masks).astype(bool), np.array(live)
    assert set(np.flatnonzero(~mask.all(axis=0))) == {0, 8, 9, 17}
    # the wrapper clips estimates to the observation box: it must not have bitten
    high = env.observation_space["estimate"].high
    assert np.all(np.abs(live) < 0.5 * high)
    offline = sensor.reconstruct(np.where(mask, sensors, np.nan), mask)
    np.testing.assert_allclose(live, offline, rtol=1e-9, atol=1e-9)


# ------------------------------------------------------------------------------------------------ extension
class PeriodicHold:
    """Toy interval-using sensor: every channel is read only at recalibrations (every update_interval)."""

    def __init__(self, dt, update_interval):
        self.dt, self.update_interval = dt, update_interval

    def fit(self, Y, mask=None):
        self.mean_ = np.mean(np.concatenate(Y), axis=0)
        self.every_ = max(1, round(self.update_interval / self.dt))
        return self

    def reset(self):
        self._k, self._held = 0, self.mean_.copy()

    def update(self, y, mask):
        if self._k % self.every_ == 0:
            self._held = np.where(mask, y, self._held)
        self._k += 1
        return self._held.copy()

    def reconstruct(self, Y, mask):
        self.reset()
        return np.array([self.update(y, m) for y, m in zip(Y, np.broadcast_to(mask, Y.shape), strict=True)])


@pytest.fixture
def periodic_hold():
    C.register_estimator("periodic", lambda dt, update_interval, **_: PeriodicHold(dt, update_interval))
    yield "periodic"
    del C.ESTIMATORS["periodic"]


def test_update_interval_sweep_grid_and_plots(small, periodic_hold, tmp_path):
    res = C.compare(["random"], ["hold", periodic_hold], seeds=[SEED], update_intervals=[0.25, 1.0, 4.0],
                    settings=SETTINGS, lyapunov_time=1.5)
    keys = [(r["estimator"], r["update_interval"]) for r in res.runs]
    assert keys == [("hold", None), ("periodic", 0.25), ("periodic", 1.0), ("periodic", 4.0)]
    # reading the live channels less often can only lose information about the stretches they were hidden
    r2 = [by_key(res, "random", "periodic", v)["median_r2"] for v in (0.25, 1.0, 4.0)]
    assert r2[0] > r2[2]
    (sw,) = res.sweep()  # where the fatigue grade (every hidden NRMSE <= 5 %) is lost, in Lyapunov times
    assert sw["intervals_s"] == [0.25, 1.0, 4.0] and sw["lyapunov_time_s"] == 1.5
    bad = [v for v, e in zip(sw["intervals_s"], sw["worst_nrmse"], strict=True) if e > 0.05]
    assert sw["first_beyond_s"] == (bad[0] if bad else None)
    if sw["first_beyond_s"] is not None:
        assert sw["first_beyond_lyapunov"] == pytest.approx(sw["first_beyond_s"] / 1.5)
    paths = res.plot(tmp_path)
    names = {p.name for p in paths}
    assert names == {"reconstruction_random.png", "r2_table.png", "update_interval_sweep.png"}
    assert all(p.stat().st_size > 20_000 for p in paths)
    text = res.summary()
    assert "periodic" in text and "Lyapunov time 1.50 s" in text


def test_registry_and_argument_errors(small):
    with pytest.raises(ValueError, match="unknown estimator 'nope'; available: hold, kalman"):
        C.compare(["B"], ["nope"], settings=SETTINGS, lyapunov_time=None)
    with pytest.raises(ValueError, match="unknown scenario 'D'"):
        C.compare(["D"], ["hold"], settings=SETTINGS, lyapunov_time=None)
    with pytest.raises(ValueError, match="is the training record"):
        C.compare(["B"], ["hold"], cases=[6], seeds=[1006], settings=SETTINGS, lyapunov_time=None)
    with pytest.raises(ValueError, match="cases: .*13"):
        C.compare(["B"], ["hold"], cases=[13], settings=SETTINGS, lyapunov_time=None)
    with pytest.raises(ValueError, match="update_interval must be a positive"):
        C.compare(["B"], ["hold"], update_intervals=[0.0], settings=SETTINGS, lyapunov_time=None)
    with pytest.raises(ValueError, match="train_cases: .*0"):
        C.CompareSettings(train_cases=(0, 1))
    with pytest.raises(ValueError, match="already registered"):
        C.register_estimator("hold", lambda dt, ui, **_: None)
    assert C.parse_int_list("1,3,8-10") == [1, 3, 8, 9, 10]


# ------------------------------------------------------------------------------------------------ CLI
def test_cli_writes_json_and_figures(small, tmp_path, capsys):
    out = tmp_path / "cmp.json"
    assert main(["compare", "--scenario", "B", "--estimators", "hold,kalman", *CLI_SMALL, "--lyapunov-time", "auto",
                 "--json", str(out), "--plot", str(tmp_path / "figs")]) == 0
    text = capsys.readouterr().out
    assert "kalman" in text and "R2 med" in text
    data = json.loads(out.read_text())
    assert [r["estimator"] for r in data["runs"]] == ["hold", "kalman"]
    assert data["runs"][1]["hidden"] == ["TwHt1ALxt", "TwHt9ALxt", "TwHt1MLyt", "TwHt9MLyt"]
    assert data["runs"] == [by_key(small, "B", e) for e in ("hold", "kalman")]  # same settings, same numbers
    assert "wall_clock" not in data and "traces" not in data  # reproducible by default (--timings adds it)
    # the predictability horizon of band-passed tower-top acceleration: ~1 s (paper 0.8-1 s, README ~1.5 s)
    # computed and reported with its provenance; on 60 s of band-passed tower-top acceleration with sensor noise
    # Rosenstein's estimate is noise-dominated since the 2nd tower mode's content was halved by the rotor's
    # aerodynamic tilt damping (~0.05 s; the estimator warns that the signal is noisy / not low-dimensional)
    assert 0.01 < data["lyapunov"]["time_s"] < 5.0
    assert data["lyapunov"]["source"].startswith("computed")
    figs = sorted(p.name for p in (tmp_path / "figs").glob("*.png"))
    assert figs == ["r2_table.png", "reconstruction_B.png"]


@pytest.mark.parametrize("argv, needle", [
    (["--estimators", "hold,warp"], "unknown estimator 'warp'"),
    (["--scenario", "Z"], "unknown scenario 'Z'"),
    (["--cases", "13"], "cases: n must be a load-case number"),
    (["--seeds", "x"], "--seeds: expected integers"),
    (["--update-interval", "fast"], "--update-interval: expected"),
    (["--train-cases", "1,99"], "train_cases:"),
    (["--option", "dmdrank"], "--option: expected ESTIMATOR.PARAM=VALUE"),
])
def test_cli_bad_input_is_a_one_line_error(argv, needle, capsys):
    assert main(["compare", *CLI_SMALL, "--lyapunov-time", "none", *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_an_unavailable_estimator_is_a_one_line_error(capsys):
    def missing(dt, update_interval, **_):
        from estimators import no_such_module  # noqa: F401

    C.register_estimator("ghost", missing)
    try:
        assert main(["compare", *CLI_SMALL, "--estimators", "hold,ghost", "--lyapunov-time", "none"]) == 2
    finally:
        del C.ESTIMATORS["ghost"]
    err = capsys.readouterr().err
    assert "estimator 'ghost' is not available" in err and len(err.strip().splitlines()) == 1


# ------------------------------------------------------------------------------------------------ slow
@pytest.mark.slow
def test_dmd_accuracy_collapses_beyond_the_lyapunov_time():
    """The seed paper's Lyapunov limit: recalibrating the Hankel-DMD sensor every 4 s instead of every 0.25 s
    loses accuracy on the hidden channels; the Kalman filter, assimilating every sample, does not care."""
    pytest.importorskip("estimators.dmd_sensor")
    settings = C.CompareSettings(train_cases=(1, 6, 11), train_duration=120.0, duration=60.0)
    res = C.compare(["A"], ["dmd", "kalman"], seeds=[SEED], update_intervals=[0.25, 4.0], settings=settings)
    fast, slow = (by_key(res, "A", "dmd", v)["median_r2"] for v in (0.25, 4.0))
    lam = res.lyapunov["time_s"]
    print(f"\ndmd median hidden R2: {fast:.4f} at 0.25 s, {slow:.4f} at 4 s; Lyapunov time {lam:.2f} s")
    # The Lyapunov time itself is no longer in the paper's 0.8-1 s range on this surrogate: since the rotor's
    # aerodynamic tilt damping (issue 15) halved the 2nd tower mode's content, Rosenstein's estimate on 120 s of
    # band-passed tower-top acceleration is ~0.06 s and the estimator warns that the signal is noisy / not
    # low-dimensional. The collapse of the DMD sensor between 0.25 s and 4 s updates is what remains to check.
    assert lam is not None and 0.0 < lam < 4.0
    assert fast > slow + 0.05
    assert by_key(res, "A", "kalman")["median_r2"] > fast
