"""fowt-env: the OC3 Hywind surrogate as a Gymnasium environment, sensor faults, virtual sensors and the CLI.

Importing the package registers the environments:

* ``fowt_env/Spar-v0`` -- full surrogate (all effects), OLC 7 by default, all 36 tower channels;
* ``fowt_env/SparLinear-v0`` -- the linear model (``effects="none"``), same defaults;
* ``fowt_env/SparScenarioA-v0`` (``B``, ``C``) -- the seed paper's virtual-sensing scenarios: its load case,
  the 18-channel fore-aft plane and the scenario's fixed mask of hidden sensors.

All take the keyword arguments of :class:`fowt_env.env.SparEnv`; episodes are truncated after
``max_episode_steps`` (48,000 steps = 600 s at dt = 0.0125 s; pass ``max_episode_steps=`` to ``gymnasium.make``
to change it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gymnasium.envs.registration import register, registry

if TYPE_CHECKING:  # imported on first use (below), so that ``fowt-env --help`` does not load the physics
    from . import faults
    from .env import RewardConfig, SparEnv
    from .wrappers import VirtualSensorWrapper

__version__ = "0.1.0"
__all__ = ["SparEnv", "RewardConfig", "VirtualSensorWrapper", "faults", "make_scenario_env", "ENV_IDS"]

MAX_EPISODE_STEPS = 48_000


_LAZY = {"SparEnv": ".env", "RewardConfig": ".env", "VirtualSensorWrapper": ".wrappers", "faults": ".faults"}


def __getattr__(name: str):
    """``fowt_env.SparEnv`` and the rest of ``__all__`` are imported when first used: the command line's
    ``--help`` and ``--version`` then answer without importing SciPy, Numba and the surrogate."""
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    module = importlib.import_module(_LAZY[name], __name__)
    value = module if name == "faults" else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


def make_scenario_env(name: str, **kwargs) -> SparEnv:
    """A :class:`SparEnv` set up as the paper's scenario ``name`` (its OLC, FA plane, fixed hidden mask)."""
    from . import faults
    from .env import SparEnv

    scenario = faults.Scenario(name)
    extra = kwargs.pop("faults", None)
    fault_list = [scenario] + faults.as_fault_list(extra)
    kwargs.setdefault("case", scenario.olc)
    kwargs.setdefault("plane", "FA")
    return SparEnv(faults=fault_list, **kwargs)


def _linear_env(**kwargs) -> SparEnv:
    import surrogates

    from .env import SparEnv

    kwargs.setdefault("model", surrogates.FOWTModel(effects="none"))
    return SparEnv(**kwargs)


ENV_IDS = ["fowt_env/Spar-v0", "fowt_env/SparLinear-v0"] + [f"fowt_env/SparScenario{s}-v0" for s in "ABC"]

if "fowt_env/Spar-v0" not in registry:
    register(id="fowt_env/Spar-v0", entry_point="fowt_env.env:SparEnv", max_episode_steps=MAX_EPISODE_STEPS)
    register(id="fowt_env/SparLinear-v0", entry_point="fowt_env:_linear_env", max_episode_steps=MAX_EPISODE_STEPS)
    for _s in "ABC":
        register(id=f"fowt_env/SparScenario{_s}-v0", entry_point="fowt_env:make_scenario_env",
                 kwargs={"name": _s}, max_episode_steps=MAX_EPISODE_STEPS)
