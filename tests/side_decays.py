"""The packaged OpenFAST side-to-side free decays (``fowt_env/data/openfast_side_decays/``, made by
``tools/openfast_side_decay_runs.py``) and the surrogate they are compared with; shared by
``tests/test_yaw_decay.py`` and ``tests/test_roll_decay.py``."""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

import surrogates
from fowt_env.io import load_record
from fowt_env.validation import reference_model

DATA = resources.files("fowt_env") / "data" / "openfast_side_decays"


def decay_run(name: str) -> tuple[Any, dict]:
    """The OpenFAST record and its ``case.json`` conditions."""
    case = json.loads((DATA / f"{name}.case.json").read_text())
    return load_record(DATA / f"{name}.npz"), case


def decay_model() -> surrogates.FOWTModel:
    """``validate()``'s default model (:func:`fowt_env.validation.reference_model`): the deck's gauges, no 1P
    loads (the deck's rotor is balanced)."""
    return reference_model()
