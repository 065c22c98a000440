"""Where the data set files live: the data folder lookup and the error for missing or bad files.

The data live in ``benchmarks/data/<dataset>/`` of the repository, each folder with its
PROVENANCE.md; ``PHYSBENCH_DATA`` or a loader's ``root`` argument points elsewhere.
"""

from __future__ import annotations

import os
from pathlib import Path

from physbench.errors import PhysbenchError

#: Environment variable naming a folder that holds the data set folders.
DATA_ENV = "PHYSBENCH_DATA"


class DatasetError(PhysbenchError, ValueError):
    """A data file that is missing or does not hold what its provenance says."""


def data_dir(dataset: str, root: str | Path | None = None) -> Path:
    """The folder of ``dataset``: under ``root``, else under ``$PHYSBENCH_DATA``, else under the
    repository's ``benchmarks/data``."""
    if root is not None:
        base = Path(root)
    elif os.environ.get(DATA_ENV):
        base = Path(os.environ[DATA_ENV])
    else:
        base = Path(__file__).resolve().parents[2] / "benchmarks" / "data"
    folder = base / dataset
    if not folder.is_dir():
        raise DatasetError(
            f"data set folder {str(folder)!r} not found; pass root=... or set {DATA_ENV} to the "
            f"folder that holds {dataset}/ (the repository keeps it under benchmarks/data)"
        )
    return folder


def data_file(folder: Path, *names: str) -> Path:
    """The first of ``names`` that exists in ``folder`` (e.g. a file or its .gz copy)."""
    for n in names:
        if (folder / n).is_file():
            return folder / n
    raise DatasetError(f"none of {', '.join(names)} in {str(folder)!r}")
