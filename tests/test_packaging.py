"""What ``pip install .`` ships: every data file the packages read must match a package-data pattern of
pyproject.toml (setuptools expands the patterns with ``glob``, where ``*`` does not enter subfolders)."""

from __future__ import annotations

import glob
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("package", ["surrogates", "fowt_env"])
def test_every_data_file_is_declared_as_package_data(package):
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    patterns = config["tool"]["setuptools"]["package-data"][package]
    pkg = ROOT / package
    shipped = {Path(p) for pattern in patterns for p in glob.glob(str(pkg / pattern)) if Path(p).is_file()}
    data = {p for p in (pkg / "data").rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert data, f"{package}/data holds no file"
    missing = sorted(str(p.relative_to(ROOT)) for p in data - shipped)
    assert not missing, f"not in the wheel: {missing}"
