"""Every fenced ``python`` block of README.md and examples/README.md runs as written (issue 19, item 1).

Each block runs on its own (a fresh interpreter, an empty working folder, a non-interactive Matplotlib backend):
a block that needs a name or a file it does not make itself fails here, as it would for a reader who pastes it.
The blocks simulate minutes of data, so the test is slow-marked.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"^```python[^\n]*\n(.*?)^```", re.S | re.M)


def blocks() -> list:
    out = []
    for name in ("README.md", "examples/README.md"):
        text = (ROOT / name).read_text(encoding="utf-8")
        for m in FENCE.finditer(text):
            line = text[: m.start()].count("\n") + 1
            out.append(pytest.param(m.group(1), id=f"{name}:{line}"))
    return out


BLOCKS = blocks()


def test_the_readmes_have_python_blocks():
    assert len(BLOCKS) >= 5  # the extraction itself is tested: README.md has five


@pytest.mark.slow
@pytest.mark.parametrize("code", BLOCKS)
def test_readme_block_runs_as_written(code, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=900)
    assert res.returncode == 0, f"block failed:\n{code}\n--- stderr ---\n{res.stderr[-3000:]}"
