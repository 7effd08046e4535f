"""``VirtualSensorWrapper``: plug any estimator into the environment as a virtual sensor."""

from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
from gymnasium import spaces

__all__ = ["VirtualSensorWrapper"]


class VirtualSensorWrapper(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Add ``obs["estimate"]``: the full channel vector reconstructed by a virtual sensor from the live channels.

    The sensor is any object with the estimator protocol ``reset()`` and ``update(y, mask) -> estimate``
    (:mod:`estimators.baseline` describes it): Hankel-DMD, Kalman or a trivial baseline all drop in unchanged.
    Dropped channels are passed to the sensor as NaN with ``mask`` False.

    ``info`` gains ``estimation_error`` (estimate - truth, per channel), ``estimation_rmse_hidden`` and
    ``estimation_rmse_live`` (RMS error over the channels that are dropped / available now; a key is absent at a
    step with no such channel, so that every value is a number and equal seeds give equal ``info``).

    The wrapper records its constructor arguments (``env.spec`` can be re-made with :func:`gymnasium.make`, as
    Gymnasium's ``check_env`` does); a re-made environment gets its own deep copy of the sensor as it was when
    this wrapper was built, never a sensor shared with this one.

    Parameters
    ----------
    env : gymnasium.Env
        A :class:`fowt_env.SparEnv` (possibly wrapped).
    sensor : object
        The virtual sensor (fitted). This wrapper drives this very object (its ``rejected_`` and other
        attributes are the ones to read after an episode) unless ``copy_sensor``.
    copy_sensor : bool
        Drive a deep copy of ``sensor`` instead (default False).

    Examples
    --------
    >>> import gymnasium as gym, fowt_env
    >>> from estimators.baseline import HoldLastValue
    >>> env = fowt_env.VirtualSensorWrapper(gym.make("fowt_env/Spar-v0", plane="FA"), HoldLastValue())
    >>> obs, info = env.reset(seed=1)
    >>> obs["estimate"].shape
    (18,)
    """

    def __init__(self, env: gym.Env, sensor: object, copy_sensor: bool = False) -> None:
        for name in ("reset", "update"):
            if not callable(getattr(sensor, name, None)):
                raise ValueError(f"sensor must have a callable {name}() (the virtual-sensor protocol)")
        # a spec re-made from this wrapper gets its own copy (taken now, before this env runs the sensor)
        gym.utils.RecordConstructorArgs.__init__(self, sensor=copy.deepcopy(sensor), copy_sensor=True)
        gym.Wrapper.__init__(self, env)
        self.sensor = copy.deepcopy(sensor) if copy_sensor else sensor
        base = env.observation_space
        if not isinstance(base, spaces.Dict) or "sensors" not in base.spaces:
            raise ValueError("VirtualSensorWrapper needs a Dict observation space with 'sensors' and 'mask'")
        box = base["sensors"]
        self._low, self._high = box.low, box.high
        self.observation_space = spaces.Dict(
            {**base.spaces, "estimate": spaces.Box(box.low, box.high, shape=box.shape, dtype=np.float64)}
        )

    def _estimate(self, obs: dict, info: dict) -> tuple[dict, dict]:
        mask = obs["mask"].astype(bool)
        y = np.where(mask, obs["sensors"], np.nan)
        est = np.asarray(self.sensor.update(y, mask), dtype=np.float64)
        if est.shape != mask.shape:
            raise ValueError(f"sensor.update returned shape {est.shape}, expected {mask.shape}")
        if not np.all(np.isfinite(est)):
            est = np.where(np.isfinite(est), est, np.where(mask, obs["sensors"], 0.0))
            info["estimate_nonfinite_replaced"] = True
        truth = info["truth"]
        err = est - truth
        est = np.clip(est, self._low, self._high)
        info["estimation_error"] = err
        if (~mask).any():
            info["estimation_rmse_hidden"] = float(np.sqrt(np.mean(err[~mask] ** 2)))
        if mask.any():
            info["estimation_rmse_live"] = float(np.sqrt(np.mean(err[mask] ** 2)))
        self.env.unwrapped._last["estimate"] = est
        return {**obs, "estimate": est}, info

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.sensor.reset()
        return self._estimate(obs, info)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        obs, info = self._estimate(obs, info)
        return obs, reward, terminated, truncated, info
