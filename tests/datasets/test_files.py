"""Finding the data set folders and files."""

from __future__ import annotations

import functools
import os
import sys
import zipfile
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

import pytest

from physbench.datasets import billiards, dataset_names, load
from physbench.datasets.files import (
    DATA_ENV,
    DatasetError,
    data_dir,
    data_file,
    shipped_data,
)


def test_data_dir_finds_the_shipped_copies():
    for folder in ("ball_drops_desilva", "billiards_dogan", "pendulum_benard", "pendulum_kaheman"):
        assert (data_dir(folder) / "PROVENANCE.md").is_file()


def test_data_dir_looks_under_root_then_the_environment(tmp_path, monkeypatch):
    with pytest.raises(DatasetError, match=DATA_ENV):
        data_dir("billiards_dogan", root=tmp_path)
    (tmp_path / "mine").mkdir()
    assert data_dir("mine", root=tmp_path) == tmp_path / "mine"
    monkeypatch.setenv(DATA_ENV, str(tmp_path))
    assert data_dir("mine") == tmp_path / "mine"


def test_data_file_takes_the_first_that_exists(tmp_path):
    (tmp_path / "b.csv.gz").write_bytes(b"")
    assert data_file(tmp_path, "b.csv", "b.csv.gz") == tmp_path / "b.csv.gz"
    (tmp_path / "b.csv").write_text("")
    assert data_file(tmp_path, "b.csv", "b.csv.gz") == tmp_path / "b.csv"
    with pytest.raises(DatasetError, match=r"none of a\.csv, a\.csv\.gz"):
        data_file(tmp_path, "a.csv", "a.csv.gz")


#: The path lists of the active ``opened`` fixtures; the audit hook appends to the last.
_OPENED: list[list[str]] = []


def _record_open(event: str, args: tuple[object, ...]) -> None:
    if event == "open" and _OPENED and isinstance(args[0], str | os.PathLike):
        _OPENED[-1].append(os.fsdecode(args[0]))


@functools.cache
def _hook() -> None:
    sys.addaudithook(_record_open)  # for the rest of the session: hooks cannot be removed


@pytest.fixture
def opened() -> Iterator[list[str]]:
    """The paths of the files opened while the fixture is active: every way of opening a file
    (``open``, ``gzip``, numpy's readers) raises the ``open`` audit event."""
    _hook()
    paths: list[str] = []
    _OPENED.append(paths)
    yield paths
    _OPENED.remove(paths)


def test_every_data_set_loads_from_the_package_data_alone(monkeypatch, opened):
    monkeypatch.delenv(DATA_ENV, raising=False)
    shipped = resources.files("physbench.datasets") / "data"
    assert shipped_data() == shipped
    billiards._table.cache_clear()  # read the file again, not what an earlier test left
    for name in dataset_names():
        assert load(name)
    read = [Path(p).resolve() for p in opened if not p.endswith((".py", ".pyc", ".so"))]
    outside = [p for p in read if not p.is_relative_to(Path(shipped).resolve())]
    assert read and not outside, f"read outside the package: {outside}"
    folders = {p.relative_to(Path(shipped).resolve()).parts[0] for p in read}
    assert folders == {
        "ball_drops_desilva",
        "billiards_dogan",
        "pendulum_benard",
        "pendulum_kaheman",
    }


def test_shipped_data_in_a_zip_archive_points_to_the_environment(tmp_path, monkeypatch):
    archive = tmp_path / "physbench.zip"
    zipfile.ZipFile(archive, "w").close()
    monkeypatch.setattr(resources, "files", lambda package: zipfile.Path(archive))
    with pytest.raises(DatasetError, match=f"not in a folder.*set {DATA_ENV}"):
        shipped_data()
