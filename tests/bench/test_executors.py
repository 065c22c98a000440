"""Where cells run: ``make_executor`` builds each executor by name with its worker count and
refuses bad names, counts and addresses; ``map_unordered`` yields every item once with its result,
and a worker process that dies is a clear error. (That every executor gives the same table:
``test_executors_give_identical_tables`` in test_runner.py.)"""

from __future__ import annotations

import os

import pytest

from physbench.bench.executors import (
    NAMES,
    DaskExecutor,
    ProcessExecutor,
    SerialExecutor,
    default_workers,
    make_executor,
)
from physbench.errors import PhysbenchError

ITEMS = [-3, 1, -4, 1, -5, 9, -2, 6]


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
        ("processes", {"workers": 0}, "--workers 0: expected a whole number >= 1"),
        ("serial", {"workers": True}, "--workers True: expected a whole number >= 1"),
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
    assert str(err.value) == message


def test_serial_maps_in_order() -> None:
    with make_executor("serial") as ex:
        assert list(ex.map_unordered(abs, ITEMS)) == [(x, abs(x)) for x in ITEMS]


def test_processes_yield_every_item_once_with_its_result() -> None:
    with make_executor("processes", workers=2) as ex:
        got = list(ex.map_unordered(abs, ITEMS))
    assert sorted(got) == sorted((x, abs(x)) for x in ITEMS)


def test_a_worker_that_dies_is_a_clear_error() -> None:
    died = r"^a worker process died \(.*\); finished cells are saved: re-run the same command"
    with pytest.raises(PhysbenchError, match=died), make_executor("processes", workers=1) as ex:
        list(ex.map_unordered(os._exit, [3]))
