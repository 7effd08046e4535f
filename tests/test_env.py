"""The Gymnasium environment: API conformance, determinism, faults, virtual-sensor protocol, long episodes."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import fowt_env
import surrogates
from estimators.baseline import HoldLastValue
from fowt_env.faults import Drift, FixedMask, NoiseBurst, RandomDropout, Scenario, Spike, Stuck


@pytest.mark.parametrize("env_id", fowt_env.ENV_IDS)
def test_env_checker_passes_with_warnings_as_errors(env_id):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = gym.make(env_id)
        check_env(env.unwrapped)
        env.close()


def test_rgb_render_and_checker_with_render_mode():
    env = gym.make("fowt_env/Spar-v0", render_mode="rgb_array", plane="FA",
                   faults=FixedMask(["TwHt3ALxt"]))
    env.reset(seed=0)
    env.step(np.zeros(2, dtype=np.float32))
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3 and frame.std() > 0
    env.close()


def rollout(env, seed, n):
    obs, info = env.reset(seed=seed)
    out = [np.concatenate([obs["sensors"], obs["mask"], info["truth"]])]
    for _ in range(n):
        obs, r, term, trunc, info = env.step(np.array([0.1, -0.2], dtype=np.float32))
        out.append(np.concatenate([obs["sensors"], obs["mask"], info["truth"], [r, info["time"]]]))
    return out


def test_same_seed_same_episode_different_seed_differs():
    kw = dict(plane="FA", faults=[RandomDropout(0.1, 1.0), Spike(0.01, 50.0)], max_episode_steps=400)
    a = rollout(gym.make("fowt_env/Spar-v0", **kw), 3, 400)
    b = rollout(gym.make("fowt_env/Spar-v0", **kw), 3, 400)
    c = rollout(gym.make("fowt_env/Spar-v0", **kw), 4, 400)
    assert all(x.tobytes() == y.tobytes() for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c, strict=True))


def test_time_limit_truncates():
    env = gym.make("fowt_env/Spar-v0", max_episode_steps=5)
    env.reset(seed=0)
    flags = [env.step(np.zeros(2, dtype=np.float32))[3] for _ in range(5)]
    assert flags == [False] * 4 + [True]


def test_sync_and_async_vector_envs_agree():
    def make():
        return gym.make("fowt_env/Spar-v0", plane="SS", faults=RandomDropout(0.2, 0.5))

    sync = gym.vector.SyncVectorEnv([make, make])
    asyn = gym.vector.AsyncVectorEnv([make, make])
    try:
        o1, _ = sync.reset(seed=[5, 6])
        o2, _ = asyn.reset(seed=[5, 6])
        for _ in range(50):
            act = np.zeros((2, 2), dtype=np.float32)
            o1, r1, *_ = sync.step(act)
            o2, r2, *_ = asyn.step(act)
            assert np.array_equal(o1["sensors"], o2["sensors"]) and np.array_equal(o1["mask"], o2["mask"])
            assert np.array_equal(r1, r2)
        assert not np.array_equal(o1["sensors"][0], o1["sensors"][1])
    finally:
        sync.close()
        asyn.close()


@pytest.mark.parametrize("bad", [np.array([np.nan, 0.0]), np.array([2.0, 0.0]), np.zeros(3)])
def test_bad_actions_raise(bad):
    env = gym.make("fowt_env/Spar-v0").unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(bad)


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="control_dt"):
        fowt_env.SparEnv(control_dt=0.02)
    with pytest.raises(ValueError, match="case"):
        fowt_env.SparEnv(case=99)
    with pytest.raises(ValueError, match="faults"):
        fowt_env.SparEnv(faults=["not a fault"])
    with pytest.raises(ValueError, match="name"):
        Scenario("D")
    with pytest.raises(ValueError, match="channels"):
        env = fowt_env.SparEnv(plane="FA", faults=FixedMask(["PtfmPitch"]))
        env.reset(seed=0)


# -------------------------------------------------------------------------------------------- faults
def _markov_stats(mask_down: np.ndarray, dt: float) -> tuple[float, float]:
    rate = mask_down.mean()
    lengths = []
    for ch in mask_down.T:
        d = np.diff(np.concatenate([[0], ch.astype(int), [0]]))
        starts, ends = np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]
        lengths.extend((ends - starts) * dt)
    return rate, float(np.mean(lengths))


def test_random_dropout_has_requested_rate_and_burst_length():
    dt = 0.0125
    f = RandomDropout(rate=0.2, mean_burst_s=2.0)
    channels = surrogates.tower_channels("FA")
    f.reset(np.random.default_rng(0), channels, dt)
    n = 200_000  # 2500 s
    down = np.zeros((n, len(channels)), bool)
    y = np.zeros(len(channels))
    for k in range(n):
        m = np.ones(len(channels), bool)
        f.apply(k, y, m)
        down[k] = ~m
    rate, burst = _markov_stats(down, dt)
    assert rate == pytest.approx(0.2, rel=0.10)
    assert burst == pytest.approx(2.0, rel=0.10)


def test_random_dropout_in_the_env():
    env = gym.make("fowt_env/Spar-v0", plane="FA", faults=RandomDropout(0.2, 0.25), max_episode_steps=None)
    obs, _ = env.reset(seed=1)
    masks = [obs["mask"]]
    for _ in range(8000):
        obs, *_ = env.step(np.zeros(2, dtype=np.float32))
        masks.append(obs["mask"])
    rate, burst = _markov_stats(np.array(masks) == 0, 0.0125)
    assert rate == pytest.approx(0.2, rel=0.10)
    assert burst == pytest.approx(0.25, rel=0.10)
    assert np.all(np.array(obs["sensors"])[obs["mask"] == 0] == 0.0)


def test_scenario_a_hides_exactly_the_papers_channels():
    env = gym.make("fowt_env/SparScenarioA-v0")
    obs, info = env.reset(seed=0)
    hidden = set(np.nonzero(obs["mask"] == 0)[0])
    assert hidden == {2, 3, 5, 7, 11, 12, 14, 16}
    assert env.unwrapped.case.name == "OLC5"
    obs, *_ = env.step(np.zeros(2, dtype=np.float32))
    assert set(np.nonzero(obs["mask"] == 0)[0]) == hidden
    for name, hid in (("B", {0, 8, 9, 17}), ("C", {0, 8, 9, 17})):
        obs, _ = gym.make(f"fowt_env/SparScenario{name}-v0").reset(seed=0)
        assert set(np.nonzero(obs["mask"] == 0)[0]) == hid


def test_silent_faults_corrupt_values_but_never_truth():
    ch = "TwHt9ALxt"
    faults = [Stuck([ch], start=0.05), Drift(["TwHt9MLyt"], rate=100.0), NoiseBurst(["TwHt5ALxt"], std=1.0)]
    env = gym.make("fowt_env/Spar-v0", plane="FA", faults=faults, noise=False)
    obs, info = env.reset(seed=2)
    i, j = env.unwrapped.channels.index(ch), env.unwrapped.channels.index("TwHt9MLyt")
    values, truths, drift = [], [], []
    for _ in range(200):
        obs, _, _, _, info = env.step(np.zeros(2, dtype=np.float32))
        values.append(obs["sensors"][i])
        truths.append(info["truth"][i])
        drift.append(obs["sensors"][j] - info["truth"][j])
        assert obs["mask"].all()  # silent faults keep the mask
    assert np.ptp(values[10:]) == 0.0 and np.ptp(truths[10:]) > 0.0
    assert drift[-1] == pytest.approx(100.0 * (200 * 0.0125 + 0.0125), rel=0.02)


# ----------------------------------------------------------------------------------- virtual sensors
def test_virtual_sensor_wrapper_with_hold_last_value():
    base = gym.make("fowt_env/Spar-v0", plane="FA", faults=RandomDropout(0.3, 0.5), noise=False)
    env = fowt_env.VirtualSensorWrapper(base, HoldLastValue())
    obs, info = env.reset(seed=4)
    assert "estimate" in obs and env.observation_space.contains(obs)
    for _ in range(300):
        obs, _, _, _, info = env.step(np.zeros(2, dtype=np.float32))
        live = obs["mask"].astype(bool)
        # live channels pass through unchanged; lost ones hold a previous value
        np.testing.assert_allclose(obs["estimate"][live], obs["sensors"][live])
        assert np.allclose(info["estimation_error"][live], 0.0, atol=1e-9)
    assert np.isfinite(info["estimation_rmse_live"])


def test_wrapper_rejects_non_sensors():
    with pytest.raises(ValueError, match="virtual-sensor protocol"):
        fowt_env.VirtualSensorWrapper(gym.make("fowt_env/Spar-v0"), object())


# ----------------------------------------------------------------------------------- long episodes
def test_reset_mid_episode_and_changing_faults():
    env = gym.make("fowt_env/Spar-v0", plane="FA", max_episode_steps=None)
    env.reset(seed=0)
    for _ in range(100):
        env.step(np.zeros(2, dtype=np.float32))
    obs, _ = env.reset(seed=0, options={"faults": [Scenario("B")]})
    assert set(np.nonzero(obs["mask"] == 0)[0]) == {0, 8, 9, 17}
    obs, _ = env.reset(seed=0, options={"faults": None})
    assert obs["mask"].all()


@pytest.mark.slow
def test_24_hours_in_one_episode_memory_flat_and_finite():
    env = fowt_env.SparEnv(case=10, dt=0.05, control_dt=5.0, plane="FA", faults=RandomDropout(0.1, 2.0))
    env.reset(seed=7)
    steps_per_hour = int(3600 / 5.0)
    rss = []
    for _hour in range(24):
        for _ in range(steps_per_hour):
            obs, r, term, trunc, info = env.step(np.zeros(2, dtype=np.float32))
            assert np.all(np.isfinite(obs["sensors"])) and np.isfinite(r) and not term
        rss.append(_resident_bytes())
    assert env._sim.time == pytest.approx(24 * 3600.0)
    # resident memory does not grow: the last 12 hours peak within 20 MB of the first 4 hours' peak (one forcing
    # chunk is ~10 MB; the level alternates by that much as chunks are replaced, and an early low reading --
    # 61 MB under the rest after the allocator returned pages -- is no baseline)
    assert max(rss[12:]) - max(rss[:4]) < 20e6, np.diff(rss)


def _resident_bytes() -> int:
    import os

    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_terminates_on_extreme_platform_pitch():
    env = gym.make("fowt_env/Spar-v0", max_pitch_deg=1.0)  # the mean pitch at rated wind is ~4 deg
    env.reset(seed=0)
    _, reward, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
    assert terminated and not truncated and abs(info["platform_pitch_deg"]) > 1.0


def test_control_dt_holds_actions_for_several_samples():
    env = fowt_env.SparEnv(control_dt=0.25)
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(2, dtype=np.float32))
    assert env.control_steps == 20 and info["time"] == pytest.approx(0.25 + 0.0125)
