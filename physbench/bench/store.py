"""The on-disk layout of a sweep's output folder and its crash-safe writes.

``DIR/cells/<key>.json`` holds one finished cell (written once, atomically: a temporary file in
the same folder, flushed to disk, then renamed over the target), so a sweep killed at any moment
leaves only whole cells, and a re-run skips them. Tables, summaries and plots are derived from the
cells and rewritten atomically the same way.

A sweep stores its cells through a :class:`CellWriter`: a thread that writes them in batches, off
the loop that hands out cells, with one concurrent flush per batch. Flushing one file to disk
(``fsync``) waits for the file system's journal: 1.4 ms on the quiet development VM, 8-12 ms while
other jobs write, which capped a sweep that flushed each cell in its main loop at 80-700 cells/s
whatever its workers could do. Concurrent flushes share journal commits (100 files: 0.5-0.8 s one
after another, 40-50 ms from 16 threads, measured on that VM under load).

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
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any

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

    def save_many(self, cells: list[tuple[str, dict[str, Any]]], flush: Any = map) -> list[str]:
        """Write each ``(key, data)`` as :meth:`save` does (whole or not at all), flushing the
        batch's files at once: each to a temporary file, then all flushed to disk through
        ``flush`` (``map`` or a thread pool's ``map``: concurrent flushes share the file system's
        journal commits), then each renamed into place. Returns each cell's JSON text."""
        texts = [json.dumps(data) for _, data in cells]
        files: list[tuple[IO[bytes], Path, Path]] = []
        try:
            for (key, _), text in zip(cells, texts, strict=True):
                path = self.path(key)
                tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
                files.append((open(tmp, "wb"), tmp, path))  # noqa: SIM115 (closed below)
                files[-1][0].write(text.encode())
            list(flush(_flush, [f for f, _, _ in files]))
            for _, tmp, path in files:
                os.replace(tmp, path)
        finally:
            for f, _, _ in files:
                f.close()
        return texts


def _flush(f: IO[bytes]) -> None:
    f.flush()
    os.fsync(f.fileno())


#: Threads that flush one batch of cell files to disk together (see the module's docstring).
FLUSHERS = 16
#: Cells one batch holds at most (each an open file until the batch is flushed).
BATCH = 128


class CellWriter:
    """Stores finished cells in a background thread, in batches (:meth:`CellStore.save_many`),
    so that the sweep's loop hands out the next cells while earlier ones are flushed to disk.
    Used as a context manager around the loop: :meth:`put` queues a cell and returns at once;
    leaving the block stores every queued cell before it returns, also when the loop raised
    (Ctrl-C included), so only cells still running are lost. A failure to write (a full disk)
    is raised by the next :meth:`put` or by leaving the block; the cells queued after it are not
    stored (a re-run runs them).

    ``saved(key, data)``, if given, is called in the writer thread for each cell once its file
    is in place, with ``data`` read back from that file's JSON text (what :meth:`CellStore.load`
    would return), e.g. to build the cell's table rows while the sweep goes on."""

    def __init__(
        self, store: CellStore, saved: Callable[[str, dict[str, Any]], None] | None = None
    ) -> None:
        self._store = store
        self._saved = saved
        self._queue: list[tuple[str, dict[str, Any]]] = []
        self._wake = threading.Condition()
        self._closed = False
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="physbench-cell-writer", daemon=True)

    def __enter__(self) -> CellWriter:
        self._thread.start()
        return self

    def put(self, key: str, data: dict[str, Any]) -> None:
        """Queue ``data`` to be stored as cell ``key``; raises the writer's error, if any."""
        with self._wake:
            self._raise()
            self._queue.append((key, data))
            self._wake.notify()

    def __exit__(self, *exc: object) -> None:
        with self._wake:
            self._closed = True
            self._wake.notify()
        self._thread.join()
        if exc[0] is None:
            with self._wake:
                self._raise()

    def _raise(self) -> None:
        if self._error is not None:
            raise self._error

    def _run(self) -> None:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(FLUSHERS, thread_name_prefix="physbench-flush") as pool:
            while True:
                with self._wake:
                    while not self._queue and not self._closed:
                        self._wake.wait()
                    batch, self._queue = self._queue[:BATCH], self._queue[BATCH:]
                if not batch:
                    return
                try:
                    texts = self._store.save_many(batch, pool.map)
                    if self._saved is not None:
                        for (key, _), text in zip(batch, texts, strict=True):
                            self._saved(key, json.loads(text))
                except BaseException as exc:  # handed to the sweep's thread by put / __exit__
                    with self._wake:
                        self._error, self._queue = exc, []
                    return
