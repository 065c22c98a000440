"""Where the data set files live: the data folder lookup and the error for missing or bad files.

The data ship inside the package as package data, ``physbench/datasets/data/<dataset>/``, each
folder with its PROVENANCE.md; ``PHYSBENCH_DATA`` or a loader's ``root`` argument points elsewhere.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from physbench.errors import PhysbenchError

#: Environment variable naming a folder that holds the data set folders.
DATA_ENV = "PHYSBENCH_DATA"


class DatasetError(PhysbenchError, ValueError):
    """A data file that is missing or does not hold what its provenance says."""


def shipped_data() -> Path:
    """The folder of the data sets that ship with the package."""
    base = resources.files("physbench.datasets") / "data"
    if not isinstance(base, Path):  # e.g. imported from a zip archive: no folder to read from
        raise DatasetError(
            f"the shipped data sets are at {str(base)!r}, not in a folder; install physbench "
            f"unzipped, or set {DATA_ENV} to a folder that holds the data set folders"
        )
    return base


def data_dir(dataset: str, root: str | Path | None = None) -> Path:
    """The folder of ``dataset``: under ``root``, else under ``$PHYSBENCH_DATA``, else the copy
    shipped with the package (:func:`shipped_data`)."""
    if root is not None:
        base = Path(root)
    elif os.environ.get(DATA_ENV):
        base = Path(os.environ[DATA_ENV])
    else:
        base = shipped_data()
    folder = base / dataset
    if not folder.is_dir():
        raise DatasetError(
            f"data set folder {str(folder)!r} not found; pass root=... or set {DATA_ENV} to the "
            f"folder that holds {dataset}/ (the package ships it under physbench/datasets/data)"
        )
    return folder


def data_file(folder: Path, *names: str) -> Path:
    """The first of ``names`` that exists in ``folder`` (e.g. a file or its .gz copy)."""
    for n in names:
        if (folder / n).is_file():
            return folder / n
    raise DatasetError(f"none of {', '.join(names)} in {str(folder)!r}")
