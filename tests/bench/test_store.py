"""Resume: a real ``physbench bench`` process killed (SIGKILL) twice mid-sweep and re-run ends with
exactly the rows of an uninterrupted run, none lost, none duplicated.

This module doubles as the plugin that provides ``slow_random`` (random search that sleeps in
``propose``), loaded by the subprocesses through ``PHYSBENCH_PLUGINS``, so that a sweep lasts long
enough to be killed between cells.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest

from physbench.bench.tables import without_timings
from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl

SPEC = """
name = "resume"
estimators = ["slow_random", "random"]
seeds = 4
iterations = 3
resolution = 32

[[scenes]]
name = "three_circles"
unknowns = ["mass", "elasticity"]
"""
CELLS = 2 * 2 * 4


class SlowRandom(CorrectionEstimator):
    name: ClassVar[str] = "slow_random"

    def __init__(self) -> None:
        self.options: dict[str, Any] = {}

    def start(self, task: Any, *, seed: int) -> None:
        self.space, self.rng = task.space, np.random.default_rng(seed)

    def propose(self, step: Any) -> dict[str, float]:
        time.sleep(0.04)
        return self.space.from_unit(self.rng.random(len(self.space)))


@hookimpl
def register_estimators() -> list[type]:
    return [SlowRandom]


def _env() -> dict[str, str]:
    here = str(Path(__file__).parent)
    path = os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH", "")]))
    return {**os.environ, "PYTHONPATH": path, "PHYSBENCH_PLUGINS": Path(__file__).stem}


def _bench(spec: Path, out: Path) -> list[str]:
    return [
        sys.executable,
        "-m",
        "physbench.cli",
        "bench",
        str(spec),
        "--out",
        str(out),
        "--executor",
        "serial",
        "-q",
    ]


def _kill_after(spec: Path, out: Path, files: int) -> int:
    """Start a sweep, SIGKILL it once ``files`` cell files exist; returns how many exist then."""
    proc = subprocess.Popen(
        _bench(spec, out), env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    cells = out / "cells"
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if cells.is_dir() and len(list(cells.glob("*.json"))) >= files:
                break
            time.sleep(0.005)
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
    assert proc.returncode == -signal.SIGKILL, (
        f"the sweep ended before it was killed: {err.decode()[-2000:]}"
    )
    return len(list(cells.glob("*.json")))


@pytest.mark.slow
def test_killed_sweep_resumes_to_the_uninterrupted_table(tmp_path: Path) -> None:
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC)
    out = tmp_path / "killed"
    first = _kill_after(spec, out, 1)
    assert 1 <= first < CELLS and not (out / "results.parquet").exists()
    second = _kill_after(
        spec, out, first + 3
    )  # the resumed run skips the saved cells, then dies again
    assert first < second < CELLS
    done = subprocess.run(_bench(spec, out), env=_env(), capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert f"{CELLS - second} run, {second} already done" in done.stdout

    ref = tmp_path / "straight"
    straight = subprocess.run(_bench(spec, ref), env=_env(), capture_output=True, text=True)
    assert straight.returncode == 0, straight.stderr

    got, want = pd.read_parquet(out / "results.parquet"), pd.read_parquet(ref / "results.parquet")
    assert len(got) == CELLS * 3 and not got.duplicated(["cell", "iteration"]).any()
    assert got["cell"].nunique() == CELLS and (got["status"] == "ok").all()
    pd.testing.assert_frame_equal(without_timings(got), without_timings(want), check_exact=True)
    assert not list(out.rglob("*.tmp"))


# ---------------------------------------------------------------- the sweep's cell writer


def _cells(n: int) -> list[tuple[str, dict[str, Any]]]:
    return [(f"c{i:04d}", {"i": i, "values": [0.1 * i, None], "status": "ok"}) for i in range(n)]


def test_the_writer_stores_every_cell_whole_and_hands_back_what_load_reads(
    tmp_path: Path,
) -> None:
    from physbench.bench.store import BATCH, CellStore, CellWriter

    store = CellStore(tmp_path)
    store.dir.mkdir(parents=True)
    seen: dict[str, dict[str, Any]] = {}
    cells = _cells(2 * BATCH + 5)  # more than one batch
    with CellWriter(store, lambda key, data: seen.__setitem__(key, data)) as writer:
        for key, data in cells:
            writer.put(key, data)
    assert seen == {key: store.load(key) for key, _ in cells}
    assert seen["c0003"] == {"i": 3, "values": [0.30000000000000004, None], "status": "ok"}
    assert sorted(p.name for p in store.dir.iterdir()) == [f"{key}.json" for key, _ in cells]


def test_the_loop_hands_cells_over_without_waiting_for_the_disk(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.bench import store as store_module

    flushed: list[float] = []

    def slow_flush(f: Any) -> None:  # a disk whose fsync takes 0.2 s
        time.sleep(0.2)
        flushed.append(time.monotonic())

    monkeypatch.setattr(store_module, "_flush", slow_flush)
    store = store_module.CellStore(tmp_path)
    store.dir.mkdir(parents=True)
    t0 = time.monotonic()
    with store_module.CellWriter(store) as writer:
        slowest_put = 0.0
        for key, data in _cells(48):
            t = time.monotonic()
            writer.put(key, data)
            slowest_put = max(slowest_put, time.monotonic() - t)
            time.sleep(0.005)  # cells arriving one after another
    took = time.monotonic() - t0
    assert len(flushed) == 48 and len(list(store.dir.glob("*.json"))) == 48
    assert slowest_put < 0.1  # never a flush's 0.2 s
    assert took < 3.0  # flushed one after another, 48 cells take 9.6 s


def test_a_failed_write_is_raised_in_the_loop(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.bench import store as store_module

    def full(f: Any) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(store_module, "_flush", full)
    store = store_module.CellStore(tmp_path)
    store.dir.mkdir(parents=True)
    with pytest.raises(OSError, match="No space left"), store_module.CellWriter(store) as writer:
        for key, data in _cells(20):
            writer.put(key, data)
            time.sleep(0.01)
    assert not list(store.dir.glob("*.json"))  # no cell renamed into place half-flushed


def test_cells_handed_over_before_an_interrupt_are_stored(tmp_path: Path) -> None:
    from physbench.bench.store import CellStore, CellWriter

    store = CellStore(tmp_path)
    store.dir.mkdir(parents=True)
    with pytest.raises(KeyboardInterrupt), CellWriter(store) as writer:
        for key, data in _cells(5):
            writer.put(key, data)
        raise KeyboardInterrupt
    assert [store.load(key) for key, _ in _cells(5)] == [data for _, data in _cells(5)]
