"""Where cells run: in this process, in local worker processes, or on a Dask cluster.

Every executor maps one picklable function over the cells and yields ``(item, result)`` pairs as
they finish, in any order; the runner writes each result and orders the table by cell index, so
the table does not depend on the executor or the number of workers. Results come back to this
process (nothing is written by workers), so Dask workers need no shared file system, only the
same physbench installation.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol, TypeVar

from physbench.errors import PhysbenchError, counted

T = TypeVar("T")
R = TypeVar("R")
NAMES = ("serial", "processes", "dask")


class Executor(Protocol):
    name: str
    workers: int

    def __enter__(self) -> Executor: ...
    def __exit__(self, *exc: object) -> None: ...
    def map_unordered(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[T, R]]: ...
    def describe(self) -> str: ...


def default_workers() -> int:
    """All cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


class SerialExecutor:
    """One cell after another in this process (debugging, tiny sweeps, exact tracebacks)."""

    name = "serial"
    workers = 1

    def __enter__(self) -> SerialExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    def map_unordered(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[T, R]]:
        for item in items:
            yield item, fn(item)

    def describe(self) -> str:
        return "serial"


class ProcessExecutor:
    """A pool of ``workers`` local processes, started with ``spawn`` (a fork would copy this
    process's threads, e.g. the progress bar's monitor, into a half-initialised child)."""

    name = "processes"

    def __init__(self, workers: int | None = None) -> None:
        self.workers = workers or default_workers()
        self._pool: Any = None

    def __enter__(self) -> ProcessExecutor:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        self._pool = ProcessPoolExecutor(
            self.workers, mp_context=multiprocessing.get_context("spawn")
        )
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=exc[0] is None, cancel_futures=True)
            self._pool = None

    def map_unordered(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[T, R]]:
        from concurrent.futures import as_completed
        from concurrent.futures.process import BrokenProcessPool

        futures = {self._pool.submit(fn, item): item for item in items}
        try:
            for fut in as_completed(futures):
                yield futures[fut], fut.result()
        except BrokenProcessPool as exc:
            raise PhysbenchError(
                f"a worker process died ({exc}); finished cells are saved: re-run the same "
                "command to resume, or use --executor serial to see which cell crashes the "
                "interpreter"
            ) from None
        finally:
            for fut in futures:
                fut.cancel()

    def describe(self) -> str:
        return f"processes ({counted(self.workers, 'worker')})"


class DaskExecutor:
    """A Dask ``distributed`` cluster: the scheduler at ``address`` (``tcp://host:8786``), or a
    LocalCluster of ``workers`` single-threaded worker processes when no address is given."""

    name = "dask"

    def __init__(self, address: str | None = None, workers: int | None = None) -> None:
        self.address = address
        self.workers = workers or default_workers()
        self._client: Any = None
        self._cluster: Any = None

    def __enter__(self) -> DaskExecutor:
        import logging

        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise PhysbenchError(
                "--executor dask needs the 'distributed' package: pip install 'physbench[dist]'"
            ) from None
        try:
            if self.address:
                self._client = Client(self.address, timeout="20s")
                self.workers = max(
                    1,
                    sum(
                        w.get("nthreads", 1)
                        for w in self._client.scheduler_info()["workers"].values()
                    ),
                )
            else:
                self._cluster = LocalCluster(
                    n_workers=self.workers,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=logging.ERROR,
                )
                self._client = Client(self._cluster)
        except OSError as exc:
            raise PhysbenchError(
                f"--address {self.address!r}: cannot reach a Dask scheduler ({exc}); expected "
                "e.g. tcp://host:8786"
            ) from None
        return self

    def __exit__(self, *exc: object) -> None:
        if self._client is not None:
            self._client.close()
        if self._cluster is not None:
            self._cluster.close()
        self._client = self._cluster = None

    def map_unordered(self, fn: Callable[[T], R], items: Sequence[T]) -> Iterator[tuple[T, R]]:
        from distributed import as_completed

        futures = [self._client.submit(fn, item, pure=False) for item in items]
        index = {f.key: item for f, item in zip(futures, items, strict=True)}
        try:
            for fut in as_completed(futures):
                try:
                    result = fut.result()
                # the cell itself never raises: this is the cluster (a killed worker, ...)
                except Exception as exc:
                    raise PhysbenchError(
                        f"the Dask cluster lost a cell ({type(exc).__name__}: {exc}); finished "
                        "cells are saved: re-run the same command to resume"
                    ) from None
                yield index[fut.key], result
        finally:
            self._client.cancel(futures)

    def describe(self) -> str:
        return f"dask ({self.address or 'LocalCluster'}, {counted(self.workers, 'worker')})"


def make_executor(name: str, *, workers: int | None = None, address: str | None = None) -> Executor:
    """The executor ``name`` (one of :data:`NAMES`); ``workers`` defaults to all cores."""
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise PhysbenchError(f"--workers {workers}: expected a whole number >= 1")
    if address and name != "dask":
        raise PhysbenchError(
            f"--address {address!r} names a Dask scheduler; it needs --executor dask (got {name!r})"
        )
    if name == "serial":
        return SerialExecutor()
    if name == "processes":
        return ProcessExecutor(workers)
    if name == "dask":
        return DaskExecutor(address, workers)
    raise PhysbenchError(
        f"--executor {name!r}: unknown executor; known executors: {', '.join(NAMES)}"
    )
