"""What a wheel holds: every file the package reads at run time is declared package data, the
licence travels with it, and the version has one source (CITATION.cff repeats it). ``.ci/wheel``
builds and runs the wheel itself; these checks read the declarations, fast and without a build."""

from __future__ import annotations

import importlib.metadata
import re
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


def test_the_licences_are_declared_for_the_wheel():
    # physbench is MIT; the billiards data set it redistributes is Apache-2.0, whose text must
    # travel with it.
    project = PYPROJECT["project"]
    assert project["license"] == "MIT AND Apache-2.0"
    billiards = "physbench/datasets/data/billiards_dogan/LICENSE"
    assert project["license-files"] == ["LICENSE", billiards]
    assert "MIT License" in (ROOT.parent / "LICENSE").read_text(encoding="utf-8")
    apache = (ROOT.parent / billiards).read_text(encoding="utf-8")
    assert "Apache License" in apache and "Version 2.0, January 2004" in apache
    assert "Apache-2.0" in (ROOT / "datasets/data/billiards_dogan/PROVENANCE.md").read_text()


def test_the_version_has_one_source():
    assert "version" not in PYPROJECT["project"]
    assert PYPROJECT["tool"]["setuptools"]["dynamic"]["version"] == {
        "attr": "physbench.__version__"
    }
    # An editable install made before a version change still reports the old one: reinstall it.
    assert physbench.__version__ == importlib.metadata.version("physbench")


def test_the_citation_names_this_version_and_the_paper():
    cff = (ROOT.parent / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(r"^version: (\S+)$", cff, re.MULTILINE)[1] == physbench.__version__
    assert "title: Predicting Physical Object Properties from Video" in cff
