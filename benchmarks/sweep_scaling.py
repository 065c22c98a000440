"""Sweep scaling: the smoke sweep with 1 and 2 workers against raw engine episodes with 1 and 2
processes, in the same run, and where the sweep's time goes.

    python benchmarks/sweep_scaling.py [--repeats 5] [--out results/sweep_scaling]

Sweep: ``physbench bench benchmarks/smoke.toml --fresh -q --workers N`` in a fresh interpreter
(end to end: start-up, imports, cells, tables), 1 and 2 workers alternating, median of the
repeats. Each run is instrumented from the outside (wrappers installed before the CLI runs, none
in physbench): phase boundaries in the parent, the start and end of every cell in its worker.

Raw engine: for every cell of the spec, the same number of simulations its estimator makes
(``iterations + 1 + 2 * unknowns``: the loop's budget) of its scene and seed, ``simulate`` only
(no render, no estimator, no store), over a warmed pool of 1 or 2 processes: the ceiling a sweep
of these cells could reach.

Writes ``OUT/sweep_scaling.json`` (every repeat) and ``OUT/sweep_scaling.md`` (the tables).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

SPEC = "benchmarks/smoke.toml"
WORKERS = (1, 2)

# ---------------------------------------------------------------- instrumented sweep (child)

_EVENTS: dict[str, Any] = {"phases": {}, "totals": {}, "cells": []}


def _mark(name: str) -> None:
    _EVENTS["phases"][name] = time.time()


def _timed(owner: Any, attr: str, total: str | None = None, start: str | None = None) -> None:
    """Wrap ``owner.attr``: add its time to ``totals[total]`` and/or mark its start/end."""
    fn = getattr(owner, attr)

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        t0 = time.time()
        if start:
            _mark(f"{start}_start")
        try:
            return fn(*args, **kwargs)
        finally:
            if total:
                _EVENTS["totals"][total] = _EVENTS["totals"].get(total, 0.0) + time.time() - t0
            if start:
                _mark(f"{start}_end")

    setattr(owner, attr, wrapper)


def timed_run_cell(config: Any) -> dict[str, Any]:
    """Runs in the worker: the product's ``run_cell`` with its wall-clock start and end."""
    from physbench.bench.runner import run_cell

    t0 = time.time()
    data = run_cell(config)
    data["_timing"] = (os.getpid(), t0, time.time())
    return data


def child(workers: int, out: str, events: str) -> None:
    _mark("interpreter")
    import physbench.cli as cli

    _mark("cli_imported")
    from physbench.bench import executors, runner, store, summary

    _timed(runner, "run_sweep", start="run_sweep")
    _timed(executors.ProcessExecutor, "__enter__", start="pool_enter")
    _timed(executors.ProcessExecutor, "__exit__", start="pool_exit")
    _timed(runner, "assemble", start="assemble")
    _timed(runner, "write_table", start="write_table")
    _timed(summary, "write_summary", start="write_summary")
    _timed(store, "atomic_write", total="write")
    runner.run_cell = timed_run_cell  # type: ignore[assignment]

    save = store.CellStore.save

    def save_timed(self: Any, key: str, data: dict[str, Any]) -> None:
        pid, t0, t1 = data.pop("_timing")
        _EVENTS["cells"].append((pid, t0, t1, time.time(), data["config"]["estimator"]))
        tot = _EVENTS["totals"]
        t, written = time.time(), tot.get("write", 0.0)
        save(self, key, data)
        took, wrote = time.time() - t, tot.get("write", 0.0) - written
        tot["cell_write"] = tot.get("cell_write", 0.0) + wrote
        tot["cell_dumps"] = tot.get("cell_dumps", 0.0) + took - wrote

    store.CellStore.save = save_timed  # type: ignore[method-assign]
    rc = cli.main(["bench", SPEC, "--out", out, "--fresh", "-q", "--workers", str(workers)])
    _mark("done")
    Path(events).write_text(json.dumps(_EVENTS))
    sys.exit(rc)


# ---------------------------------------------------------------- analysis of one sweep run


def breakdown(ev: dict[str, Any], launched: float, ended: float, workers: int) -> dict[str, float]:
    """Seconds per phase of one sweep run, from the child's events."""
    p, tot, cells = ev["phases"], ev["totals"], ev["cells"]
    first_start: dict[int, float] = {}
    busy: dict[int, float] = {}
    for pid, t0, t1, _, _ in cells:
        first_start[pid] = min(first_start.get(pid, t0), t0)
        busy[pid] = busy.get(pid, 0.0) + t1 - t0
    loop = p["pool_exit_start"] - p["pool_enter_start"]
    per_worker_first = sorted(first_start.values())
    cell_times = sorted(t1 - t0 for _, t0, t1, _, _ in cells)
    median_cell = statistics.median(cell_times)
    # a worker's first cell also imports the estimators' libraries
    first_cells = [t1 - t0 for pid, t0, t1, _, _ in cells if t0 == first_start[pid]]
    return {
        "wall": ended - launched,
        "interpreter_start": p["interpreter"] - launched,
        "cli_import": p["cli_imported"] - p["interpreter"],
        "before_cells": p["pool_enter_start"] - p["run_sweep_start"],
        "pool_start": statistics.mean(per_worker_first) - p["pool_enter_start"],
        "first_cell_imports": statistics.mean(first_cells) - median_cell,
        "cells_loop": loop,
        "cell_run_sum": sum(busy.values()),
        "cell_median_ms": 1000 * median_cell,
        "worker_busy": sum(busy.values()) / (workers * loop),
        "parent_cell_save": tot.get("cell_dumps", 0.0) + tot.get("cell_write", 0.0),
        "parent_cell_dumps": tot.get("cell_dumps", 0.0),
        "parent_cell_write": tot.get("cell_write", 0.0),
        "pool_shutdown": p["pool_exit_end"] - p["pool_exit_start"],
        "assemble": p["assemble_end"] - p["assemble_start"],
        "write_table": p["write_table_end"] - p["write_table_start"],
        "write_summary": p["write_summary_end"] - p["write_summary_start"],
        "after_summary": p["done"] - p["write_summary_end"],
        "exit": ended - p["done"],
    }


def run_sweep_once(workers: int, tmp: Path) -> dict[str, float]:
    out, events = tmp / f"w{workers}", tmp / f"events{workers}.json"
    cmd = [sys.executable, __file__, "--child", str(workers), str(out), str(events)]
    launched = time.time()
    subprocess.run(cmd, check=True, env={**os.environ, "PYTHONPATH": os.getcwd()})
    ended = time.time()
    return breakdown(json.loads(events.read_text()), launched, ended, workers)


# ---------------------------------------------------------------- raw engine episodes


def episodes() -> list[tuple[str, int, int, str]]:
    """(scene, seed, simulations, engine) for every cell of the spec."""
    from physbench.bench.spec import load_spec

    out = []
    for c in load_spec(SPEC).cells():
        cfg = c.config
        sims = cfg.iterations + 1 + 2 * len(cfg.params)
        out.append((cfg.scene, cfg.seed, sims, cfg.engine))
    return out


def raw_episode(item: tuple[str, int, int, str]) -> float:
    """Runs in a pool process: the item's simulations, ``simulate`` only."""
    from physbench.plugins import create
    from physbench.scenes import resolve_scene

    scene_name, seed, n, engine = item
    scene = resolve_scene(scene_name, seed)
    sim = create("simulator", engine)
    t0 = time.perf_counter()
    for _ in range(n):
        sim.simulate(scene)
    return time.perf_counter() - t0


def run_raw_once(workers: int, items: list[tuple[str, int, int, str]]) -> float:
    """Wall seconds for all ``items`` over a warmed pool of ``workers`` processes."""
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        pool.map(raw_episode, items[: 2 * workers], chunksize=1)  # imports and caches
        t0 = time.perf_counter()
        pool.map(raw_episode, items, chunksize=1)
        return time.perf_counter() - t0


# ---------------------------------------------------------------- report

PHASES = {
    "interpreter_start": "interpreter start (parent)",
    "cli_import": "import physbench CLI (parent)",
    "before_cells": "spec, size check, stamps (parent)",
    "pool_start": "pool start-up to a worker's first cell (spawn + imports)",
    "first_cell_imports": "first cell's extra time in a worker (estimator imports)",
    "cells_loop": "cell loop (pool start to last result)",
    "cell_run_sum": "  run_cell time summed over workers",
    "worker_busy": "  worker busy fraction of the loop",
    "cell_median_ms": "  median cell, ms",
    "parent_cell_save": "  parent: storing cells (total)",
    "parent_cell_dumps": "  parent: serialising histories (json.dumps)",
    "parent_cell_write": "  parent: writing cell files (atomic write + fsync)",
    "pool_shutdown": "pool shutdown",
    "assemble": "assemble long table from cells",
    "write_table": "write results.parquet",
    "write_summary": "stats + summary tables",
    "after_summary": "run.json, printing",
    "exit": "interpreter exit",
    "wall": "end to end",
}


def median_of(runs: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def markdown(result: dict[str, Any]) -> str:
    sw, raw = result["sweep"], result["raw"]
    lines = [
        "# Sweep scaling",
        "",
        f"Machine: {result['machine']}. {result['repeats']} repeats, medians; "
        "`python benchmarks/sweep_scaling.py`.",
        "",
        "| what | 1 worker s | 2 workers s | ratio (1 / 2) |",
        "|---|---|---|---|",
    ]
    for name, rows in (
        ("smoke sweep, end to end", sw),
        ("its cell loop (pool start to last result)", result["cell_loop"]),
        ("raw engine episodes (simulate only)", raw),
    ):
        t1, t2 = rows["1"]["median_s"], rows["2"]["median_s"]
        lines.append(f"| {name} | {t1:.2f} | {t2:.2f} | {rows['ratio']:.2f} |")
    lines += [
        "",
        "Where the sweep's time goes (medians, seconds unless noted):",
        "",
        "| phase | 1 worker | 2 workers |",
        "|---|---|---|",
    ]
    for key, label in PHASES.items():
        a, b = sw["1"]["breakdown"][key], sw["2"]["breakdown"][key]
        fmt = "{:.2f}" if key != "cell_median_ms" else "{:.1f}"
        lines.append(f"| {label} | {fmt.format(a)} | {fmt.format(b)} |")
    return "\n".join(lines) + "\n"


def summarise(runs: dict[int, list[Any]]) -> dict[str, Any]:
    """Per worker count: every run's seconds and their median (and the median breakdown when
    the runs are sweeps); ``ratio`` = median with 1 / median with 2."""
    out: dict[str, Any] = {}
    for w, rs in runs.items():
        walls = [r["wall"] if isinstance(r, dict) else r for r in rs]
        out[str(w)] = {"runs_s": [round(x, 3) for x in walls], "median_s": statistics.median(walls)}
        if isinstance(rs[0], dict):
            out[str(w)]["breakdown"] = {k: round(median_of(rs, k), 4) for k in rs[0]}
    out["ratio"] = round(out["1"]["median_s"] / out["2"]["median_s"], 3)
    for w in WORKERS:
        out[str(w)]["median_s"] = round(out[str(w)]["median_s"], 3)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default="results/sweep_scaling")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(int(args.child[0]), args.child[1], args.child[2])
        return
    sweep: dict[int, list[dict[str, float]]] = {w: [] for w in WORKERS}
    raw: dict[int, list[float]] = {w: [] for w in WORKERS}
    items = episodes()
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            for w in WORKERS if r % 2 == 0 else WORKERS[::-1]:
                sweep[w].append(run_sweep_once(w, Path(tmp)))
                raw[w].append(run_raw_once(w, items))
                print(
                    f"repeat {r + 1}/{args.repeats}, {w} worker(s): sweep "
                    f"{sweep[w][-1]['wall']:.2f} s, raw {raw[w][-1]:.2f} s",
                    file=sys.stderr,
                )
    result = {
        "machine": f"{os.cpu_count()} cores",
        "python": platform.python_version(),
        "spec": Path(SPEC).stem,
        "repeats": args.repeats,
        "sweep": summarise(sweep),
        "cell_loop": summarise({w: [r["cells_loop"] for r in rs] for w, rs in sweep.items()}),
        "raw": summarise(raw),
    }
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_scaling.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "sweep_scaling.md").write_text(markdown(result))
    print(markdown(result))


if __name__ == "__main__":
    main()
