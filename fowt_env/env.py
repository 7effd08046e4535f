"""``SparEnv``: the OC3 Hywind surrogate as a Gymnasium environment with sensor faults."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

import surrogates
from surrogates.channels import ALL_CHANNELS, GAUGE_HEIGHTS, tower_channels

from .faults import Fault, as_fault_list

__all__ = ["SparEnv", "RewardConfig"]

RATED_POWER = 5.0e6  # W, NREL 5 MW
SENSOR_RANGE = {"acc": 50.0, "moment": 1.0e6}  # full scale: m/s^2 (about 5 g), kN m (1000 MN m)
GENERATOR_EFFICIENCY = 0.944


@dataclass(frozen=True)
class RewardConfig:
    """Weights and scales of the default load-mitigation reward.

    ``reward = -(moment_weight * ((M - M_ref) / moment_scale)**2 + power_weight * ((P - P_rated) / power_scale)**2
    + action_weight * |a|**2)`` per step, with ``M`` the tower-base fore-aft bending moment ``TwHt1MLyt`` (kN·m,
    noise free), ``M_ref`` its value at the load case's static operating point, ``P`` the electrical power (W)
    and ``a`` the normalised action.

    Attributes
    ----------
    moment_weight, power_weight, action_weight : float
        Weights (-).
    moment_scale : float
        Moment normalisation (kN·m).
    power_scale : float
        Power normalisation (W).
    """

    moment_weight: float = 1.0
    power_weight: float = 1.0
    action_weight: float = 0.0
    moment_scale: float = 2.0e4
    power_scale: float = 1.0e6


class SparEnv(gym.Env):
    """NREL 5 MW on the OC3 Hywind spar: tower sensors under waves, turbulence and sensor faults.

    Description
    -----------
    A reduced aero-hydro-servo-elastic surrogate (:mod:`surrogates`) of the floating turbine runs under an
    operational load case (JONSWAP waves, Kaimal turbulence, 1P/3P rotor forcing). The agent observes the tower
    accelerometers and strain gauges at nine heights -- some of which may be lost or faulty -- and may add
    collective blade-pitch and generator-torque offsets to the baseline controller. With zero actions the
    turbine runs on its baseline controller, so estimator studies can ignore actions altogether.

    Action Space
    ------------
    ``Box(-1, 1, (2,), float32)``: ``[pitch, torque]`` offsets normalised by ``max_pitch_offset_deg`` (default
    5 deg of collective pitch) and ``max_torque_offset`` (default 4e5 N·m on the low-speed shaft, ~10 % of
    rated). Non-finite or out-of-range actions raise ``ValueError``.

    Observation Space
    -----------------
    ``Dict(sensors=Box(-range, range, (n,), float64), mask=MultiBinary(n))`` with n = 18 (``plane="FA"`` or
    ``"SS"``: accelerations at gauges 1-9, then bending moments at gauges 1-9) or 36 (``plane=None``). Units are
    OpenFAST's (m/s², kN·m); readings saturate at the full-scale range (50 m/s², 1e6 kN·m). A lost channel
    reads 0.0 in ``sensors`` and 0 in ``mask``; no NaN ever appears.
    Silent faults (stuck, spikes, drift, noise bursts) keep ``mask`` at 1.

    Rewards
    -------
    Load mitigation by default, see :class:`RewardConfig`: minus the squared, normalised fluctuation of the
    tower-base fore-aft bending moment and deviation of electrical power from rated. Pass ``reward_fn(env,
    truth, action) -> float`` to replace it.

    Starting State
    --------------
    The static equilibrium under the mean loads, followed by ``warmup_seconds`` of simulation under the
    episode's own random waves and wind (seeded by ``reset(seed=...)``).

    Episode End
    -----------
    Truncation through the registration's ``max_episode_steps`` (600 s at the default dt) or
    ``episode_seconds`` if given, and with ``replay`` at the last step the measured inputs cover (a further
    :meth:`step` raises ``gymnasium.error.ResetNeeded``). Termination on physical failure: a non-finite state or
    platform pitch beyond ``max_pitch_deg`` (default 15 deg).

    Arguments
    ---------
    case : int or LoadCase, default 7
        Load case (OLC 1-12 of the seed paper, or a custom :class:`surrogates.LoadCase`).
    model : FOWTModel, optional
        The surrogate (default: all effects at nominal strength).
    dt : float, default 0.0125
        Sensor sample time (s).
    control_dt : float, optional
        An action is held this long (s), a multiple of dt (default dt); one step spans control_dt.
    plane : {"FA", "SS", None}, default None
        Observed tower channels.
    faults : Fault or list of Fault, optional
        Sensor faults (:mod:`fowt_env.faults`), applied in order, seeded from the env's ``np_random``.
    episode_seconds : float, optional
        Truncate after this much simulated time.
    render_mode : {"rgb_array", "human", None}
    noise : bool, default True
        Sensor noise from the model's :class:`surrogates.SensorNoise`.
    reward : RewardConfig, optional
    reward_fn : callable, optional
    max_pitch_offset_deg, max_torque_offset, max_pitch_deg, warmup_seconds : float
        Action scaling (deg, N·m), termination threshold (deg) and warm-up (s). Every argument is checked when
        the environment is made (finite, sign, range, and the memory a sample step and warm-up imply: at most
        :data:`MAX_STEP_SAMPLES` samples per forcing chunk, warm-up or control step); a bad one raises a
        ``ValueError`` naming it. :meth:`step` before :meth:`reset` raises ``gymnasium.error.ResetNeeded``.
    replay : path, surrogates.Record or fowt_env.replay_stream.ReplaySource, optional
        Replay measured conditions instead of random waves and wind: every episode is driven by the record's
        ``Wave1Elev`` and wind (:class:`fowt_env.replay_stream.ReplaySource`; a ``.npz`` record file is read
        chunk by chunk, so a day-long episode keeps flat memory) from ``replay_start``, the warm-up included,
        and is truncated when the inputs run out. The load case is the record's (``case.json`` beside it, else
        estimated); a :class:`surrogates.LoadCase` given as ``case`` overrides it, a load-case number other than
        the default is refused. ``info["replay_time"]`` is the time on the inputs' own axis (s). Use the class
        directly (or ``gymnasium.make(..., max_episode_steps=N)``): the registration truncates at 600 s.
    replay_wind : None, "record", path or MeasuredWind
        The replayed wind (``ReplaySource``'s ``wind``): default an ``<run>.inflow.npz`` beside the record, else
        its ``Wind1VelX``.
    replay_start : float, default 0
        Offset (s) into the inputs where each episode's warm-up starts; ``reset(options={"replay_start": s})``
        changes it for that episode.

    Examples
    --------
    >>> import gymnasium as gym, fowt_env
    >>> env = gym.make("fowt_env/Spar-v0", plane="FA", faults=fowt_env.faults.Scenario("A"))
    >>> obs, info = env.reset(seed=0)
    >>> obs["sensors"].shape, int(obs["mask"].sum())
    ((18,), 10)
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}

    def __init__(
        self,
        case: int | surrogates.LoadCase = 7,
        model: surrogates.FOWTModel | None = None,
        dt: float = 0.0125,
        control_dt: float | None = None,
        plane: str | None = None,
        faults: Fault | list[Fault] | None = None,
        episode_seconds: float | None = None,
        render_mode: str | None = None,
        noise: bool = True,
        reward: RewardConfig | None = None,
        reward_fn=None,
        max_pitch_offset_deg: float = 5.0,
        max_torque_offset: float = 4.0e5,
        max_pitch_deg: float = 15.0,
        warmup_seconds: float = 30.0,
        replay: Any = None,
        replay_wind: Any = None,
        replay_start: float = 0.0,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']} or None, got {render_mode!r}")
        _check_arguments(dt=dt, control_dt=control_dt, episode_seconds=episode_seconds, noise=noise,
                         max_pitch_offset_deg=max_pitch_offset_deg, max_torque_offset=max_torque_offset,
                         max_pitch_deg=max_pitch_deg, warmup_seconds=warmup_seconds, case=case,
                         reward=reward, reward_fn=reward_fn)
        self.model = model if model is not None else surrogates.FOWTModel()
        if not isinstance(self.model, surrogates.FOWTModel):
            raise ValueError(f"model must be a surrogates.FOWTModel, got {type(self.model).__name__}")
        if isinstance(case, surrogates.LoadCase):
            self.case = case
        else:
            try:
                self.case = surrogates.load_case(int(case))
            except (TypeError, ValueError) as exc:
                raise ValueError(f"case: {exc}") from exc
        self._replay = None
        if replay is not None:  # measured conditions: the record's load case and its forcing, chunk by chunk
            from .replay_stream import ReplaySource

            if not isinstance(case, surrogates.LoadCase) and int(case) != 7:
                raise ValueError("case: with replay= the load case is the record's; pass a surrogates.LoadCase to "
                                 f"override it, not the load-case number {case!r}")
            override = case if isinstance(case, surrogates.LoadCase) else None
            self._replay = replay if isinstance(replay, ReplaySource) else ReplaySource(
                replay, wind=replay_wind, case=override)
            self.case = override if override is not None else self._replay.case
            self.replay_start = self._replay_start(replay_start, (round(warmup_seconds / dt) + 2) * dt)
        self._sim = surrogates.StreamingSimulator(self.model, self.case, dt, warmup_seconds=warmup_seconds)
        if self._replay is not None:
            self._sim.forcing = self._replay.forcing(self._sim.sim)
        self.dt = self._sim.dt
        control_dt = self.dt if control_dt is None else float(control_dt)
        ratio = control_dt / self.dt
        if not np.isfinite(ratio) or ratio < 1 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
            raise ValueError(f"control_dt must be a positive multiple of dt={self.dt}, got {control_dt!r}")
        self.control_steps = int(round(ratio))
        self.control_dt = self.control_steps * self.dt
        self.channels = list(ALL_CHANNELS[:36]) if plane is None else tower_channels(plane)
        self.plane = plane
        self._idx = np.array([ALL_CHANNELS.index(c) for c in self.channels])
        self._i_moment = ALL_CHANNELS.index("TwHt1MLyt")
        self._i_pitch = ALL_CHANNELS.index("PtfmPitch")
        self._i_rpm = ALL_CHANNELS.index("RotSpeed")
        self.faults = as_fault_list(faults)
        if episode_seconds is not None and (not np.isfinite(episode_seconds) or episode_seconds <= 0):
            raise ValueError(f"episode_seconds must be positive and finite, got {episode_seconds!r}")
        self.episode_seconds = episode_seconds
        self.render_mode = render_mode
        self.noise = bool(noise)
        self.reward_config = reward if reward is not None else RewardConfig()
        self.reward_fn = reward_fn
        self.max_pitch_offset = np.deg2rad(float(max_pitch_offset_deg))
        self.max_torque_offset = float(max_torque_offset)
        self.max_pitch_deg = float(max_pitch_deg)
        n = len(self.channels)
        # sensor full-scale ranges: readings saturate there, like a real sensor's (and the bounds are finite)
        self.sensor_range = np.array([SENSOR_RANGE["acc"] if "AL" in c else SENSOR_RANGE["moment"]
                                      for c in self.channels])
        self._range_lo = -self.sensor_range
        self.observation_space = spaces.Dict(
            {
                "sensors": spaces.Box(-self.sensor_range, self.sensor_range, shape=(n,), dtype=np.float64),
                "mask": spaces.MultiBinary(n),
            }
        )
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        sysm = self._sim.sim.system
        y_eq = sysm.C @ self._sim.sim.x_eq + sysm.D[:, 0]
        self._moment_ref = float(y_eq[self._i_moment])
        op = sysm.op
        self._gen_torque0 = op.generator_torque_lss if op is not None else 0.0
        self._step = 0
        self._sample = 0
        self._last: dict[str, Any] = {}
        self._fig = None

    # ---------------------------------------------------------------------------------------------- helpers
    def _measure(self, noisy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Apply the faults sample by sample; return the last measured vector and mask (observed channels)."""
        if not self.faults:
            self._sample += noisy.shape[0]
            y = noisy[-1, self._idx]
            mask = np.isfinite(y)
            return np.where(mask, y, 0.0), mask
        y = mask = None
        for row in noisy:
            y = row[self._idx].copy()
            mask = np.ones(len(self.channels), dtype=bool)
            for f in self.faults:
                f.apply(self._sample, y, mask)
            self._sample += 1
        assert y is not None and mask is not None
        mask &= np.isfinite(y)
        return np.where(mask, y, 0.0), mask

    def _obs(self, y: np.ndarray, mask: np.ndarray) -> dict[str, np.ndarray]:
        # np.clip's bounds, without its wrappers (y is finite float64: _measure zeroes what is not finite)
        sensors = np.minimum(np.maximum(y, self._range_lo), self.sensor_range)
        return {"sensors": sensors, "mask": mask.astype(np.int8)}

    def _physical_action(self, action) -> tuple[np.ndarray, np.ndarray]:
        """Physical offsets ``[pitch (rad), torque (N·m)]`` and the checked normalised action (float64)."""
        raw = action if isinstance(action, np.ndarray) else np.asarray(action)
        if raw.dtype.kind == "f" and raw.shape == (2,):  # the usual float32/float64 action: no general checks
            a = raw.astype(float)
            a0, a1 = a.tolist()
            if not (math.isfinite(a0) and math.isfinite(a1)):
                raise ValueError(f"action must be finite, got {a}")
            if abs(a0) > 1.0 + 1e-6 or abs(a1) > 1.0 + 1e-6:
                raise ValueError(f"action must lie in [-1, 1] (normalised pitch and torque offsets), got {a}")
            return np.array([a0 * self.max_pitch_offset, a1 * self.max_torque_offset]), a
        if np.iscomplexobj(raw):
            raise TypeError(f"action must be real [pitch, torque] in [-1, 1], got complex values: {_shown(action)}")
        try:
            a = np.asarray(raw, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"action must be two real numbers [pitch, torque] in [-1, 1], got {_shown(action)}"
                            ) from None
        if a.shape != (2,):
            raise ValueError(f"action must have shape (2,) [pitch, torque], got {a.shape}")
        a0, a1 = float(a[0]), float(a[1])
        if not (math.isfinite(a0) and math.isfinite(a1)):
            raise ValueError(f"action must be finite, got {a}")
        if abs(a0) > 1.0 + 1e-6 or abs(a1) > 1.0 + 1e-6:
            raise ValueError(f"action must lie in [-1, 1] (normalised pitch and torque offsets), got {a}")
        return np.array([a0 * self.max_pitch_offset, a1 * self.max_torque_offset]), a

    def electrical_power(self, truth: np.ndarray, torque_offset: float) -> float:
        """Electrical power (W) from rotor speed and generator torque (baseline + offset)."""
        omega = truth[self._i_rpm] * np.pi / 30.0
        return float(GENERATOR_EFFICIENCY * (self._gen_torque0 + torque_offset) * omega)

    def _replay_start(self, offset: object, need: float | None = None) -> float:
        """A checked ``replay_start`` (s into the inputs): the inputs must cover the warm-up and a step from it
        (``need`` s, default the simulator's warm-up and two samples)."""
        assert self._replay is not None
        start = _real("replay_start", offset)
        span = self._replay.t_end - self._replay.t_begin
        need = (self._sim.warmup + 2) * self._sim.dt if need is None else need
        if start < 0 or start + need > span:
            raise ValueError(f"replay_start={offset!r} s: the inputs cover {span:g} s, and an episode needs the "
                             f"warm-up and a step ({need:g} s) after its start (0 <= replay_start <= "
                             f"{max(span - need, 0):g})")
        return start

    # -------------------------------------------------------------------------------------------- Gym API
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start an episode. ``options`` may hold ``faults`` (a new fault list for this and later episodes)."""
        super().reset(seed=seed)
        if options and "faults" in options:
            self.faults = as_fault_list(options["faults"])
        seed_int = int(self.np_random.integers(0, 2**63 - 1))
        if self._replay is not None:  # every episode replays the inputs from its start
            start = self.replay_start if not options or "replay_start" not in options else self._replay_start(
                options["replay_start"])
            self._replay.restart()
            self._sim.forcing.start(self._replay.t_begin + start)
            self._replay_t0 = self._replay.t_begin + start + self._sim.warmup * self.dt
        self._sim.reset(np.random.SeedSequence(seed_int))
        for f in self.faults:
            f.reset(np.random.default_rng(int(self.np_random.integers(0, 2**63 - 1))), self.channels, self.dt)
        self._step = 0
        self._sample = 0
        noisy, truth = self._sim.advance(1, np.zeros(2), noise=self.noise)
        y, mask = self._measure(noisy)
        info = {"truth": truth[-1, self._idx].copy(), "time": self._sim.time, "channels": list(self.channels)}
        if self._replay is not None:
            info["replay_time"] = self._replay_t0 + self._sim.time
        self._last = {"truth_all": truth[-1], "y": y, "mask": mask, "estimate": None}
        if self.render_mode == "human":
            self.render()
        return self._obs(y, mask), info

    def step(self, action):
        if "truth_all" not in self._last:
            raise gym.error.ResetNeeded("SparEnv.step() before reset(): call env.reset(seed=...) to start an "
                                        "episode first")
        act_phys, a = self._physical_action(action)
        if self._replay is not None and self._sim.steps_left < self.control_steps * self._sim.substeps:
            raise gym.error.ResetNeeded(f"the replayed inputs ended at t = {self._replay_t0 + self._sim.time:g} s "
                                        "(the episode was truncated there): call env.reset()")
        noisy, truth = self._sim.advance(self.control_steps, act_phys, noise=self.noise)
        self._step += 1
        last = truth[-1]
        finite = math.isfinite(np.add.reduce(last)) and math.isfinite(np.add.reduce(self._sim.x))
        if not finite:
            noisy = np.nan_to_num(noisy, nan=0.0, posinf=0.0, neginf=0.0)
            last = np.nan_to_num(last, nan=0.0, posinf=0.0, neginf=0.0)
        y, mask = self._measure(noisy)
        terminated = (not finite) or abs(last[self._i_pitch]) > self.max_pitch_deg
        truncated = self.episode_seconds is not None and self._sim.time >= self.episode_seconds - 1e-9
        power = self.electrical_power(last, act_phys[1]) if finite else 0.0
        if self.reward_fn is not None:
            reward = float(self.reward_fn(self, last, a))
        elif finite:
            rc = self.reward_config
            reward = -float(
                rc.moment_weight * ((last[self._i_moment] - self._moment_ref) / rc.moment_scale) ** 2
                + rc.power_weight * ((power - RATED_POWER) / rc.power_scale) ** 2
                + rc.action_weight * float(a @ a)
            )
        else:
            reward = -1e3
        info = {
            "truth": last[self._idx],
            "time": self._sim.time,
            "power": power,
            "platform_pitch_deg": float(last[self._i_pitch]),
        }
        if self._replay is not None:  # the episode ends with the measured inputs
            truncated = truncated or self._sim.steps_left < self.control_steps * self._sim.substeps
            info["replay_time"] = self._replay_t0 + self._sim.time
        self._last = {"truth_all": last, "y": y, "mask": mask, "estimate": self._last.get("estimate")}
        if self.render_mode == "human":
            self.render()
        return self._obs(y, mask), reward, bool(terminated), bool(truncated), info

    def render(self):
        """Tower deflection, platform attitude, live/dropped sensors, and estimates if a wrapper set them."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array' or 'human'")
            return None
        from .render import render_frame

        frame, self._fig = render_frame(self, self._fig, interactive=self.render_mode == "human")
        return frame if self.render_mode == "rgb_array" else None

    def close(self):
        if self._fig is not None:
            import matplotlib.pyplot as plt

            plt.close(self._fig)
            self._fig = None
        if self._replay is not None:  # the replayed record's files (reopened by a later reset)
            self._replay.close()

    # ------------------------------------------------------------------------------------------ extras
    @property
    def state(self) -> np.ndarray:
        """The surrogate's state vector (28,: see surrogates.model.STATE_NAMES), for model-based studies."""
        return self._sim.state

    @property
    def gauge_heights(self) -> np.ndarray:
        """Heights of the nine tower gauges above still water (m)."""
        return np.asarray(GAUGE_HEIGHTS)


MAX_STEP_SAMPLES = 2_000_000
"""Largest number of simulation samples one forcing chunk (600 s), the warm-up or one control step may need
(a few hundred MB of forcing and output arrays): a ``dt`` of 1e-7 s or a warm-up of 1e7 s is refused up front
instead of ending in a ``MemoryError`` asking for hundreds of GiB."""
_CHUNK_SECONDS = 600.0  # surrogates.StreamingSimulator's default forcing chunk


def _shown(action: object) -> str:
    """``repr(action)`` on one line, cut at 80 characters (for error messages only: a repr costs more than a step)."""
    shown = " ".join(repr(action).split())
    return shown if len(shown) <= 80 else shown[:77] + "..."


def _real(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} must be a real number, got {value!r} ({type(value).__name__})")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def _check_arguments(*, dt, control_dt, episode_seconds, noise, max_pitch_offset_deg, max_torque_offset,
                     max_pitch_deg, warmup_seconds, case, reward, reward_fn) -> None:
    """Validate SparEnv's constructor arguments: a ValueError naming the first bad one."""
    step = _real("dt", dt)
    if step <= 0:
        raise ValueError(f"dt must be > 0 s, got {dt!r}")
    if _CHUNK_SECONDS / step > MAX_STEP_SAMPLES:
        raise ValueError(f"dt={dt!r} s is too small: a {_CHUNK_SECONDS:.0f} s forcing chunk would need "
                         f"{_CHUNK_SECONDS / step:.3g} samples (at most {MAX_STEP_SAMPLES:.0e}); use dt >= "
                         f"{_CHUNK_SECONDS / MAX_STEP_SAMPLES:.2g} s")
    if control_dt is not None:
        cdt = _real("control_dt", control_dt)
        if cdt <= 0:
            raise ValueError(f"control_dt must be > 0 s, got {control_dt!r}")
        if cdt / step > MAX_STEP_SAMPLES:
            raise ValueError(f"control_dt={control_dt!r} s is {cdt / step:.3g} samples of dt={dt!r} s per step "
                             f"(at most {MAX_STEP_SAMPLES:.0e})")
    if episode_seconds is not None and _real("episode_seconds", episode_seconds) <= 0:
        raise ValueError(f"episode_seconds must be positive and finite, got {episode_seconds!r}")
    warm = _real("warmup_seconds", warmup_seconds)
    if warm < 0:
        raise ValueError(f"warmup_seconds must be >= 0 s, got {warmup_seconds!r}")
    if warm / step > MAX_STEP_SAMPLES:
        raise ValueError(f"warmup_seconds={warmup_seconds!r} s is {warm / step:.3g} samples of dt={dt!r} s (at most "
                         f"{MAX_STEP_SAMPLES:.0e}, i.e. {MAX_STEP_SAMPLES * step:.4g} s at this dt)")
    pitch = _real("max_pitch_offset_deg", max_pitch_offset_deg)
    if not 0.0 <= pitch <= 90.0:
        raise ValueError(f"max_pitch_offset_deg must be in [0, 90] deg, got {max_pitch_offset_deg!r}")
    if _real("max_torque_offset", max_torque_offset) < 0:
        raise ValueError(f"max_torque_offset must be >= 0 N·m, got {max_torque_offset!r}")
    limit = _real("max_pitch_deg", max_pitch_deg)
    if not 0.0 < limit <= 180.0:
        raise ValueError(f"max_pitch_deg must be in (0, 180] deg, got {max_pitch_deg!r}")
    if not isinstance(noise, (bool, np.bool_)):
        raise ValueError(f"noise must be True or False, got {noise!r}")
    if isinstance(case, (bool, np.bool_)) or not isinstance(case, (int, np.integer, surrogates.LoadCase)):
        raise ValueError(f"case must be a load-case number (int) or a surrogates.LoadCase, got {case!r}")
    if reward is not None and not isinstance(reward, RewardConfig):
        raise ValueError(f"reward must be a fowt_env.env.RewardConfig or None, got {type(reward).__name__}")
    if reward_fn is not None and not callable(reward_fn):
        raise ValueError(f"reward_fn must be callable (env, truth, action) -> float, or None, got {reward_fn!r}")
