"""--tiny only: tools/model_error_table.py with its hard-coded settings shrunk (plumbing test; the numbers mean
nothing). The tool itself is imported from REPO and run through its own main(). Usage: model_error_tiny.py REPO OUT"""

import importlib.util
import sys
from pathlib import Path

import surrogates.model_error as me

repo, out = Path(sys.argv[1]), sys.argv[2]
spec = importlib.util.spec_from_file_location("model_error_table", repo / "tools" / "model_error_table.py")
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)
tool.SETTINGS = {"train_cases": (1, 4), "train_duration": 60.0, "duration": 40.0, "trace_seconds": 0.0}
tool.SEEDS = (0, 1)
me.STANDARD_PERTURBATIONS = dict(list(me.STANDARD_PERTURBATIONS.items())[:2])
raise SystemExit(tool.main(["--out", out]))
