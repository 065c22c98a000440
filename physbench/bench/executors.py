"""Where cells run: in this process, in local worker processes, or on a Dask cluster.

Every executor maps one picklable function over the cells and yields ``(item, result)`` pairs as
they finish, in any order; the runner writes each result and orders the table by cell index, so
the table does not depend on the executor or the number of workers. Results come back to this
process (nothing is written by workers), so Dask workers need no shared file system, only the
same physbench installation.

A cell that kills its interpreter (``os._exit``, a segfault in an extension) is contained by the
``processes`` and ``dask`` executors: it is retried once alone, then handed to the caller's
``died`` with what happened, and the sweep goes on. ``serial`` runs cells in this very process, so
it cannot contain that. Local worker processes (a LocalCluster's too) die with the process that
started them.

The caller may group items by what their first run in a process costs (``affinity``: a cell's
estimator and engine, whose libraries take up to a second to import): the ``processes`` executor
then gives a free worker the items of groups it has already run, so each group's imports are paid
by as few workers as the load allows instead of by every worker.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Generator, Hashable, Iterator, Sequence
from pathlib import Path
from typing import Any, Generic, Protocol, TypeVar

from physbench.errors import PhysbenchError, counted

T = TypeVar("T")
R = TypeVar("R")
NAMES = ("serial", "processes", "dask")
#: Items a local pool holds per worker: one running, one queued behind it.
QUEUED = 2


class Executor(Protocol):
    name: str
    workers: int

    def __enter__(self) -> Executor: ...
    def __exit__(self, *exc: object) -> None: ...
    def map_unordered(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        died: Callable[[T, str], R],
        affinity: Callable[[T], Hashable] | None = None,
    ) -> Iterator[tuple[T, R]]: ...
    def describe(self) -> str: ...


def default_workers() -> int:
    """All cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def die_with_parent(parent: int) -> None:
    """Make this process end when ``parent`` does; called first thing in every local worker, so
    that killing a sweep's main process does not leave its workers computing for minutes. Linux
    asks the kernel (``PR_SET_PDEATHSIG``); elsewhere a thread watches the parent's pid."""
    if sys.platform == "linux":
        import ctypes

        try:
            pr_set_pdeathsig = 1
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # it died before prctl took effect
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="physbench-parent-watch", daemon=True).start()


def start_worker(parent: int) -> None:
    """The initializer of every :class:`ProcessExecutor` worker: it ends with its parent
    (:func:`die_with_parent`) and, once its pool shuts it down, without the interpreter's
    teardown (:mod:`physbench.teardown`), which would otherwise keep a core busy after the cells
    are done. Its exit status is then always 0, which nothing reads: a worker that dies while it
    works is told apart by its pool before it reaches that exit. A plugin that a built-in
    shadows was named by the main process already; workers do not repeat it."""
    import warnings

    from physbench.plugins import PluginWarning
    from physbench.teardown import skip_at_exit

    die_with_parent(parent)
    skip_at_exit(lambda: 0)
    warnings.simplefilter("ignore", PluginWarning)


def how_it_died(exitcode: int | None) -> str:
    """``exit code 3`` or ``signal 11 (SIGSEGV)``, from a process's ``exitcode``."""
    if exitcode is not None and exitcode < 0:
        try:
            return f"signal {-exitcode} ({signal.Signals(-exitcode).name})"
        except ValueError:
            return f"signal {-exitcode}"
    return f"exit code {exitcode}"


def _run_alone(conn: Any, fn: Callable[[T], R], item: T, parent: int) -> None:
    """The body of a process that runs one suspect item on its own (see
    :meth:`ProcessExecutor.map_unordered`) and sends back ``(ok, result or exception)``."""
    die_with_parent(parent)
    try:
        msg: tuple[bool, Any] = (True, fn(item))
    except Exception as exc:
        msg = (False, exc)
    conn.send(msg)
    conn.close()


class SerialExecutor:
    """One cell after another in this process (debugging, tiny sweeps, exact tracebacks). A cell
    that kills the interpreter ends the command here (``died`` is never called); the cells
    finished before it are saved."""

    name = "serial"
    workers = 1

    def __enter__(self) -> SerialExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    def map_unordered(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        died: Callable[[T, str], R],
        affinity: Callable[[T], Hashable] | None = None,
    ) -> Iterator[tuple[T, R]]:
        for item in items:
            yield item, fn(item)

    def describe(self) -> str:
        return "serial"


class Pending(Generic[T]):
    """The items a :class:`ProcessExecutor` has yet to hand out, grouped by ``affinity`` (all in
    one group without it), each group in the callers' order; asked by the executor each time a
    worker has room for another item."""

    def __init__(self, items: Sequence[T], affinity: Callable[[T], Hashable] | None) -> None:
        from collections import deque

        self._groups: dict[Hashable, deque[T]] = {}
        for item in items:
            key = affinity(item) if affinity is not None else None
            self._groups.setdefault(key, deque()).append(item)
        self._started: set[Hashable] = set()
        self._affinity = affinity

    def __len__(self) -> int:
        return sum(len(q) for q in self._groups.values())

    def take(self, ran: set[Hashable]) -> T:
        """The next item for a worker that has run the groups ``ran`` (updated): one of those
        groups if any is left; else a group no worker has started, in the callers' order; else
        one from the group with the most items left, so that stragglers share the longest one."""
        key = next((k for k, q in self._groups.items() if q and k in ran), None)
        if key is None:
            key = next((k for k, q in self._groups.items() if q and k not in self._started), None)
        if key is None:
            key = max(self._groups, key=lambda k: len(self._groups[k]))
        ran.add(key)
        self._started.add(key)
        item = self._groups[key].popleft()
        if not self._groups[key]:
            del self._groups[key]
        return item

    def put_back(self, item: T) -> None:
        """Return ``item`` to the front of its group: the worker it was taken for was gone."""
        from collections import deque

        key = self._affinity(item) if self._affinity is not None else None
        self._groups.setdefault(key, deque()).appendleft(item)


class ProcessExecutor:
    """``workers`` local processes, started with ``spawn`` (a fork would copy this process's
    threads, e.g. the progress bar's monitor, into a half-initialised child), each its own
    single-process pool so that this process chooses which worker runs which item (see
    :class:`Pending`).

    At most :data:`QUEUED` items per worker are handed out at a time (one running, one waiting,
    so that a worker starts its next item without a round trip through this process), so when a
    worker dies (and its pool with it) the items in flight are known: each is run again alone in
    a fresh process, ``workers`` at a time; one that kills that process too is given to ``died``,
    the others yield their results, and the remaining items go on in fresh pools.

    Leaving the block does not wait for the workers to exit: they finish in the background
    (joined when this process exits) while the caller goes on, e.g. to the tables."""

    name = "processes"

    def __init__(self, workers: int | None = None) -> None:
        self.workers = workers or default_workers()
        self._pools: list[Any] = []

    def _context(self) -> Any:
        import multiprocessing

        return multiprocessing.get_context("spawn")

    def __enter__(self) -> ProcessExecutor:
        from concurrent.futures import ProcessPoolExecutor

        self._pools = [
            ProcessPoolExecutor(
                1,
                mp_context=self._context(),
                initializer=start_worker,
                initargs=(os.getpid(),),
            )
            for _ in range(self.workers)
        ]
        return self

    def __exit__(self, *exc: object) -> None:
        for pool in self._pools:
            pool.shutdown(wait=False, cancel_futures=True)
        self._pools = []

    def map_unordered(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        died: Callable[[T, str], R],
        affinity: Callable[[T], Hashable] | None = None,
    ) -> Iterator[tuple[T, R]]:
        pending = Pending(items, affinity)
        while pending:
            if not self._pools:
                self.__enter__()
            suspects = yield from self._until_broken(fn, pending)
            if suspects is not None:
                for pool in self._pools:
                    pool.shutdown(wait=True)
                self._pools = []
                for i in range(0, len(suspects), self.workers):
                    yield from self._each_alone(fn, suspects[i : i + self.workers], died)

    def _until_broken(
        self,
        fn: Callable[[T], R],
        pending: Pending[T],
    ) -> Generator[tuple[T, R], None, list[T] | None]:
        """Yield results from the pools until ``pending`` is empty (then return ``None``) or a
        pool breaks (then, once the other pools' items in flight are done, return the broken
        pools' items, maybe none)."""
        from concurrent.futures import ALL_COMPLETED, FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool

        window: dict[Any, tuple[int, T]] = {}  # future -> (worker, item)
        ran: list[set[Hashable]] = [set() for _ in self._pools]
        queued = [0] * len(self._pools)
        suspects: list[T] = []
        broken = False
        try:
            while pending or window:
                for w, pool in enumerate(self._pools):
                    while pending and queued[w] < QUEUED and not broken:
                        item = pending.take(ran[w])
                        try:
                            window[pool.submit(fn, item)] = (w, item)
                        except BrokenProcessPool:
                            pending.put_back(item)
                            broken = True
                            break
                        queued[w] += 1
                # once a pool broke, wait for all: a broken pool fails every future it holds
                done = wait(window, return_when=ALL_COMPLETED if broken else FIRST_COMPLETED).done
                for fut in done:
                    w, item = window.pop(fut)
                    queued[w] -= 1
                    if isinstance(fut.exception(), BrokenProcessPool):
                        suspects.append(item)
                        broken = True
                    else:
                        yield item, fut.result()
                if broken and not window:
                    return suspects
            return None
        finally:
            for fut in window:
                fut.cancel()

    def _each_alone(
        self, fn: Callable[[T], R], items: list[T], died: Callable[[T, str], R]
    ) -> Iterator[tuple[T, R]]:
        """Run every item in a process of its own, all at once (the caller passes at most
        ``workers``), yielding its result or, if that process dies too, ``died``'s."""
        from multiprocessing.connection import wait

        ctx = self._context()
        running: dict[Any, tuple[Any, T]] = {}
        try:
            for item in items:
                recv, send = ctx.Pipe(duplex=False)
                proc = ctx.Process(
                    target=_run_alone, args=(send, fn, item, os.getpid()), daemon=True
                )
                proc.start()
                send.close()  # so that recv sees the end of the pipe when proc dies
                running[recv] = (proc, item)
            while running:
                for conn in wait(list(running)):
                    proc, item = running.pop(conn)
                    try:
                        ok, value = conn.recv()
                    except EOFError:
                        proc.join()
                        how = how_it_died(proc.exitcode)
                        yield (
                            item,
                            died(
                                item,
                                f"the worker process died: {how}, also when run again alone in "
                                "a fresh process",
                            ),
                        )
                        continue
                    finally:
                        conn.close()
                    proc.join()
                    if not ok:
                        raise value
                    yield item, value
        finally:
            for proc, _ in running.values():
                proc.kill()
                proc.join()

    def describe(self) -> str:
        return f"processes ({counted(self.workers, 'worker')})"


class DaskExecutor:
    """A Dask ``distributed`` cluster: the scheduler at ``address`` (``tcp://host:8786``), or a
    LocalCluster of ``workers`` single-threaded worker processes when no address is given.

    A cell whose worker dies is run again once, alone on the cluster after the other cells, then
    given to ``died``. A LocalCluster's scheduler gives up on a cell at its first dead worker
    (``allowed_failures=0``) so that physbench does the retrying; a remote scheduler first retries
    as its own ``allowed-failures`` says.

    The address is a trust boundary: results arrive pickled, and unpickling runs code of the
    sender's choosing, so whoever controls that cluster can run code in this process."""

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
                    # The scheduler logs every cell it gives up on as an error; physbench
                    # reports that cell itself.
                    silence_logs=logging.CRITICAL,
                    scheduler_kwargs={"allowed_failures": 0},
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

    def map_unordered(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        died: Callable[[T, str], R],
        affinity: Callable[[T], Hashable] | None = None,
    ) -> Iterator[tuple[T, R]]:
        """``affinity`` is ignored: the Dask scheduler places tasks itself."""
        from distributed import KilledWorker, as_completed

        running: dict[str, tuple[Any, T]] = {}
        for item in items:
            fut = self._client.submit(fn, item, pure=False)
            running[fut.key] = (fut, item)
        suspects: list[T] = []
        try:
            for fut in as_completed([f for f, _ in running.values()]):
                _, item = running.pop(fut.key)
                try:
                    result = self._result(fut)
                except KilledWorker:  # maybe only queued on the worker another cell killed
                    suspects.append(item)
                    continue
                yield item, result
            for item in suspects:
                # Alone, so that if it kills its worker again it takes no other cell along.
                fut = self._client.submit(fn, item, pure=False)
                running[fut.key] = (fut, item)
                try:
                    result = self._result(fut)
                except KilledWorker:
                    result = died(
                        item,
                        "the Dask worker process died running it (KilledWorker), also when run "
                        "again alone on the cluster",
                    )
                del running[fut.key]
                yield item, result
        finally:
            self._client.cancel([f for f, _ in running.values()])

    @staticmethod
    def _result(fut: Any) -> Any:
        """``fut``'s result; a cell never raises (the runner records its errors), so an exception
        here is the cluster's: ``KilledWorker`` passes, the rest end the sweep."""
        from distributed import KilledWorker

        try:
            return fut.result()
        except KilledWorker:
            raise
        except Exception as exc:
            raise PhysbenchError(
                f"the Dask cluster lost a cell ({type(exc).__name__}: {exc}); finished cells are "
                "saved: re-run the same command to resume"
            ) from None

    def describe(self) -> str:
        return f"dask ({self.address or 'LocalCluster'}, {counted(self.workers, 'worker')})"


def _is_main_guard(node: Any) -> bool:
    """Whether ``node`` (an AST node) is ``if __name__ == "__main__":`` (either order)."""
    import ast

    test = node.test if isinstance(node, ast.If) else None
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1):
        return False
    sides = [test.left, *test.comparators]
    names = {s.id for s in sides if isinstance(s, ast.Name)}
    texts = {s.value for s in sides if isinstance(s, ast.Constant)}
    return isinstance(test.ops[0], ast.Eq) and names == {"__name__"} and texts == {"__main__"}


def guarded(source: str, line: int) -> bool:
    """Whether ``line`` of the Python ``source`` lies in the body of an
    ``if __name__ == "__main__":`` block."""
    import ast

    return any(
        _is_main_guard(node) and node.body[0].lineno <= line <= (node.body[-1].end_lineno or 0)
        for node in ast.walk(ast.parse(source))
    )


def unguarded_main_call() -> tuple[str, int] | None:
    """The script file and line from which this call was made, when a local worker process
    would run that line again: Python's ``spawn`` start method (the only one that is safe with
    threads, see :class:`ProcessExecutor`) starts every worker by running the main script anew,
    under the name ``__mp_main__``, so whatever the script does outside
    ``if __name__ == "__main__":`` happens again in each worker, a sweep included (which then
    finds its own folder locked). ``None`` when the call is guarded, or when the main module is
    not re-run (``python -c``, a notebook, ``python -m pkg``, the ``physbench`` command) or its
    source cannot be read."""
    main = sys.modules.get("__main__")
    spec_name = getattr(getattr(main, "__spec__", None), "name", None) or ""
    path = getattr(main, "__file__", None)
    if main is None or not path or spec_name == "__main__" or spec_name.endswith(".__main__"):
        return None
    frame = sys._getframe(1)
    while frame is not None and not (
        frame.f_globals is vars(main) and frame.f_code.co_name == "<module>"
    ):
        frame = frame.f_back  # type: ignore[assignment]
    if frame is None:  # not called while the script's top level runs
        return None
    try:
        if guarded(Path(path).read_text(encoding="utf-8"), frame.f_lineno):
            return None
    except (OSError, SyntaxError, ValueError):
        return None
    return str(path), frame.f_lineno


def check_main_guard(executor: str) -> None:
    """Refuse, before any cell runs, a sweep on local worker processes started from a script's
    top level outside ``if __name__ == "__main__":`` (:func:`unguarded_main_call`)."""
    where = unguarded_main_call()
    if where is None:
        return
    path, line = where
    raise PhysbenchError(
        f"{path}, line {line}: a sweep on local worker processes (executor {executor!r}) is "
        'started outside `if __name__ == "__main__":`. Each worker process starts by running '
        "this script again (Python's spawn start method), which would start the sweep again in "
        'every worker. Put the script\'s work under `if __name__ == "__main__":` (as in '
        "help(physbench.sweep)), or run the cells in this process with executor='serial'"
    )


def make_executor(name: str, *, workers: int | None = None, address: str | None = None) -> Executor:
    """The executor ``name`` (one of :data:`NAMES`); ``workers`` defaults to all cores. Local
    worker processes (``processes``, a ``dask`` LocalCluster) are refused when the main script
    would start the sweep again in each of them (:func:`check_main_guard`)."""
    from physbench import numeric

    if workers is not None and not numeric.WORKERS.accepts(workers):
        raise PhysbenchError(f"--workers {workers!r}: expected {numeric.WORKERS.describe()}")
    if address and name != "dask":
        raise PhysbenchError(
            f"--address {address!r} names a Dask scheduler; it needs --executor dask (got {name!r})"
        )
    if name == "processes" or (name == "dask" and not address):
        check_main_guard(name)
    if name == "serial":
        return SerialExecutor()
    if name == "processes":
        return ProcessExecutor(workers)
    if name == "dask":
        return DaskExecutor(address, workers)
    raise PhysbenchError(
        f"--executor {name!r}: unknown executor; known executors: {', '.join(NAMES)}"
    )
