"""The on-disk layout of a sweep's output folder and its crash-safe writes.

``DIR/cells/<key>.json`` holds one finished cell (written once, atomically: a temporary file in
the same folder, flushed to disk, then renamed over the target), so a sweep killed at any moment
leaves only whole cells, and a re-run skips them. Tables, summaries and plots are derived from the
cells and rewritten atomically the same way.

One sweep at a time writes a folder: it holds ``DIR/.lock`` (a :class:`filelock.FileLock`, released
by the system if the process is killed) and records its pid in ``DIR/.lock.pid``, so a second sweep
on the same folder is refused with that pid (or waits) instead of repeating cells and deleting the
first one's temporary files.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Iterator
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


LOCK = ".lock"


class FolderBusyError(PhysbenchError):
    """Another sweep holds the lock on the output folder."""


class CellStore:
    """Finished cells of one output folder, keyed by :attr:`physbench.bench.spec.Cell.key`."""

    def __init__(self, out: str | Path) -> None:
        self.out = Path(out)
        self.dir = self.out / "cells"

    @contextlib.contextmanager
    def writing(self, *, wait: bool = False) -> Iterator[CellStore]:
        """Create the folder (refusing one that cannot be written) and hold its lock while the
        block runs; called by the runner around a whole sweep. When another process holds it,
        refuses (:class:`FolderBusyError`) or, with ``wait``, waits for it."""
        from filelock import FileLock, Timeout

        self._make()
        lock = FileLock(self.out / LOCK, timeout=-1 if wait else 0)
        try:
            lock.acquire()
        except Timeout:
            try:
                pid = f" (pid {int((self.out / f'{LOCK}.pid').read_text())})"
            except (OSError, ValueError):
                pid = ""
            raise FolderBusyError(
                f"--out {str(self.out)!r}: another physbench bench is writing this folder{pid}; "
                "wait for it (--wait) or use another --out"
            ) from None
        try:
            atomic_write(self.out / f"{LOCK}.pid", str(os.getpid()).encode())
            yield self
        finally:
            (self.out / f"{LOCK}.pid").unlink(missing_ok=True)
            lock.release()

    def _make(self) -> None:
        try:
            if self.out.exists() and not self.out.is_dir():
                raise NotADirectoryError(f"{self.out} is a file")
            self.dir.mkdir(parents=True, exist_ok=True)
            probe = self.dir / f".probe.{os.getpid()}.tmp"
            probe.write_bytes(b"")
            probe.unlink(missing_ok=True)
        except OSError as exc:
            raise PhysbenchError(
                f"--out {str(self.out)!r}: cannot write results there ({exc.strerror or exc}); "
                "expected a writable folder (it is created if missing)"
            ) from None

    def prepare(self, *, fresh: bool = False) -> None:
        """Drop temporary files left by a killed run, and with ``fresh`` forget every finished
        cell and derived file; called under :meth:`writing`'s lock, so no live writer's
        temporary files are dropped."""
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
