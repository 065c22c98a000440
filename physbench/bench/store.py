"""The on-disk layout of a sweep's output folder and its crash-safe writes.

``DIR/cells/<key>.json`` holds one finished cell (written once, atomically: a temporary file in
the same folder, flushed to disk, then renamed over the target), so a sweep killed at any moment
leaves only whole cells, and a re-run skips them. Tables, summaries and plots are derived from the
cells and rewritten atomically the same way.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from typing import Any

from physbench.errors import PhysbenchError

RESULTS = "results.parquet"
DERIVED = (
    RESULTS,
    "stats.csv",
    "summary.csv",
    "summary.md",
    "summary.tex",
    "report.html",
    "win_rate.csv",
)


def atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` so that readers (and a resumed run) see the old file or the new
    one, never a part."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


class CellStore:
    """Finished cells of one output folder, keyed by :attr:`physbench.bench.spec.Cell.key`."""

    def __init__(self, out: str | Path) -> None:
        self.out = Path(out)
        self.dir = self.out / "cells"

    def prepare(self, *, fresh: bool = False) -> None:
        """Create the folder (refusing one that cannot be written), drop temporary files left by
        a killed run, and with ``fresh`` forget every finished cell and derived file."""
        try:
            if self.out.exists() and not self.out.is_dir():
                raise NotADirectoryError(f"{self.out} is a file")
            self.dir.mkdir(parents=True, exist_ok=True)
            probe = self.dir / f".probe.{os.getpid()}.tmp"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            raise PhysbenchError(
                f"--out {str(self.out)!r}: cannot write results there ({exc.strerror or exc}); "
                "expected a writable folder (it is created if missing)"
            ) from None
        for tmp in [*self.dir.glob(".*.tmp"), *self.out.glob(".*.tmp")]:
            tmp.unlink(missing_ok=True)
        if fresh:
            shutil.rmtree(self.dir)
            self.dir.mkdir()
            for name in DERIVED:
                (self.out / name).unlink(missing_ok=True)

    def path(self, key: str) -> Path:
        return self.dir / f"{key}.json"

    def load(self, key: str) -> dict[str, Any] | None:
        """The finished cell, or ``None`` if it has not finished (or its file is unreadable)."""
        try:
            return json.loads(self.path(key).read_text())
        except (OSError, ValueError):
            return None

    def save(self, key: str, data: dict[str, Any]) -> None:
        atomic_write(self.path(key), json.dumps(data).encode())
