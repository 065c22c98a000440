"""``physbench bench SPEC --out DIR``: the table and the final line, ``--fresh``, a plugin renderer
chosen with ``--renderer``, stale cells refused until ``--allow-stale`` or ``--fresh``, clear errors
for bad specs and output folders, and an interrupt that says how to resume."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pandas as pd
import pytest

from physbench.bench.runner import run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import without_timings
from physbench.cli import main

#: What building the parser must not import (the work happens in ``main``).
PARSING_HEAVY = ("numpy", "pandas", "physbench.bench.runner", "matplotlib")


def test_cli_prints_table_and_final_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "cli"\nestimators = ["random"]\nseeds = 2\niterations = 2\nresolution = 16\n'
        '[[scenes]]\nname = "second_order"\nunknowns = ["elasticity"]\n'
    )
    argv = ["bench", str(spec), "--out", str(tmp_path / "o"), "--executor", "serial"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "| second order | paper NN | (4 ± 2)e-03 |" in out
    assert out.splitlines()[-1].startswith("cli: 2 cells (2 run, 0 already done, 0 failed) in ")
    assert (tmp_path / "o" / "spec.toml").read_text() == spec.read_text()
    assert main([*argv, "-q", "--fresh"]) == 0
    assert "(2 run, 0 already done" in capsys.readouterr().out


def test_a_plugin_renderer_is_selected_on_the_command_line(
    tmp_path: Path, blocks: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    small = {
        "name": "tiny",
        "estimators": ["random"],
        "seeds": 2,
        "iterations": 3,
        "resolution": 32,
        "scenes": ["second_order"],
        "renderer": {"name": "blocks", "options": {"gain": 0.5}},
    }
    df = run_sweep(parse_spec(small), tmp_path / "spec", executor="serial", progress=False).table
    toml = tmp_path / "s.toml"
    toml.write_text(
        'name = "cli"\nestimators = ["random"]\nseeds = 2\niterations = 3\nresolution = 32\n'
        'scenes = ["second_order"]\n'
    )
    before = blocks.CALLS
    argv = ["bench", str(toml), "--out", str(tmp_path / "cli"), "--executor", "serial", "-q"]
    assert main([*argv, "--renderer", "blocks", "-R", "gain=0.5"]) == 0
    renders = blocks.CALLS - before
    assert renders == before  # as many renders as the spec's run
    cli = pd.read_parquet(tmp_path / "cli" / "results.parquet")
    pd.testing.assert_frame_equal(without_timings(cli), without_timings(df), check_exact=True)
    capsys.readouterr()
    assert main([*argv, "--renderer", "nope"]) == 2
    err = capsys.readouterr().err
    assert "--renderer = 'nope': unknown renderer 'nope'; known renderers: " in err, err


def test_a_changed_scene_generator_is_refused_until_allowed(
    tmp_path: Path, toy: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["bench", str(tmp_path / "spec.toml"), "--out", str(tmp_path), "-q"]
    (tmp_path / "spec.toml").write_text(
        'name = "toy"\nestimators = ["toy", "random"]\nseeds = 3\niterations = 2\n'
        'resolution = 16\n[[scenes]]\nname = "toy_scene"\nunknowns = ["mass", "elasticity"]\n'
    )
    assert main([*argv, "--executor", "serial"]) == 0
    assert "(12 run, 0 already done, 0 failed)" in capsys.readouterr().out
    assert main([*argv, "--executor", "serial"]) == 0  # unchanged: resumes silently
    assert "(0 run, 12 already done, 0 failed)" in capsys.readouterr().out
    toy.FRAMES = 9
    before = {p: p.stat().st_mtime_ns for p in (tmp_path / "cells").glob("*.json")}
    assert main([*argv, "--executor", "serial"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        f"physbench bench: error: {tmp_path}: 12 of 12 finished cells were produced by other "
        "code or settings than this run would use:\n"
        "  - scene toy_scene, seeds 0-2: the generated scene differs (its generator or scene "
        "file changed)\n"
        "Resuming would mix their results with new ones. Rerun with --allow-stale"
    ), err
    assert "--fresh to start over" in err and "estimator" not in err
    # refused before anything ran or was written
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "cells").glob("*.json")} == before

    assert main([*argv, "--executor", "serial", "--allow-stale"]) == 0
    assert "(0 run, 12 already done, 0 failed)" in capsys.readouterr().out
    log = json.loads((tmp_path / "run.json").read_text())
    assert log["runs"][-1]["kept_stale"] == 12
    assert main([*argv, "--executor", "serial", "--fresh"]) == 0
    assert "(12 run, 0 already done" in capsys.readouterr().out
    assert main([*argv, "--executor", "serial"]) == 0  # fresh cells carry the new stamp
    assert "(0 run, 12 already done, 0 failed)" in capsys.readouterr().out


def test_cli_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "s"\nestimators = ["random"]\nseeds = 1\niterations = 1\nresolution = 16\n'
        'scenes = ["three_circles"]\n'
    )
    blocker = tmp_path / "file.txt"
    blocker.write_text("")
    cases = [
        ([str(tmp_path / "missing.toml")], "spec file"),
        (
            [str(spec), "--executor", "serial", "--out", str(blocker / "sub")],
            "cannot write results there",
        ),
        ([str(spec), "--executor", "serial", "--address", "tcp://x:1"], "needs --executor dask"),
    ]
    for argv, message in cases:
        if "--out" not in argv:
            argv = [*argv, "--out", str(tmp_path / "out")]
        code = main(["bench", *argv])
        err = capsys.readouterr().err
        assert code == 2 and err.startswith("physbench bench: error: ") and message in err, err
    bad = tmp_path / "bad.toml"
    bad.write_text("seeds = [\n")
    assert main(["bench", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert "not valid TOML" in capsys.readouterr().err


def test_an_interrupt_says_the_finished_cells_are_saved(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.bench import runner

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "run_sweep", interrupted)
    spec = tmp_path / "s.toml"
    spec.write_text('name = "s"\nestimators = ["random"]\nseeds = 1\nscenes = ["three_circles"]\n')
    assert main(["bench", str(spec), "--out", str(tmp_path / "o"), "-q"]) == 130
    assert capsys.readouterr().err == (
        f"physbench bench: interrupted; finished cells are saved in {tmp_path / 'o'}: re-run the "
        "same command to resume\n"
    )


def test_argument_parsing_imports_nothing_heavy(heavy_imports: Callable[..., list[str]]) -> None:
    then = "physbench.cli.build_parser('bench')"
    assert heavy_imports("physbench.cli", then=then, heavy=PARSING_HEAVY) == []


#: An estimator ``gated`` (random search) that, in each cell, records its process in the folder
#: ``PB_GATE`` (``started-<pid>-<n>``) and then waits (at most 30 s) for the file ``PB_GATE/go``.
GATED = """
import os
import time
from pathlib import Path
from typing import ClassVar

import numpy as np

from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl

GATE = Path(os.environ["PB_GATE"])


class Gated(CorrectionEstimator):
    name: ClassVar[str] = "gated"

    def __init__(self):
        self.options = {}

    def start(self, task, *, seed):
        self.space, self.rng = task.space, np.random.default_rng(seed)
        n = len(list(GATE.glob("started-*")))
        (GATE / f"started-{os.getpid()}-{n}").write_text("")
        deadline = time.monotonic() + 30
        while not (GATE / "go").exists() and time.monotonic() < deadline:
            time.sleep(0.05)

    def propose(self, step):
        return self.space.from_unit(self.rng.random(len(self.space)))


@hookimpl
def register_estimators():
    return [Gated]
"""

GATED_SPEC = (
    'name = "gated"\nestimators = ["gated"]\nseeds = 4\niterations = 1\nresolution = 16\n'
    '[[scenes]]\nname = "second_order"\nunknowns = ["elasticity"]\n'
)


def _gated_bench(
    tmp_path: Path, plugin: Callable[..., ModuleType], monkeypatch: pytest.MonkeyPatch
) -> tuple[list[str], dict[str, str], Path]:
    """The ``physbench bench`` arguments of a sweep of 4 ``gated`` cells into ``tmp_path/out``,
    the environment that finds the plugin in a child process, and the gate folder."""
    import os
    import sys

    import physbench

    gate = tmp_path / "gate"
    gate.mkdir()
    monkeypatch.setenv("PB_GATE", str(gate))
    plugin("pb_gated", GATED)
    (tmp_path / "spec.toml").write_text(GATED_SPEC)
    paths = [tmp_path / "plugins", Path(physbench.__file__).parents[1]]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(map(str, paths))}
    argv = ["bench", str(tmp_path / "spec.toml"), "--out", str(tmp_path / "out"), "-q"]
    return [sys.executable, "-m", "physbench", *argv], env, gate


def _until(condition: Callable[[], bool], what: str, seconds: float = 60) -> None:
    import time

    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.05)


def test_killing_the_main_process_ends_its_workers(
    tmp_path: Path, plugin: Callable[..., ModuleType], monkeypatch: pytest.MonkeyPatch
) -> None:
    import signal
    import subprocess

    import psutil

    command, env, gate = _gated_bench(tmp_path, plugin, monkeypatch)
    main_proc = subprocess.Popen([*command, "--workers", "2"], env=env, stderr=subprocess.DEVNULL)
    try:
        _until(lambda: len(list(gate.glob("started-*"))) == 2, "both workers to start a cell")
        family = psutil.Process(main_proc.pid).children(recursive=True)
        workers = {int(f.name.split("-")[1]) for f in gate.glob("started-*")}
        assert workers <= {p.pid for p in family} and len(workers) == 2
    finally:
        main_proc.send_signal(signal.SIGKILL)
        main_proc.wait()

    def alive() -> list[psutil.Process]:
        out = []
        for p in family:
            try:
                if p.status() != psutil.STATUS_ZOMBIE:
                    out.append(p)
            except psutil.NoSuchProcess:
                pass
        return out

    try:
        _until(lambda: not alive(), "the workers to end", seconds=10)
    finally:
        for p in alive():
            p.kill()


def test_a_second_run_on_the_same_folder_refuses_or_waits(
    tmp_path: Path,
    plugin: Callable[..., ModuleType],
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    import subprocess
    import threading

    command, env, gate = _gated_bench(tmp_path, plugin, monkeypatch)
    first = subprocess.Popen([*command, "--executor", "serial"], env=env)
    waited: list[int] = []
    try:
        _until(lambda: any(gate.glob("started-*")), "the first run to start a cell")
        assert main([*command[3:], "--executor", "serial"]) == 2
        out = tmp_path / "out"
        assert capsys.readouterr().err == (
            f"physbench bench: error: --out {str(out)!r}: another physbench bench is writing "
            f"this folder (pid {first.pid}); wait for it (--wait) or use another --out\n"
        )
        second = threading.Thread(
            target=lambda: waited.append(main([*command[3:], "--executor", "serial", "--wait"]))
        )
        second.start()
        second.join(1)
        assert second.is_alive()  # waiting for the first run
    finally:
        (gate / "go").write_text("")
        assert first.wait(60) == 0
    second.join(60)
    assert waited == [0] and "(0 run, 4 already done, 0 failed)" in capsys.readouterr().out
    runs = json.loads((out / "run.json").read_text())["runs"]
    assert [r["ran"] for r in runs] == [4, 0]
    assert len(list((out / "cells").glob("*.json"))) == 4 and len(list(gate.iterdir())) == 5


def test_a_sweep_this_machine_cannot_finish_is_refused_at_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """100,000 seeds x 4 estimators x 5 unknown sets: one sentence in well under 2 s, not a
    listing of two million cells."""
    import time

    monkeypatch.delenv("PHYSBENCH_NO_SIZE_CHECK", raising=False)
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "big"\nestimators = ["tpe", "cmaes", "optuna", "random"]\n'
        "seeds = {start = 0, count = 100000}\n"
        '[[scenes]]\nname = "three_circles"\nunknowns = ["mass", "mass+elasticity"]\n'
        '[[scenes]]\nname = "second_order"\nunknowns = ["elasticity"]\n'
        '[[scenes]]\nname = "stacked_boxes"\nunknowns = ["friction"]\n'
        '[[scenes]]\nname = "bouncing_balls"\nunknowns = ["mass"]\n'
    )
    start = time.perf_counter()
    code = main(["bench", str(spec), "--out", str(tmp_path / "out"), "--workers", "2"])
    assert time.perf_counter() - start < 2
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("physbench bench: error: this sweep (2000000 cells, 2 at a time; ")
    assert "of compute, more than the 24 h limit; make the seeds, estimators, axes or " in err
    assert not (tmp_path / "out").exists()


def test_a_sweep_whose_every_cell_fails_exits_non_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 28: every cell failed, yet ``bench`` exited 0."""
    from physbench import experiment

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("no simulation today")

    monkeypatch.setattr(experiment, "run_config", broken)
    spec = tmp_path / "s.toml"
    spec.write_text(
        'name = "s"\nestimators = ["random"]\nseeds = 2\niterations = 1\nresolution = 16\n'
        'scenes = ["three_circles"]\n'
    )
    argv = ["bench", str(spec), "--out", str(tmp_path / "o"), "--executor", "serial"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "physbench bench: error: sweep 's': all 2 cells failed" in err
    assert "RuntimeError: no simulation today" in err


def test_a_shipped_example_runs_by_name(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 28: the quick start's benchmarks/smoke.toml does not exist for a wheel user."""
    from physbench.bench.spec import load_spec
    from physbench.examples import example_names, example_path

    assert "smoke" in example_names()
    spec = load_spec(example_path("smoke"))
    assert spec.name == "smoke" and len(spec.cells()) == 240
    for argv, message in (
        (["--example", "nope"], "unknown example spec 'nope'; known example specs: smoke"),
        ([str(example_path("smoke")), "--example", "smoke"], "not both"),
        ([], "give a sweep spec file"),
    ):
        assert main(["bench", *argv, "--out", str(tmp_path / "o")]) == 2
        assert message in capsys.readouterr().err


def test_the_shipped_smoke_spec_is_the_benchmarks_one() -> None:
    import tomllib

    from physbench.examples import example_path

    root = Path(__file__).resolve().parents[2]
    shipped = tomllib.loads(example_path("smoke").read_text(encoding="utf-8"))
    assert shipped == tomllib.loads((root / "benchmarks" / "smoke.toml").read_text("utf-8"))
