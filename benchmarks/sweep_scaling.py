"""Sweep scaling: the smoke sweep (and smoke48, the same cells with 4x the seeds) with 1 and 2
workers against raw engine episodes with 1 and 2 processes, in the same run, and where the
sweep's time goes.

    python benchmarks/sweep_scaling.py [--repeats 5] [--out results/sweep_scaling] [--specs ...]

Sweep: ``physbench bench SPEC --fresh -q --workers N`` in a fresh interpreter
(end to end: start-up, imports, cells, tables), 1 and 2 workers alternating, median of the
repeats. Each run is instrumented from the outside (wrappers installed before the CLI runs, none
in physbench): phase boundaries in the parent, the start and end of every cell in its worker.

Raw engine: for every cell of the spec, the same number of simulations its estimator makes
(``iterations + 1 + 2 * unknowns``: the loop's budget) of its scene and seed, ``simulate`` only
(no render, no estimator, no store), over a warmed pool of 1 or 2 processes: the ceiling a sweep
of these cells could reach.

Amdahl bound: from the 1-worker run, the cells' own time (``run_cell`` in the worker, with each
estimator's first-cell imports, which workers split by estimator) is the part 2 workers can
split; the rest of the wall time (parent and pool start-up, storing cells, tables, exit) is not,
so the best 2-worker time is ``rest + cells / 2``.

Writes ``OUT/sweep_scaling.json`` (every repeat, the load average) and ``OUT/sweep_scaling.md``.
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

SPECS = ("benchmarks/smoke.toml", "benchmarks/smoke48.toml")
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


def child(spec: str, workers: int, out: str, events: str) -> None:
    _mark("interpreter")
    from physbench.__main__ import main  # the ``physbench`` script's entry point

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
    # as the script runs it, so that its exit (without the teardown) is measured
    argv = ["bench", spec, "--out", out, "--fresh", "-q", "--workers", str(workers)]
    sys.argv = ["physbench", *argv]
    rc = main()
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
    # ... and so does its first cell of each estimator: that one's time less the estimator's median
    per_est: dict[str, list[float]] = {}
    firsts: dict[tuple[int, str], float] = {}
    for pid, t0, t1, _, est in sorted(cells, key=lambda c: c[1]):
        per_est.setdefault(est, []).append(t1 - t0)
        firsts.setdefault((pid, est), t1 - t0)
    imports = sum(t - statistics.median(per_est[est]) for (_, est), t in firsts.items())
    return {
        "wall": ended - launched,
        "interpreter_start": p["interpreter"] - launched,
        "cli_import": p["cli_imported"] - p["interpreter"],
        "before_cells": p["pool_enter_start"] - p["run_sweep_start"],
        "pool_start": statistics.mean(per_worker_first) - p["pool_enter_start"],
        "first_cell_imports": statistics.mean(first_cells) - median_cell,
        "estimator_imports": imports,
        "estimator_imports_per_worker": imports / len(first_start),
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


def _cpu_of_children() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_sweep_once(spec: str, workers: int, tmp: Path) -> dict[str, float]:
    # a folder per spec: --fresh would otherwise time deleting the other spec's cells
    out, events = tmp / f"{Path(spec).stem}_w{workers}", tmp / f"events{workers}.json"
    cmd = [sys.executable, __file__, "--child", spec, str(workers), str(out), str(events)]
    cpu, launched = _cpu_of_children(), time.time()
    subprocess.run(cmd, check=True, env={**os.environ, "PYTHONPATH": os.getcwd()})
    ended = time.time()
    res = breakdown(json.loads(events.read_text()), launched, ended, workers)
    # the sweep's workers were joined by it, so their CPU time is counted with it
    res["cpu"] = _cpu_of_children() - cpu
    return res


# ---------------------------------------------------------------- raw engine episodes


def episodes(spec: str) -> list[tuple[str, int, int, str]]:
    """(scene, seed, simulations, engine) for every cell of ``spec``."""
    from physbench.bench.spec import load_spec

    out = []
    for c in load_spec(spec).cells():
        cfg = c.config
        sims = cfg.iterations + 1 + 2 * len(cfg.params)
        out.append((cfg.scene, cfg.seed, sims, cfg.engine))
    return out


def raw_episode(item: tuple[str, int, int, str]) -> float:
    """Runs in a pool process: the item's simulations, ``simulate`` only."""
    from physbench.components import create
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
    "estimator_imports": "each worker's first cell of each estimator, less its median, summed",
    "estimator_imports_per_worker": "  the same per worker",
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
    "cpu": "CPU time, parent + workers (user + system)",
}


def median_of(runs: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def amdahl(sweep: dict[str, Any]) -> dict[str, float]:
    """From the 1-worker medians: seconds 2 workers can split (the cells' own time) and the
    rest; the best 2-worker time and ratio they allow. And the CPU bound: 2 cores give at most
    2 CPU seconds per second, so the 2-worker run takes at least half the CPU time it used
    (parent and workers), which bounds the ratio too; the 1-worker run is not held to it, as
    its parent works on the second core beside the worker."""
    work = sweep["1"]["breakdown"]["cell_run_sum"]
    rest = sweep["1"]["median_s"] - work
    best = rest + work / 2
    cpu2 = sweep["2"]["breakdown"]["cpu"]
    return {
        "parallel_s": round(work, 3),
        "serial_s": round(rest, 3),
        "best_2_workers_s": round(best, 3),
        "best_ratio": round(sweep["1"]["median_s"] / best, 3),
        "cpu_2_workers_s": round(cpu2, 3),
        "cpu_bound_ratio": round(sweep["1"]["median_s"] / (cpu2 / 2), 3),
    }


def markdown(result: dict[str, Any]) -> str:
    load = result["load"]
    lines = [
        "# Sweep scaling",
        "",
        f"Machine: {result['machine']}. {result['repeats']} repeats (1 and 2 workers alternating), "
        "medians; `python benchmarks/sweep_scaling.py`. Load average (1 min) at each repeat: "
        + ", ".join(f"{x:.1f}" for x in load)
        + " (the benchmark's own processes included).",
        "",
        "| what | 1 worker s | 2 workers s | ratio (1 / 2) | runs, 1 worker | runs, 2 workers |",
        "|---|---|---|---|---|---|",
    ]
    for name, res in result["specs"].items():
        for what, rows in (
            (f"{name} sweep, end to end", res["sweep"]),
            (f"{name}: its cell loop (pool start to last result)", res["cell_loop"]),
            (f"{name}: raw engine episodes (simulate only)", res["raw"]),
        ):
            t1, t2 = rows["1"]["median_s"], rows["2"]["median_s"]
            r1, r2 = (" ".join(f"{x:.2f}" for x in rows[w]["runs_s"]) for w in ("1", "2"))
            lines.append(f"| {what} | {t1:.2f} | {t2:.2f} | {rows['ratio']:.2f} | {r1} | {r2} |")
    lines += [
        "",
        "Amdahl bound (from the 1-worker medians): the cells' own time (imports included) "
        "splits over 2 workers, the rest of the wall time does not. "
        "CPU bound: the 2-worker run cannot take less than half the CPU time its parent and "
        "workers used (2 cores), so the ratio is at most 1-worker wall / (2-worker CPU / 2).",
        "",
        "| spec | parallel s | serial s | best with 2 workers s | best ratio "
        "| CPU of the 2-worker run s | CPU-bound ratio | measured ratio |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, res in result["specs"].items():
        a = res["amdahl"]
        lines.append(
            f"| {name} | {a['parallel_s']:.2f} | {a['serial_s']:.2f} | "
            f"{a['best_2_workers_s']:.2f} | {a['best_ratio']:.2f} | {a['cpu_2_workers_s']:.2f} | "
            f"{a['cpu_bound_ratio']:.2f} | {res['sweep']['ratio']:.2f} |"
        )
    for name, res in result["specs"].items():
        sw = res["sweep"]
        lines += [
            "",
            f"Where the {name} sweep's time goes (medians, seconds unless noted):",
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
    ap.add_argument("--specs", nargs="+", default=list(SPECS))
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args.child[0], int(args.child[1]), args.child[2], args.child[3])
        return
    sweep = {s: {w: [] for w in WORKERS} for s in args.specs}
    raw: dict[str, dict[int, list[float]]] = {s: {w: [] for w in WORKERS} for s in args.specs}
    items = {s: episodes(s) for s in args.specs}
    load = []
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            load.append(os.getloadavg()[0])
            for spec in args.specs:
                for w in WORKERS if r % 2 == 0 else WORKERS[::-1]:
                    sweep[spec][w].append(run_sweep_once(spec, w, Path(tmp)))
                    raw[spec][w].append(run_raw_once(w, items[spec]))
                    print(
                        f"repeat {r + 1}/{args.repeats}, {Path(spec).stem}, {w} worker(s): sweep "
                        f"{sweep[spec][w][-1]['wall']:.2f} s, raw {raw[spec][w][-1]:.2f} s, "
                        f"load {os.getloadavg()[0]:.1f}",
                        file=sys.stderr,
                    )
    result: dict[str, Any] = {
        "machine": f"{os.cpu_count()} cores",
        "python": platform.python_version(),
        "repeats": args.repeats,
        "load": load,
        "specs": {},
    }
    for spec in args.specs:
        res = {
            "sweep": summarise(sweep[spec]),
            "cell_loop": summarise(
                {w: [r["cells_loop"] for r in rs] for w, rs in sweep[spec].items()}
            ),
            "raw": summarise(raw[spec]),
        }
        res["amdahl"] = amdahl(res["sweep"])
        result["specs"][Path(spec).stem] = res
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_scaling.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "sweep_scaling.md").write_text(markdown(result))
    print(markdown(result))


if __name__ == "__main__":
    main()
