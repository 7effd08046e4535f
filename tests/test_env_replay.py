"""SparEnv(replay=...): episodes driven by measured waves and wind, streamed chunk by chunk (issue 16)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import surrogates
from fowt_env.env import SparEnv
from fowt_env.replay import record_case
from fowt_env.replay_stream import NpzSeries, ReplaySource
from surrogates.channels import ALL_CHANNELS, tower_channels
from surrogates.model import INPUT_BLOCKS
from surrogates.replay import MeasuredWaves, MeasuredWind, replay_forcing
from surrogates.replay_stream import SEAM_TOLERANCE, ArraySeries, ReplayForcing, StreamedWaves, StreamedWind
from surrogates.simulate import N_BLADE_COLUMNS

DT_REC = 0.05  # s, the synthetic measurement's sample time


def _measured(duration: float, seed: int = 1, t0: float = 0.0) -> surrogates.Record:
    """A synthetic measurement: JONSWAP elevation (Hs 5 m, Tp 10 s) and Kaimal hub wind (12 m/s, TI 0.12)."""
    w = surrogates.waves.synthesize_waves(5.0, 10.0, 3.3, 0.0, duration, DT_REC, seed=seed)
    n = w.elevation.size
    hub = surrogates.wind.synthesize_wind(12.0, 0.12, duration, DT_REC, seed=seed + 1).hub[:n]
    t = t0 + np.arange(n) * DT_REC
    return surrogates.Record(t, np.column_stack([w.elevation + 0.1, hub]), ["Wave1Elev", "Wind1VelX"], ["m", "m/s"])


@pytest.fixture(scope="module")
def record_file(tmp_path_factory):
    rec = _measured(400.0)
    path = tmp_path_factory.mktemp("replay") / "run.npz"
    rec.save(path)
    return rec, path


@pytest.fixture(scope="module")
def replay_env(record_file):
    _, path = record_file
    return SparEnv(replay=path, dt=0.05, noise=False, warmup_seconds=20.0, plane="FA")


def test_chunked_forcing_matches_the_whole_record_transform_across_seams(record_file, replay_env):
    rec, _ = record_file
    sim = replay_env._sim.sim  # the record's load case, dt 0.05 s
    n_steps = int(390.0 / sim.dt_int)
    u_w, v_w, _, _ = replay_forcing(sim, n_steps, 0.0, MeasuredWaves.from_record(rec), MeasuredWind.from_record(rec),
                                    np.random.SeedSequence(0))
    series = ArraySeries(0.0, DT_REC, np.column_stack([rec["Wave1Elev"], rec["Wind1VelX"]]))
    forcing = ReplayForcing(sim, StreamedWaves(series, 0), StreamedWind(series, "hub", hub_column=1))
    chunk = int(80.0 / sim.dt_int)  # four seams
    parts_u, parts_v = [], []
    for k0 in range(0, n_steps, chunk):
        u, v, blade = forcing(k0, chunk)
        assert u.shape[0] == chunk + 1 and blade.shape == (0, N_BLADE_COLUMNS)
        parts_u.append(u[:chunk])
        parts_v.append(v[:chunk])
    u_c = np.concatenate(parts_u)[: n_steps + 1]
    v_c = np.concatenate(parts_v)[: n_steps + 1]
    for name in ("elev", "wave", "wind"):
        cols = INPUT_BLOCKS[name]
        ref = u_w[:, cols].reshape(len(u_w), -1)
        got = u_c[:, cols].reshape(len(u_c), -1)
        scale = np.where(ref.std(axis=0) > 0, ref.std(axis=0), 1.0)
        assert np.max(np.abs(got - ref) / scale) < SEAM_TOLERANCE, name
    scale = v_w[..., 0].std(axis=0)
    assert np.max(np.abs(v_c[..., 0] - v_w[..., 0]) / scale) < SEAM_TOLERANCE  # the deep strips included


@pytest.mark.slow
def test_streaming_simulator_replay_equals_simulate_through_chunk_seams():
    """The chunked stream and one ``simulate`` start 3e-5 of a channel's std apart (measured: both paths, both
    effects off or on). With the flexible blades' effects together the record's blade pitch touches fine pitch at
    20-60 s, where the torque law's region switch amplifies that into 1.7e-3 of ``TwHt1MLyt``'s std, which then
    decays; with either of them off the paths stay within 2.3e-5. The seams are compared without
    ``blade_deflection``, away from the switch."""
    rec = _measured(400.0)
    lc = record_case(rec)
    model = surrogates.FOWTModel().with_effects(blade_deflection=0.0)
    stream = surrogates.StreamingSimulator(model, lc, 0.05, chunk_seconds=100.0, warmup_seconds=20.0)
    stream.forcing = ReplaySource(rec).forcing(stream.sim)
    stream.reset(seed=4)
    _, truth = stream.advance(int(300.0 / 0.05), np.zeros(2), noise=False)
    ref = surrogates.simulate(model, lc, 300.0, 0.05, transient=20.0, noise=False, waves=rec, wind=rec,
                              initial={"Azimuth": float(np.rad2deg(stream.psi_start))})
    for ch in ("TwHt1MLyt", "TwHt9ALxt", "PtfmPitch", "PtfmSurge", "RotSpeed", "BldPitch1"):
        i = ALL_CHANNELS.index(ch)
        assert np.max(np.abs(truth[:, i] - ref.y[:, i])) < 1e-3 * np.std(ref.y[:, i]), ch


def test_replayed_episode_reproduces_simulate_on_the_same_file(record_file, replay_env):
    rec, _ = record_file
    env = replay_env
    assert env.case == record_case(rec)
    obs, info = env.reset(seed=2)
    assert info["replay_time"] == pytest.approx(20.05)
    rows = [info["truth"]]
    for _ in range(2000):  # 100 s
        obs, _, terminated, truncated, info = env.step(np.zeros(2))
        rows.append(info["truth"])
        assert not (terminated or truncated)
    got = np.array(rows)
    ref = surrogates.simulate(env.model, env.case, 120.0, 0.05, transient=20.0, noise=False, waves=rec, wind=rec,
                              initial={"Azimuth": float(np.rad2deg(env._sim.psi_start))})
    want = ref.select(tower_channels("FA")).y[: got.shape[0]]  # info["truth"] is the step's last sample
    # the streamed forcing differs from the whole-record one at the 1e-5 level (seams: the test above); where the
    # controller switches region (generator torque reaching its region-3 value, as at ~60 s of this record) a
    # difference that small grows to a few 1e-4 of the channels' std, no more
    assert np.max(np.abs(got - want) / want.std(axis=0)) < 1e-3


def test_the_episode_ends_with_the_inputs_and_restarts_from_replay_start(replay_env):
    env = replay_env
    obs0, info = env.reset(seed=0, options={"replay_start": 250.0})
    assert info["replay_time"] == pytest.approx(270.05)
    steps = 0
    truncated = False
    while not truncated:
        _, _, terminated, truncated, info = env.step(np.zeros(2))
        steps += 1
        assert not terminated
    # 399.95 s is the last input sample; the hold of the last internal step needs it
    assert 399.95 - 0.05 < info["replay_time"] <= 399.95 + 1e-9
    assert steps == round((info["replay_time"] - 270.05) / 0.05)
    with pytest.raises(gym.error.ResetNeeded, match="replayed inputs ended"):
        env.step(np.zeros(2))
    obs1, _ = env.reset(seed=0, options={"replay_start": 250.0})
    np.testing.assert_array_equal(obs0["sensors"], obs1["sensors"])
    _, info = env.reset(seed=0)
    assert info["replay_time"] == pytest.approx(20.05)
    with pytest.raises(ValueError, match="replay_start=-1"):
        env.reset(options={"replay_start": -1.0})


@pytest.mark.slow
def test_a_record_in_memory_and_an_explicit_load_case(record_file):
    rec, _ = record_file
    lc = surrogates.load_case(7).replace(hs=4.0, tp=9.0, wind_speed=12.0, name="mine")
    env = SparEnv(replay=rec, case=lc, noise=False, warmup_seconds=5.0)
    assert env.case is lc
    env.reset(seed=0)
    env.step(np.zeros(2))



def test_npz_series_reads_windows_forward_and_back(record_file):
    rec, path = record_file
    series = NpzSeries(path, [("y", [1, 0])], 0.0, DT_REC)
    want = np.column_stack([rec["Wind1VelX"], rec["Wave1Elev"]])
    np.testing.assert_array_equal(series.read(100, 5000), want[100:5000])
    np.testing.assert_array_equal(series.read(4000, 6000), want[4000:6000])  # overlaps the kept window
    np.testing.assert_array_equal(series.read(10, 20), want[10:20])  # back: reopens the stream
    series.close()


def _save(tmp_path, t, cols, names, name="bad.npz"):
    path = tmp_path / name
    surrogates.Record(t, np.column_stack(cols), names, ["m"] * len(names)).save(path)
    return path


@pytest.mark.parametrize("where", ["file", "memory"])
def test_bad_inputs_get_clear_errors(tmp_path, where):
    t = np.arange(0.0, 100.0, 0.1)
    eta, wind = np.sin(t), 11.0 + 0.0 * t

    def make(tt, cols, names):
        rec = surrogates.Record(tt, np.column_stack(cols), names, ["m"] * len(names))
        if where == "memory":
            return ReplaySource(rec)
        return ReplaySource(_save(tmp_path, tt, cols, names))

    with pytest.raises(ValueError, match="no Wave1Elev channel"):
        make(t, [wind], ["Wind1VelX"])
    with pytest.raises(ValueError, match="no Wind1VelX channel"):
        make(t, [eta], ["Wave1Elev"])
    with pytest.raises(ValueError, match="shorter than 20 s"):
        make(t[:100], [eta[:100], wind[:100]], ["Wave1Elev", "Wind1VelX"])
    bad = eta.copy()
    bad[503] = np.nan
    with pytest.raises(ValueError, match=r"Wave1Elev has a non-finite sample \(NaN/inf\) at t = 50.3 s"):
        make(t, [bad, wind], ["Wave1Elev", "Wind1VelX"])
    tt = t.copy()
    tt[700:] += 0.05
    with pytest.raises(ValueError, match="time axis is not regular .* at t = 69.9 s"):
        make(tt, [eta, wind], ["Wave1Elev", "Wind1VelX"])
    with pytest.raises(ValueError, match="mean wind > 0"):
        make(t, [eta, 0.0 * t], ["Wave1Elev", "Wind1VelX"])


def test_bad_replay_arguments(record_file, tmp_path):
    rec, path = record_file
    with pytest.raises(ValueError, match="replay_start=390"):
        SparEnv(replay=path, replay_start=390.0)
    with pytest.raises(ValueError, match="replay_start must be finite"):
        SparEnv(replay=path, replay_start=float("nan"))
    with pytest.raises(ValueError, match="load case is the record's"):
        SparEnv(replay=rec, case=3)
    with pytest.raises(ValueError, match="replay must be a record file path"):
        SparEnv(replay=42)
    with pytest.raises(ValueError, match="is not a file"):
        SparEnv(replay=tmp_path / "missing.npz")
    other = tmp_path / "other.npz"
    np.savez(other, t=np.arange(3.0))
    with pytest.raises(ValueError, match="not an inflow file"):
        SparEnv(replay=path, replay_wind=other)
    with pytest.raises(ValueError, match="not a record file"):
        SparEnv(replay=other)


@pytest.mark.slow
def test_a_polar_inflow_file_is_streamed_as_the_field_wind(record_file, tmp_path):
    rec, path = record_file
    t = np.arange(0.0, 400.0, 0.2)
    radii = np.array([0.0, 30.0, 63.0])
    az = np.arange(8) * 2 * np.pi / 8
    rng = np.random.default_rng(0)
    polar = (12.0 + 0.5 * np.sin(0.05 * t)[:, None, None] + 0.3 * rng.standard_normal((t.size, 3, 8)))
    polar[:, 0, :] = polar[:, 0, :1]
    hub = np.column_stack([polar[:, 0, 0], 0 * t, 0 * t])
    inflow = tmp_path / "run.inflow.npz"
    np.savez(inflow, t=t, hub_uvw=hub, polar_u=polar.astype(np.float16), polar_radii=radii, polar_azimuth_rad=az,
             disc_mean_u=polar.mean(axis=(1, 2)))
    src = ReplaySource(path, wind=inflow)
    assert src.wind.level == "field"
    sim = surrogates.Simulator(surrogates.FOWTModel(), src.case, 0.0125)
    n_steps = int(300.0 / sim.dt_int)
    u_w, _, _, b_w = replay_forcing(sim, n_steps, 0.0, MeasuredWaves.from_record(rec), MeasuredWind.from_inflow(inflow),
                                    np.random.SeedSequence(0))
    forcing = src.forcing(sim)
    u_c, _, b_c = forcing(0, n_steps)
    for name in ("wind", "hub_wind", "shear"):
        np.testing.assert_allclose(u_c[:, INPUT_BLOCKS[name]], u_w[:, INPUT_BLOCKS[name]], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(b_c, b_w)


@pytest.mark.slow
def test_replayed_forcing_from_a_file_keeps_flat_memory(tmp_path):
    """Peak of the allocations while streaming 3 h of inputs equals that of 40 min (the file is never held)."""
    import tracemalloc

    peaks = {}
    for minutes in (40, 180):
        path = tmp_path / f"in_{minutes}.npz"
        _measured(minutes * 60.0, seed=3).save(path)
        src = ReplaySource(path)
        sim = surrogates.Simulator(surrogates.FOWTModel(), src.case, 0.05)
        forcing = src.forcing(sim)
        chunk = int(600.0 / sim.dt_int)
        forcing(0, chunk)  # transfer functions cached, as in an episode
        tracemalloc.start()
        for k0 in range(chunk, forcing.steps_available - chunk, chunk):
            forcing(k0, chunk)
        peaks[minutes] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        src.close()
    assert peaks[180] < 1.1 * peaks[40]  # measured 27.3 MiB for both
    assert peaks[180] < 200 * 2**20  # bytes: a 600 s window's arrays, not the 3 h record's


def test_an_inflow_file_beside_the_record_is_the_default_wind(record_file, tmp_path):
    rec, _ = record_file
    path = tmp_path / "run.npz"
    rec.save(path)
    t = np.arange(0.0, 400.0, 0.2)
    polar = np.full((t.size, 2, 4), 12.0, dtype=np.float16)
    np.savez(tmp_path / "run.inflow.npz", t=t, hub_uvw=np.column_stack([12.0 + 0 * t, 0 * t, 0 * t]), polar_u=polar,
             polar_radii=np.array([0.0, 63.0]), polar_azimuth_rad=np.arange(4) * np.pi / 2)
    assert ReplaySource(path).wind.level == "field"
    assert ReplaySource(path, wind="record").wind.level == "hub"
    assert ReplaySource(rec).wind.level == "hub"
