"""Where cells run: ``make_executor`` builds each executor by name with its worker count and
refuses bad names, counts and addresses; ``map_unordered`` yields every item once with its result,
and an item whose worker process dies is run again alone once, then given to ``died``. (That every
executor gives the same table: ``test_executors_give_identical_tables`` in test_runner.py.)"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest

from physbench.bench.executors import (
    CHUNK,
    NAMES,
    QUEUED,
    DaskExecutor,
    ProcessExecutor,
    SerialExecutor,
    chunk_size,
    default_workers,
    make_executor,
)
from physbench.bench.placement import Pending
from physbench.errors import PhysbenchError

ITEMS = [-3, 1, -4, 1, -5, 9, -2, 6]


def _never(item: object, error: str) -> object:
    raise AssertionError(f"no process died, yet died({item!r}, {error!r}) was called")


def test_names_build_their_executor_with_all_cores_by_default() -> None:
    assert NAMES == ("serial", "processes", "dask")
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert default_workers() == cores
    serial, processes, dask = (make_executor(name) for name in NAMES)
    assert isinstance(serial, SerialExecutor) and serial.workers == 1
    assert isinstance(processes, ProcessExecutor) and processes.workers == cores
    assert isinstance(dask, DaskExecutor) and dask.workers == cores and dask.address is None


def test_worker_counts_and_addresses_are_kept_and_described() -> None:
    assert make_executor("processes", workers=3).describe() == "processes (3 workers)"
    assert make_executor("processes", workers=1).describe() == "processes (1 worker)"
    assert make_executor("dask", workers=1).describe() == "dask (LocalCluster, 1 worker)"
    assert make_executor("dask", workers=2).describe() == "dask (LocalCluster, 2 workers)"
    remote = make_executor("dask", workers=2, address="tcp://host:8786")
    assert remote.describe() == "dask (tcp://host:8786, 2 workers)"
    assert make_executor("serial").describe() == "serial"


@pytest.mark.parametrize(
    ("name", "kwargs", "message"),
    [
        ("processes", {"workers": 0}, "--workers 0: expected a whole number in [1, 512]"),
        ("serial", {"workers": True}, "--workers True: expected a whole number in [1, 512]"),
        ("processes", {"workers": 10**9}, "--workers 1000000000: expected a whole number in"),
        (
            "processes",
            {"address": "tcp://x:1"},
            "--address 'tcp://x:1' names a Dask scheduler; it needs --executor dask "
            "(got 'processes')",
        ),
        (
            "threads",
            {},
            "--executor 'threads': unknown executor; known executors: serial, processes, dask",
        ),
    ],
)
def test_bad_settings_are_named(name: str, kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(PhysbenchError) as err:
        make_executor(name, **kwargs)  # type: ignore[arg-type]
    assert str(err.value).startswith(message)


SCRIPT = """\
import physbench

def main():
    physbench.sweep(SPEC, OUT)

if __name__ == "__main__":
    main()  # guarded
    physbench.sweep(SPEC, OUT)  # guarded too
else:
    main()  # the workers' re-run reaches this
main()  # unguarded
"""


@pytest.mark.parametrize(
    ("line", "guarded_"), [(4, False), (7, True), (8, True), (10, False), (11, False)]
)
def test_a_line_is_guarded_inside_the_main_block_only(line: int, guarded_: bool) -> None:
    from physbench.bench.executors import guarded

    assert guarded(SCRIPT, line) is guarded_
    reversed_test = SCRIPT.replace('__name__ == "__main__"', "'__main__' == __name__")
    assert guarded(reversed_test, line) is guarded_


def test_serial_maps_in_order() -> None:
    with make_executor("serial") as ex:
        assert list(ex.map_unordered(abs, ITEMS, _never)) == [(x, abs(x)) for x in ITEMS]


def test_processes_yield_every_item_once_with_its_result() -> None:
    with make_executor("processes", workers=2) as ex:
        got = list(ex.map_unordered(abs, ITEMS, _never))
    assert sorted(got) == sorted((x, abs(x)) for x in ITEMS)


def _group(item: str) -> str:
    return item[0]


def test_a_worker_keeps_to_the_groups_it_has_run_then_starts_a_new_one() -> None:
    pending = Pending(["a1", "b1", "a2", "b2", "c1", "a3"], _group)
    taken = [pending.take("first"), pending.take("second"), pending.take("second")]
    assert taken == ["a1", "b1", "b2"]  # the second worker starts b, a group nobody has started
    assert [pending.take("first"), pending.take("first"), pending.take("second")] == [
        "a2",
        "a3",
        "c1",
    ]
    assert not pending


def test_without_estimates_a_worker_with_nothing_of_its_own_helps_the_longest_group() -> None:
    pending = Pending(["a1", "b1", "b2", "c1", "c2", "c3"], _group)
    assert [pending.take(w) for w in ("x", "y", "z")] == ["a1", "b1", "c1"]
    assert pending.take("x") == "c2"  # c has 2 left, b 1; no item has finished yet
    pending.put_back("c2")
    assert pending.take("z") == "c2" and len(pending) == 2


def _timed_groups(left: int) -> Pending[str]:
    """Group a: 1 s per item, 5 s more for a worker's first (its imports), ``left`` items left
    on its one worker; group b: done."""
    pending = Pending([f"a{i}" for i in range(3 + left)] + ["b0"], _group)
    assert [pending.take("on a") for _ in range(3)] == ["a0", "a1", "a2"]
    for item, seconds in (("a0", 6.0), ("a1", 1.0), ("a2", 1.0)):
        pending.done("on a", item, seconds)
    assert pending.take("on b") == "b0"
    assert pending.estimates("a") == (1.0, 5.0)
    return pending


def test_a_worker_joins_a_started_group_only_while_that_pays() -> None:
    # 5 items left: its worker needs 5 s, a newcomer 6 s for its first: wait
    pending = _timed_groups(5)
    assert pending.take("on b") is None
    assert pending.take("on b", force=True) == "a3"  # nothing else in flight: go anyway
    # 7 items left: 7 s against 6 s: join
    assert _timed_groups(7).take("on b") == "a3"
    # a group whose workers are gone is taken up whatever it costs
    pending = _timed_groups(1)
    pending.forget("on a")
    assert pending.take("on b") == "a3"


def test_without_affinity_items_go_in_the_callers_order() -> None:
    pending = Pending(ITEMS, None)
    assert [pending.take(i % 3) for i in range(len(ITEMS))] == ITEMS


def test_dask_tasks_hold_several_cells_until_the_end_of_a_sweep_nears() -> None:
    # 960 cells on 16 worker threads: CHUNK cells a task, so that the client's and the
    # scheduler's cost per task is shared
    assert chunk_size(960, 16) == CHUNK
    # fewer left: smaller tasks, then one cell each, so that no worker waits behind a chunk
    assert chunk_size(200, 16) == 1
    assert [chunk_size(n, 2) for n in (64, 48, 32, 16, 15, 1, 0)] == [4, 3, 2, 1, 1, 1, 1]


def test_dask_looks_at_its_workers_once_a_second_not_for_every_cell() -> None:
    class Client:
        asked = 0

        def nthreads(self) -> dict[str, int]:
            Client.asked += 1
            return {"tcp://w1": 1, "tcp://w2": 1}

    ex = DaskExecutor(workers=2)
    ex._client = Client()
    for _ in range(50):
        assert ex._threads() == {"tcp://w1": 1, "tcp://w2": 1}
    assert Client.asked == 1
    ex._threads(fresh=True)  # e.g. when no cell is in flight
    assert Client.asked == 2


def test_dask_chunks_give_every_item_once(
    tmp_path: Path, plugin: Callable[..., ModuleType], monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("distributed")
    monkeypatch.setenv("PB_GO_FILE", str(tmp_path / "go"))
    stamping = plugin("pb_stamping", STAMPING)
    items = [f"{g}{i}" for i in range(40) for g in "ab"]  # chunks of 4, then fewer
    with make_executor("dask", workers=2) as ex:
        got = list(ex.map_unordered(stamping.pid_of, items, _never, _group))
    assert sorted(item for item, _ in got) == sorted(items)
    assert len({pid for _, pid in got}) == 2


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_each_group_runs_in_the_worker_that_started_it(
    executor: str,
    tmp_path: Path,
    plugin: Callable[..., ModuleType],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    if executor == "dask":
        pytest.importorskip("distributed")
    monkeypatch.setenv("PB_GO_FILE", str(tmp_path / "go"))
    stamping = plugin("pb_stamping", STAMPING)
    # QUEUED items of each group: all are handed out at once, so none is left to share.
    items = [f"{g}{i}" for i in range(QUEUED) for g in "ab"]
    with make_executor(executor, workers=2) as ex:
        pids = dict(ex.map_unordered(stamping.pid_of, items, _never, _group))
    assert sorted(pids) == sorted(items)
    assert {pids[f"a{i}"] for i in range(QUEUED)} == {pids["a0"]}
    assert {pids[f"b{i}"] for i in range(QUEUED)} == {pids["b0"]} != {pids["a0"]}


#: A worker function that kills its process for some items, and logs every call to ``LOG``.
DYING = """
import os
import subprocess
import sys
import time
import signal

LOG = os.environ["PB_DYING_LOG"]


def crash_on(x):
    with open(LOG, "a") as f:
        f.write(f"{x}\\n")
    if x == 3:
        os._exit(3)
    if x == 11:
        os.kill(os.getpid(), signal.SIGSEGV)
    return -x
"""


@pytest.mark.parametrize("affinity", [None, lambda x: x % 2], ids=["one group", "odd and even"])
def test_items_that_kill_their_worker_are_retried_once_then_given_to_died(
    affinity: Callable[[int], int] | None,
    tmp_path: Path,
    plugin: Callable[..., ModuleType],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    log = tmp_path / "calls.txt"
    monkeypatch.setenv("PB_DYING_LOG", str(log))
    dying = plugin("pb_dying", DYING)
    items = [1, 3, 2, 11, 4, 5, 6, 7]
    with make_executor("processes", workers=2) as ex:
        got = dict(ex.map_unordered(dying.crash_on, items, lambda x, error: error, affinity))
    again = ", also when run again alone in a fresh process"
    assert got == {
        **{x: -x for x in items if x not in (3, 11)},
        3: "the worker process died: exit code 3" + again,
        11: "the worker process died: signal 11 (SIGSEGV)" + again,
    }
    calls = Counter(int(line) for line in log.read_text().split())
    # Once alone after the pool broke (the messages above say so), and at most once before: an
    # item in flight when another one broke the pool may not have started there yet.
    assert 1 <= calls[3] <= 2 and 1 <= calls[11] <= 2
    assert set(calls) == set(items) and max(calls.values()) <= 2


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead but not yet reaped by its new parent, does not)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    return "\nState:\tZ" not in status


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc")
def test_a_killed_sweep_leaves_no_local_dask_worker_behind() -> None:
    pytest.importorskip("distributed")
    code = (
        "import os, time\n"
        "from physbench.bench.executors import DaskExecutor\n"
        "with DaskExecutor(workers=2) as ex:\n"
        "    print(*ex._client.run(os.getpid).values(), flush=True)\n"
        "    time.sleep(120)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        workers = [int(pid) for pid in proc.stdout.readline().split()]
        assert len(workers) == 2 and all(_alive(pid) for pid in workers)
    finally:
        proc.kill()  # SIGKILL: no cleanup runs in the main process
        proc.wait()
    deadline = time.monotonic() + 10
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [pid for pid in workers if _alive(pid)]


#: Worker functions for the pipelining and shutdown tests.
STAMPING = """
import atexit
import os
import time
from pathlib import Path

GO = Path(os.environ["PB_GO_FILE"])


def started(x):
    return time.time()


def pid_of(x):
    return os.getpid()


def _wait_for_go():
    deadline = time.monotonic() + 5
    while not GO.exists() and time.monotonic() < deadline:
        time.sleep(0.02)


def lingering(x):
    # at this worker's exit, wait (at most 5 s) until the test has created GO
    atexit.register(_wait_for_go)
    return x
"""


def test_a_worker_has_its_next_item_before_the_caller_takes_a_result(
    tmp_path: Path, plugin: Callable[..., ModuleType], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PB_GO_FILE", str(tmp_path / "go"))
    stamping = plugin("pb_stamping", STAMPING)
    with make_executor("processes", workers=1) as ex:
        results = ex.map_unordered(stamping.started, [0, 1], _never)
        next(results)
        time.sleep(1.0)  # the caller is busy (storing a cell, say)
        busy_until = time.time()
        _, second_started = next(results)
    assert second_started < busy_until


def test_leaving_the_pool_does_not_wait_for_its_workers_to_exit(
    tmp_path: Path, plugin: Callable[..., ModuleType], monkeypatch: pytest.MonkeyPatch
) -> None:
    go = tmp_path / "go"
    monkeypatch.setenv("PB_GO_FILE", str(go))
    stamping = plugin("pb_stamping", STAMPING)
    ex = make_executor("processes", workers=1)
    with ex:
        assert [r for _, r in ex.map_unordered(stamping.lingering, [7], _never)] == [7]
        t0 = time.monotonic()
    left_after = time.monotonic() - t0
    go.touch()
    assert left_after < 2.5  # waiting for the worker would take the 5 s it lingers
