"""Finding the data set folders and files."""

from __future__ import annotations

import pytest

from physbench.datasets.files import DATA_ENV, DatasetError, data_dir, data_file


def test_data_dir_finds_the_repository_copies():
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
