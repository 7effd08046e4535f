"""Stable-Baselines3's environment checker on every registered id (warnings as errors).

SB3 needs PyTorch, which is too heavy for the test extra, so this test runs where SB3 is installed
(``pip install stable-baselines3``) and is skipped otherwise; Gymnasium's own checker runs everywhere
(tests/test_env.py).
"""

import warnings

import gymnasium as gym
import pytest

import fowt_env

sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker",
                                  reason="stable-baselines3 (and PyTorch) not installed")


@pytest.mark.parametrize("env_id", fowt_env.ENV_IDS)
def test_stable_baselines3_check_env(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_checker.check_env(env.unwrapped, warn=True, skip_render_check=True)
