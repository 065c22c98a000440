"""What a wheel holds: every file the package reads at run time is declared package data.
(``.ci/wheel`` builds and runs the wheel itself; these checks read the declarations, fast and
without a build.)"""

from __future__ import annotations

import tomllib
from pathlib import Path

import physbench

ROOT = Path(physbench.__file__).parent
PYPROJECT = tomllib.loads((ROOT.parent / "pyproject.toml").read_text(encoding="utf-8"))


def _package_data() -> set[Path]:
    """The files under ``physbench/`` that setuptools' package-data patterns select."""
    selected: set[Path] = set()
    for package, patterns in PYPROJECT["tool"]["setuptools"]["package-data"].items():
        folder = ROOT.parent.joinpath(*package.split("."))
        for pattern in patterns:
            selected |= {p for p in folder.glob(pattern) if p.is_file()}
    return selected


def test_every_file_of_the_package_besides_its_code_is_package_data():
    files = {
        p
        for p in ROOT.rglob("*")
        if p.is_file() and p.suffix not in (".py", ".pyc") and "__pycache__" not in p.parts
    }
    missing = sorted(str(p.relative_to(ROOT)) for p in files - _package_data())
    assert not missing, f"not declared package data in pyproject.toml, so not in a wheel: {missing}"
    shipped = {str(p.relative_to(ROOT)) for p in files}
    assert "datasets/data/billiards_dogan/shots_20221225_2_match.csv.gz" in shipped
    assert "estimators/resnet3d/weights/stacked_boxes__mass.safetensors" in shipped
