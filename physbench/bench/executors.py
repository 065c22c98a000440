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
estimator and engine, whose libraries take up to 2 s to import): the ``processes`` and ``dask``
executors then give a free worker the items of groups it has already run, so each group's imports
are paid by as few workers as the load allows instead of by every worker
(:mod:`~physbench.bench.placement`).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Generator, Hashable, Iterator, Sequence
from pathlib import Path
from typing import Any, Protocol, TypeVar

from physbench.bench.placement import Pending, timed_call
from physbench.errors import PhysbenchError, counted

T = TypeVar("T")
R = TypeVar("R")
NAMES = ("serial", "processes", "dask")
#: Items a worker holds at most: one running, one queued behind it (while at least as many items
#: as workers are left; fewer, and each worker holds one, so that none waits behind another's).
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


class ProcessExecutor:
    """``workers`` local processes, started with ``spawn`` (a fork would copy this process's
    threads, e.g. the progress bar's monitor, into a half-initialised child), each its own
    single-process pool so that this process chooses which worker runs which item (see
    :class:`~physbench.bench.placement.Pending`).

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
        generation = 0
        while pending:
            if not self._pools:
                self.__enter__()
            generation += 1
            suspects = yield from self._until_broken(fn, pending, generation)
            if suspects is not None:
                for pool in self._pools:
                    pool.shutdown(wait=True)
                for w in range(len(self._pools)):
                    pending.forget((generation, w))
                self._pools = []
                for i in range(0, len(suspects), self.workers):
                    yield from self._each_alone(fn, suspects[i : i + self.workers], died)

    def _until_broken(
        self,
        fn: Callable[[T], R],
        pending: Pending[T],
        generation: int,
    ) -> Generator[tuple[T, R], None, list[T] | None]:
        """Yield results from the pools (worker ``w`` is ``(generation, w)`` to ``pending``)
        until ``pending`` is empty (then return ``None``) or a pool breaks (then, once the other
        pools' items in flight are done, return the broken pools' items, maybe none)."""
        from concurrent.futures import ALL_COMPLETED, FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool

        window: dict[Any, tuple[int, T]] = {}  # future -> (worker, item)
        queued = [0] * len(self._pools)
        suspects: list[T] = []
        broken = False

        def hand_out(w: int, *, force: bool = False) -> None:
            nonlocal broken
            limit = QUEUED if len(pending) >= len(self._pools) else 1
            while pending and queued[w] < limit and not broken:
                item = pending.take((generation, w), force=force)
                if item is None:
                    return
                try:
                    window[self._pools[w].submit(timed_call, fn, item)] = (w, item)
                except BrokenProcessPool:
                    pending.put_back(item)
                    broken = True
                    return
                queued[w] += 1
                force = False

        try:
            while pending or window:
                for w in range(len(self._pools)):
                    hand_out(w)
                if pending and not window and not broken:  # every worker chose to wait
                    hand_out(queued.index(min(queued)), force=True)
                # once a pool broke, wait for all: a broken pool fails every future it holds
                done = wait(window, return_when=ALL_COMPLETED if broken else FIRST_COMPLETED).done
                for fut in done:
                    w, item = window.pop(fut)
                    queued[w] -= 1
                    if isinstance(fut.exception(), BrokenProcessPool):
                        suspects.append(item)
                        broken = True
                    else:
                        seconds, result = fut.result()
                        pending.done((generation, w), item, seconds)
                        yield item, result
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


#: Dask settings for the LocalCluster physbench starts (its workers get them from its nannies).
LOCAL_DASK_CONFIG = {
    # Dask sets MALLOC_TRIM_THRESHOLD_=65536 in the workers it spawns, so that glibc hands freed
    # memory back at once; a cell then faults its frames' memory in again and again: 42-43 ms of
    # CPU per smoke cell against 27-30 ms without it (measured on the development VM).
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    # The statistical profiler samples every thread's stack every 10 ms, for a dashboard that a
    # physbench LocalCluster does not open; the monitors below poll for it too. Together they
    # cost an idle 2-worker cluster 0.065 CPU-s per second, 0.016 with these settings.
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
    # Cells are placed by physbench (see map_unordered), at most QUEUED per worker: nothing to
    # steal.
    "distributed.scheduler.work-stealing": False,
}


#: Cells one Dask task runs at most. Each task costs this process ~4 ms of CPU (the client's
#: messages and the LocalCluster's scheduler, beside physbench's own ~2 ms per cell): alone, a
#: 2-worker LocalCluster of trivial cells ran 5x slower than local processes. A task of several
#: cells shares that cost; tasks shrink to one cell towards the end of a sweep
#: (:func:`chunk_size`), so that no worker waits behind another's chunk.
CHUNK = 4
#: A chunk is at most this fraction of what is left per worker thread.
CHUNK_SHARE = 8


def chunk_size(left: int, threads: int) -> int:
    """Cells per Dask task while ``left`` cells wait for ``threads`` worker threads."""
    return max(1, min(CHUNK, left // (CHUNK_SHARE * max(threads, 1))))


def timed_calls(fn: Callable[[T], R], items: list[T], own: bool) -> list[tuple[float, R]]:
    """:func:`timed_call` for each of ``items`` (one Dask task); ``own``: the worker is one of
    physbench's own LocalCluster, whose process then ends without the interpreter's teardown
    (as the ``processes`` executor's do, :func:`start_worker`): closing a 2-worker LocalCluster
    took 1.2-1.7 s, 0.1 s this way."""
    if own and not _ENDS_EARLY:
        from physbench.teardown import skip_at_exit

        skip_at_exit(lambda: 0)
        _ENDS_EARLY.append(True)
    return [timed_call(fn, item) for item in items]


#: Set in a worker process once :func:`timed_calls` made it end without teardown.
_ENDS_EARLY: list[bool] = []


#: Seconds between two looks at a Dask cluster's workers. Each look is a round trip to the
#: scheduler; made for every finished cell (with every worker's details, as before), it cost this
#: process ~8 ms of CPU per cell and capped a 2-worker LocalCluster at 27 cells/s. Workers that
#: join are given cells within this time; a cell handed to one that left is run elsewhere by
#: the scheduler (a loose restriction).
LOOK_EVERY = 1.0


class DaskExecutor:
    """A Dask ``distributed`` cluster: the scheduler at ``address`` (``tcp://host:8786``), or a
    LocalCluster of ``workers`` single-threaded worker processes when no address is given
    (started with :data:`LOCAL_DASK_CONFIG`).

    Cells are handed out as by :class:`ProcessExecutor`: at most :data:`QUEUED` tasks per worker
    thread at a time, each of up to :data:`CHUNK` cells (:func:`chunk_size`), to a worker chosen
    by ``affinity`` (:class:`~.placement.Pending`), as a loose restriction
    (``workers=[address], allow_other_workers=True``: if that worker leaves, the scheduler runs
    the task elsewhere). Workers that join a remote cluster get cells within
    :data:`LOOK_EVERY` seconds.

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
        self._seen: set[str] = set()  # the workers cells were last handed to
        self._nthreads: dict[str, int] = {}  # the scheduler's answer at self._asked
        self._asked = -float("inf")

    def __enter__(self) -> DaskExecutor:
        import logging

        try:
            import dask
            from distributed import Client, LocalCluster
        except ImportError:
            raise PhysbenchError(
                "--executor dask needs the 'distributed' package: pip install 'physbench[dist]'"
            ) from None
        try:
            if self.address:
                self._client = Client(self.address, timeout="20s")
                self.workers = max(1, sum(self._threads(fresh=True).values()))
            else:
                with dask.config.set(LOCAL_DASK_CONFIG):
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

    def _threads(self, *, fresh: bool = False) -> dict[str, int]:
        """Each worker's address and threads: asked of the scheduler at most every
        :data:`LOOK_EVERY` seconds, or now with ``fresh``."""
        now = time.monotonic()
        if fresh or now - self._asked >= LOOK_EVERY:
            self._nthreads = {a: int(n) for a, n in self._client.nthreads().items()}
            self._asked = now
        return self._nthreads

    def map_unordered(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        died: Callable[[T, str], R],
        affinity: Callable[[T], Hashable] | None = None,
    ) -> Iterator[tuple[T, R]]:
        from distributed import KilledWorker, as_completed

        pending = Pending(items, affinity)
        running: dict[str, tuple[Any, list[T], str]] = {}  # future key -> (future, items, worker)
        finished = as_completed()
        suspects: list[T] = []
        try:
            self._refill(fn, pending, running, finished)
            for fut in finished:
                _, chunk, addr = running.pop(fut.key)
                try:
                    results = self._result(fut)
                except KilledWorker:  # maybe only queued on the worker another cell killed
                    suspects += chunk
                    self._refill(fn, pending, running, finished)
                    continue
                for item, (seconds, _) in zip(chunk, results, strict=True):
                    pending.done(addr, item, seconds)
                self._refill(fn, pending, running, finished)
                for item, (_, result) in zip(chunk, results, strict=True):
                    yield item, result
            yield from self._alone(fn, suspects, died, running)
        finally:
            self._client.cancel([f for f, _, _ in running.values()])

    def _refill(
        self,
        fn: Callable[[T], R],
        pending: Pending[T],
        running: dict[str, tuple[Any, list[T], str]],
        finished: Any,
    ) -> None:
        """Hand each worker items from ``pending`` as :class:`ProcessExecutor` does, :data:`QUEUED`
        tasks per thread, each of up to :func:`chunk_size` items; with none in flight and no
        worker (a LocalCluster's nanny restarting the only one), wait for one."""
        if pending and not running and not self._threads(fresh=True):
            try:
                self._client.wait_for_workers(1, timeout=60)
            except TimeoutError:
                raise PhysbenchError(
                    "the Dask cluster has no workers left (none joined in 60 s); finished cells "
                    "are saved: re-run the same command to resume"
                ) from None
        threads = self._threads()
        for addr in self._seen - threads.keys():
            pending.forget(addr)
        self._seen = set(threads)
        held: dict[str, int] = {}
        for _, _, addr in running.values():
            held[addr] = held.get(addr, 0) + 1
        force = not running
        total = sum(threads.values())
        own = self._cluster is not None
        for addr, n in threads.items():
            limit = n * (QUEUED if len(pending) >= total else 1)
            while pending and held.get(addr, 0) < limit:
                chunk: list[T] = []
                size = chunk_size(len(pending), total)
                while pending and len(chunk) < size:
                    item = pending.take(addr, force=force)
                    if item is None:
                        break
                    chunk.append(item)
                    force = False
                if not chunk:
                    break
                fut = self._client.submit(
                    timed_calls,
                    fn,
                    chunk,
                    own,
                    pure=False,
                    workers=[addr],
                    allow_other_workers=True,
                )
                running[fut.key] = (fut, chunk, addr)
                held[addr] = held.get(addr, 0) + 1
                finished.add(fut)

    def _alone(
        self,
        fn: Callable[[T], R],
        suspects: list[T],
        died: Callable[[T, str], R],
        running: dict[str, tuple[Any, list[T], str]],
    ) -> Iterator[tuple[T, R]]:
        """Run each suspect again, one at a time, so that if it kills its worker again it takes
        no other cell along; yield its result or ``died``'s."""
        from distributed import KilledWorker

        for item in suspects:
            own = self._cluster is not None
            fut = self._client.submit(timed_calls, fn, [item], own, pure=False)
            running[fut.key] = (fut, [item], "")
            try:
                [(_, result)] = self._result(fut)
            except KilledWorker:
                result = died(
                    item,
                    "the Dask worker process died running it (KilledWorker), also when run "
                    "again alone on the cluster",
                )
            del running[fut.key]
            yield item, result

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
