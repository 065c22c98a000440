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
