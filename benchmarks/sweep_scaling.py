"""Sweep scaling: smoke48 (960 cells) with 1..N workers, on local processes and on a Dask
LocalCluster, against raw engine episodes with as many processes, in the same run; where each
sweep's time goes; and how its cells spread over the workers.

    python benchmarks/sweep_scaling.py [--repeats 3] [--workers 1 2 4 8 16]
        [--executors processes dask] [--dask-workers 16] [--raw-workers 1 16] [--seeds 4]
        [--specs benchmarks/smoke48.toml] [--out results/sweep_scaling] [--add]

Sweep: ``physbench bench SPEC --fresh -q --executor E --workers N`` in a fresh interpreter (end
to end: start-up, imports, cells, tables), instrumented from the outside (wrappers installed
before the CLI runs, none in physbench): phase boundaries in the sweep's process, and in the
workers the start and end of every cell, in wall-clock and CPU time, and each worker's own
start-up (from its process's start to its first cell). The configurations run in one order, then
the reverse, repeat after repeat, so that a change of load falls on all of them.

Raw engine: for every cell of the spec, as many ``simulate`` calls of its scene and seed as its
estimator makes (``iterations + 1 + 2 * unknowns``), over a warmed pool of N processes: the
ceiling a sweep of these cells could reach on this machine.

How the cells spread: cells per worker, the estimators each worker ran (each one's libraries are
imported by every worker that runs it), and the time workers stood idle while cells had not yet
started ("idle while cells waited": per worker, the gaps between its cells and after its last
one, up to the moment the last cell started).

What 16 cores would give, from CPU time (which the load of other jobs hardly changes, unlike wall
time): the sweep's own serial phases (its process's CPU outside the cell loop), each worker's
overhead (start-up and the extra time of its first cell of each estimator) and the cells' work
(their CPU, less those extras). Amdahl: the 1-worker run splits into serial phases + one
worker's overhead + work; N workers need at least serial + the largest overhead among the N
workers (each pays its own at once; measured in the N-worker run, or, where there was none, that
of the estimators each worker runs in the placement replayed below) + work / N. The sweep
process's own CPU in the cell loop, per cell, bounds how many cells per second it can take.

Placement replayed: the executor's own placement (:class:`physbench.bench.placement.Pending`,
at most ``QUEUED`` cells per worker) run on a simulated clock for 1..16 workers, each cell taking
its estimator's median CPU time measured here and a worker's first cell of an estimator that
estimator's measured extra (its imports): how the cells would spread over 16 workers on this
machine's measured costs, and the time workers would stand idle while cells waited.

Writes ``OUT/results.json`` (every run, the load averages before each; rewritten after each run,
so a benchmark cut short keeps what it measured; ``--add`` adds runs to it) and
``OUT/summary.md``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

SPECS = ("benchmarks/smoke48.toml",)
WORKERS = (1, 2, 4, 8, 16)
EXECUTORS = ("processes", "dask")

# ---------------------------------------------------------------- instrumented sweep (child)

_EVENTS: dict[str, Any] = {"phases": {}, "cpu": {}, "totals": {}, "cells": [], "batches": []}


def _mark(name: str) -> None:
    _EVENTS["phases"][name] = time.time()
    _EVENTS["cpu"][name] = time.process_time()


def _timed(owner: Any, attr: str, start: str) -> None:
    """Wrap ``owner.attr``: mark its start and end."""
    fn = getattr(owner, attr)

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        _mark(f"{start}_start")
        try:
            return fn(*args, **kwargs)
        finally:
            _mark(f"{start}_end")

    setattr(owner, attr, wrapper)


def _process_started() -> float:
    """Wall-clock time at which this process started (Linux: its start tick since boot)."""
    fields = Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()
    ticks = int(fields[19])  # field 22 of stat(5), counted after the name
    age = time.clock_gettime(time.CLOCK_BOOTTIME) - ticks / os.sysconf("SC_CLK_TCK")
    return time.time() - age


def timed_run_cell(config: Any) -> dict[str, Any]:
    """Runs in the worker: the product's ``run_cell`` with its start and end (wall and CPU),
    and, once per worker, the worker's start and its CPU time before its first cell. (Kept on
    ``sys``: Dask unpickles this function by value, with copies of this module's globals.)"""
    worker: dict[str, float] = sys.__dict__.setdefault("_sweep_scaling_worker", {})
    if not worker:
        worker.update(started=_process_started(), startup_cpu=time.process_time())
    from physbench.bench.runner import run_cell

    t0, c0 = time.time(), time.process_time()
    data = run_cell(config)
    data["_timing"] = {
        "pid": os.getpid(),
        "t0": t0,
        "t1": time.time(),
        "cpu": time.process_time() - c0,
        **worker,
    }
    return data


def child(spec: str, executor: str, workers: int, out: str, events: str) -> None:
    _mark("interpreter")
    from physbench.__main__ import main  # the ``physbench`` script's entry point

    _mark("cli_imported")
    from physbench.bench import executors, runner, store, summary

    _timed(runner, "run_sweep", "run_sweep")
    for cls in (executors.ProcessExecutor, executors.DaskExecutor):
        _timed(cls, "__enter__", "pool_enter")
        _timed(cls, "__exit__", "pool_exit")
    _timed(runner, "assemble", "assemble")
    _timed(runner, "write_table", "write_table")
    _timed(summary, "write_summary", "write_summary")
    runner.run_cell = timed_run_cell  # type: ignore[assignment]
    warm = runner._import_tables

    def warm_timed() -> None:
        try:
            warm()
        finally:
            _EVENTS["import_tables_cpu"] = time.thread_time()

    runner._import_tables = warm_timed

    put = store.CellWriter.put

    def put_timed(self: Any, key: str, data: dict[str, Any]) -> None:
        timing = data.pop("_timing")
        _EVENTS["cells"].append(
            {**timing, "received": time.time(), "est": data["config"]["estimator"], "key": key}
        )
        put(self, key, data)

    save_many = store.CellStore.save_many

    def save_many_timed(self: Any, cells: list[Any], flush: Any = map) -> list[str]:
        t0 = time.time()
        try:
            return save_many(self, cells, flush)
        finally:
            _EVENTS["batches"].append((t0, time.time(), len(cells)))

    from physbench.bench.spec import load_spec

    for c in load_spec(spec).cells():
        n = _EVENTS.setdefault("estimators_cells", {})
        n[c.config.estimator] = n.get(c.config.estimator, 0) + 1
    store.CellWriter.put = put_timed  # type: ignore[method-assign]
    store.CellStore.save_many = save_many_timed  # type: ignore[method-assign]
    argv = ["bench", spec, "--out", out, "--fresh", "-q", "--executor", executor]
    sys.argv = ["physbench", *argv, "--workers", str(workers)]
    rc = main()
    _mark("done")
    self_cpu = resource.getrusage(resource.RUSAGE_SELF)
    _EVENTS["parent_cpu"] = self_cpu.ru_utime + self_cpu.ru_stime
    Path(events).write_text(json.dumps(_EVENTS))
    sys.exit(rc)


# ---------------------------------------------------------------- analysis of one sweep run


def spread(cells: list[dict[str, Any]]) -> dict[str, Any]:
    """How the cells of one run spread over its workers (see the module's docstring)."""
    by_worker: dict[int, list[dict[str, Any]]] = {}
    for c in cells:
        by_worker.setdefault(c["pid"], []).append(c)
    last_start = max(c["t0"] for c in cells)
    first_start = min(c["t0"] for c in cells)
    idle = {}
    for pid, own in by_worker.items():
        own.sort(key=lambda c: c["t0"])
        gaps = [max(0.0, min(b["t0"], last_start) - a["t1"]) for a, b in itertools.pairwise(own)]
        idle[pid] = sum(gaps) + max(0.0, last_start - own[-1]["t1"])
    counts = sorted(len(own) for own in by_worker.values())
    span = sum(last_start - min(c["t0"] for c in own) for own in by_worker.values())
    per_worker = [
        {
            "cells": len(own),
            "estimators": sorted({c["est"] for c in own}),
            "busy_s": round(sum(c["t1"] - c["t0"] for c in own), 3),
            "cpu_s": round(sum(c["cpu"] for c in own), 3),
            "first_cell_s": round(own[0]["t0"] - first_start, 3),
            "idle_while_waiting_s": round(idle[pid], 3),
        }
        for pid, own in sorted(by_worker.items(), key=lambda kv: kv[1][0]["t0"])
    ]
    return {
        "per_worker": per_worker,
        "workers_used": len(by_worker),
        "cells_per_worker": counts,
        "estimators_per_worker": sorted(len({c["est"] for c in own}) for own in by_worker.values()),
        "idle_while_waiting_s": sum(idle.values()),
        "idle_while_waiting_max_s": max(idle.values()),
        "idle_while_waiting_share": sum(idle.values()) / span if span > 0 else 0.0,
        "last_start_after_first_s": last_start - first_start,
    }


def overheads(cells: list[dict[str, Any]]) -> dict[int, dict[str, float]]:
    """Per worker, in CPU seconds: start-up (to its first cell), the extra time of its first cell
    of each estimator over that estimator's median cell in this run, and its cells' time."""
    per_est: dict[str, list[float]] = {}
    for c in cells:
        per_est.setdefault(c["est"], []).append(c["cpu"])
    median = {est: statistics.median(v) for est, v in per_est.items()}
    out: dict[int, dict[str, float]] = {}
    seen: set[tuple[int, str]] = set()
    for c in sorted(cells, key=lambda c: c["t0"]):
        w = out.setdefault(
            c["pid"], {"startup": c["startup_cpu"], "first_cells": 0.0, "cells": 0.0}
        )
        w["cells"] += c["cpu"]
        if (c["pid"], c["est"]) not in seen:
            seen.add((c["pid"], c["est"]))
            w["first_cells"] += max(0.0, c["cpu"] - median[c["est"]])
    return out


def estimator_costs(cells: list[dict[str, Any]]) -> dict[str, dict[str, float]]:
    """Per estimator, in CPU seconds: its median cell (a worker's first cell of it left out) and
    the median extra of a worker's first cell of it over that (its imports and first-call work)."""
    seen: set[tuple[int, str]] = set()
    firsts: dict[str, list[float]] = {}
    others: dict[str, list[float]] = {}
    for c in sorted(cells, key=lambda c: c["t0"]):
        first = (c["pid"], c["est"]) not in seen
        seen.add((c["pid"], c["est"]))
        (firsts if first else others).setdefault(c["est"], []).append(c["cpu"])
    out = {}
    for est, v in others.items():
        typical = statistics.median(v)
        extra = statistics.median(firsts.get(est, [typical])) - typical
        out[est] = {"typical": round(typical, 4), "extra": round(max(0.0, extra), 4)}
    return out


def breakdown(ev: dict[str, Any], launched: float, ended: float, workers: int) -> dict[str, Any]:
    """Seconds per phase of one sweep run, from the child's events; its spread and overheads."""
    p, cpu, cells = ev["phases"], ev["cpu"], ev["cells"]
    loop = p["pool_exit_start"] - p["pool_enter_start"]
    firsts = {}
    for c in cells:
        firsts[c["pid"]] = min(firsts.get(c["pid"], c["t0"]), c["t0"])
    cell_wall = [c["t1"] - c["t0"] for c in cells]
    over = overheads(cells)
    loop_cpu = cpu["pool_exit_end"] - cpu["pool_enter_start"]
    batches = ev["batches"]
    res: dict[str, Any] = {
        "wall": ended - launched,
        "interpreter_start": p["interpreter"] - launched,
        "cli_import": p["cli_imported"] - p["interpreter"],
        "before_cells": p["pool_enter_start"] - p["run_sweep_start"],
        "pool_start": statistics.mean(firsts.values()) - p["pool_enter_start"],
        "last_worker_start": max(firsts.values()) - p["pool_enter_start"],
        "cells_loop": loop,
        "cell_run_sum": sum(cell_wall),
        "cell_median_ms": 1000 * statistics.median(cell_wall),
        "cell_cpu_median_ms": 1000 * statistics.median(c["cpu"] for c in cells),
        "worker_busy": sum(cell_wall) / (workers * loop),
        "store_batches": len(batches),
        "store_busy": sum(b - a for a, b, _ in batches),
        "store_after_last_cell": max(b for _, b, _ in batches) - max(c["received"] for c in cells),
        "pool_shutdown": p["pool_exit_end"] - p["pool_exit_start"],
        "assemble": p["assemble_end"] - p["assemble_start"],
        "write_table": p["write_table_end"] - p["write_table_start"],
        "write_summary": p["write_summary_end"] - p["write_summary_start"],
        "after_summary": p["done"] - p["write_summary_end"],
        "exit": ended - p["done"],
        "parent_cpu": ev["parent_cpu"],
        "parent_cpu_in_loop": loop_cpu,
        "parent_serial_cpu": ev["parent_cpu"] - loop_cpu,
        "worker_startup_cpu_mean": statistics.mean(w["startup"] for w in over.values()),
        "worker_startup_cpu_max": max(w["startup"] for w in over.values()),
        "worker_first_cells_cpu_mean": statistics.mean(w["first_cells"] for w in over.values()),
        "worker_overhead_cpu_max": max(w["startup"] + w["first_cells"] for w in over.values()),
        "cells_cpu": sum(c["cpu"] for c in cells),
        "busiest_worker_cpu": max(w["startup"] + w["cells"] for w in over.values()),
    }
    res.update(spread(cells))
    res["estimator_costs"] = estimator_costs(cells)
    res["cells"] = len(cells)
    res["estimators_cells"] = ev["estimators_cells"]  # in the spec's order
    # the tables' imports run in a thread beside the loop, once: not a cost per cell
    res["import_tables_cpu"] = ev.get("import_tables_cpu", 0.0)
    res["parent_loop_cpu_per_cell_ms"] = 1000 * (loop_cpu - res["import_tables_cpu"]) / len(cells)
    return res


def _cpu_of_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def table_hash(out: Path) -> str:
    """A hash of the sweep's long table without its timings and versions: the same cells with
    the same results give the same hash, whatever executor and workers ran them."""
    import hashlib

    import pandas as pd

    df = pd.read_parquet(out / "results.parquet")
    df = df.drop(columns=[c for c in df.columns if c.startswith("t_") or c == "versions"])
    return hashlib.sha256(df.to_csv(index=False).encode()).hexdigest()[:16]


def run_sweep_once(spec: str, executor: str, workers: int, tmp: Path) -> dict[str, Any]:
    # a folder per spec and executor: --fresh would otherwise time deleting another run's cells
    out = tmp / f"{Path(spec).stem}_{executor}_w{workers}"
    events = tmp / "events.json"
    cmd = [sys.executable, __file__, "--child", spec, executor, str(workers), str(out), str(events)]
    load = os.getloadavg()
    cpu, launched = _cpu_of_children(), time.time()
    path = os.pathsep.join(p for p in (os.getcwd(), os.environ.get("PYTHONPATH")) if p)
    subprocess.run(cmd, check=True, env={**os.environ, "PYTHONPATH": path})
    ended = time.time()
    res = breakdown(json.loads(events.read_text()), launched, ended, workers)
    # the sweep's workers ended before it, so their CPU time is counted with it
    res["cpu"] = _cpu_of_children() - cpu
    res["table_hash"] = table_hash(out)
    res["load_before"] = [round(x, 2) for x in load]
    return res


# ---------------------------------------------------------------- placement replayed


def replay(
    counts: dict[str, int], costs: dict[str, dict[str, float]], workers: int, startup: float
) -> dict[str, Any]:
    """The executor's placement on a simulated clock (see the module's docstring): ``counts``
    cells per estimator (in spec order, grouped as the executor groups them), each taking its
    estimator's ``typical`` seconds, plus ``extra`` in a worker's first cell of it; every worker
    ready after ``startup`` seconds; the parent hands out cells instantly."""
    import heapq

    from physbench.bench.executors import QUEUED
    from physbench.bench.placement import Pending

    items = [(est, i) for est, n in counts.items() for i in range(n)]
    pending = Pending(items, lambda it: it[0])
    queue: dict[int, list[tuple[str, int]]] = {w: [] for w in range(workers)}
    ran: dict[int, set[str]] = {w: set() for w in range(workers)}
    free = dict.fromkeys(range(workers), startup)  # when each worker's running cell ends
    running: set[int] = set()
    events: list[tuple[float, int, tuple[str, int], float]] = []
    n_cells = dict.fromkeys(range(workers), 0)
    idle = dict.fromkeys(range(workers), 0.0)
    now = 0.0

    def start(w: int) -> None:
        if w in running or not queue[w]:
            return
        est = queue[w][0][0]
        sec = costs[est]["typical"] + (0.0 if est in ran[w] else costs[est]["extra"])
        ran[w].add(est)
        running.add(w)
        heapq.heappush(events, (max(now, free[w]) + sec, w, queue[w][0], sec))

    def hand_out(force: bool = False) -> None:
        for w in range(workers):
            limit = QUEUED if len(pending) >= workers else 1
            while pending and len(queue[w]) < limit:
                item = pending.take(w, force=force)
                if item is None:
                    break
                queue[w].append(item)
                force = False
            start(w)

    hand_out()
    while events:
        nxt = events[0][0]
        # workers without a cell (once started) while a cell has not started: idle while waiting
        unstarted = len(pending) + sum(len(q) for q in queue.values()) - len(running)
        if unstarted:
            for v in range(workers):
                if v not in running:
                    idle[v] += max(0.0, nxt - max(now, free[v]))
        now, w, item, sec = heapq.heappop(events)
        queue[w].pop(0)
        running.discard(w)
        free[w] = now
        n_cells[w] += 1
        pending.done(w, item, sec)
        hand_out()
        if pending and not events:
            hand_out(force=True)
    end = now
    return {
        "workers": workers,
        "span_s": round(end, 3),
        "cells_per_worker": sorted(n_cells.values()),
        "estimators_per_worker": sorted(len(r) for r in ran.values()),
        "idle_while_waiting_s": round(sum(idle.values()), 3),
        "idle_while_waiting_max_s": round(max(idle.values()), 3),
        # the largest start-up + imports of one worker, for the estimators it ran here
        "overhead_max_s": round(
            startup + max(sum(costs[e]["extra"] for e in r) for r in ran.values()), 3
        ),
    }


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


def run_raw_once(workers: int, items: list[tuple[str, int, int, str]]) -> dict[str, Any]:
    """Wall seconds for all ``items`` over a warmed pool of ``workers`` processes."""
    import multiprocessing

    load = os.getloadavg()
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        pool.map(raw_episode, items[: 2 * workers], chunksize=1)  # imports and caches
        t0 = time.perf_counter()
        pool.map(raw_episode, items, chunksize=1)
        return {"wall": time.perf_counter() - t0, "load_before": [round(x, 2) for x in load]}


# ---------------------------------------------------------------- summaries

#: Phases of the breakdown table: key, label, format.
PHASES = (
    ("interpreter_start", "interpreter start (sweep process)", "{:.2f}"),
    ("cli_import", "import physbench CLI", "{:.2f}"),
    ("before_cells", "spec, size check, stamps, executor", "{:.2f}"),
    ("pool_start", "pool start to a worker's first cell, mean over workers", "{:.2f}"),
    ("last_worker_start", "  to the last worker's first cell", "{:.2f}"),
    ("cells_loop", "cell loop (pool start to last result)", "{:.2f}"),
    ("cell_run_sum", "  run_cell wall time summed over workers", "{:.2f}"),
    ("worker_busy", "  worker busy fraction of the loop", "{:.2f}"),
    ("cell_median_ms", "  median cell, wall ms", "{:.1f}"),
    ("cell_cpu_median_ms", "  median cell, CPU ms", "{:.1f}"),
    ("store_busy", "  storing cells (writer thread, beside the loop)", "{:.2f}"),
    ("store_batches", "  batches stored", "{:.0f}"),
    ("store_after_last_cell", "  storing after the last result", "{:.2f}"),
    ("pool_shutdown", "pool shutdown", "{:.2f}"),
    ("assemble", "assemble the long table", "{:.2f}"),
    ("write_table", "write results.parquet", "{:.2f}"),
    ("write_summary", "stats + summary tables", "{:.2f}"),
    ("after_summary", "run.json, printing", "{:.2f}"),
    ("exit", "interpreter exit", "{:.2f}"),
    ("wall", "end to end", "{:.2f}"),
    ("cpu", "CPU, sweep process + workers", "{:.2f}"),
    ("parent_cpu", "CPU, sweep process", "{:.2f}"),
    ("parent_serial_cpu", "  of it outside the cell loop", "{:.2f}"),
    ("import_tables_cpu", "  importing the tables' libraries (a thread beside the loop)", "{:.2f}"),
    ("parent_loop_cpu_per_cell_ms", "  in the loop, the rest per cell, ms", "{:.2f}"),
    ("worker_startup_cpu_mean", "CPU of a worker's start-up, mean", "{:.2f}"),
    ("worker_startup_cpu_max", "  largest", "{:.2f}"),
    ("worker_first_cells_cpu_mean", "CPU of a worker's first cells' extra, mean", "{:.2f}"),
    ("worker_overhead_cpu_max", "  start-up + first cells' extra, largest", "{:.2f}"),
    ("busiest_worker_cpu", "CPU of the busiest worker (start-up + cells)", "{:.2f}"),
)
SPREAD = ("workers_used", "idle_while_waiting_s", "idle_while_waiting_max_s")


def median_run(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per key, the median over the runs (lists: the run with the median wall time's)."""
    mid = sorted(runs, key=lambda r: r["wall"])[len(runs) // 2]
    out: dict[str, Any] = {}
    for k, v in runs[0].items():
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            out[k] = round(statistics.median(r[k] for r in runs), 4)
        else:
            out[k] = mid[k]
    return out


def predict(one: dict[str, Any], many: dict[str, Any], n: int) -> dict[str, Any]:
    """What ``n`` cores would give (see the module's docstring), in CPU seconds, from the medians
    of the 1-worker processes run ``one`` and of the processes run with the most workers
    ``many`` (its workers' overheads: each of them ran fewer estimators than the single worker).
    The sweep process is one: its CPU in the cell loop, per cell, bounds the cells per second."""
    serial = one["parent_serial_cpu"]
    overhead_1 = one["worker_overhead_cpu_max"]
    work = one["cells_cpu"] - one["worker_first_cells_cpu_mean"]
    t1 = serial + overhead_1 + work
    parent_loop = one["cells"] * many["parent_loop_cpu_per_cell_ms"] / 1000
    rep = replay(one["estimators_cells"], one["estimator_costs"], n, many["worker_startup_cpu_max"])
    # measured with n workers if a run had as many; else the replay's: the estimators each of n
    # workers would run, with their measured imports
    if many["workers_used"] >= n:
        overhead_n = many["worker_overhead_cpu_max"]
    else:
        overhead_n = rep["overhead_max_s"]
    amdahl = serial + overhead_n + work / n
    return {
        "workers": n,
        "serial_cpu": round(serial, 3),
        "overhead_1_cpu": round(overhead_1, 3),
        "overhead_n_cpu": round(overhead_n, 3),
        "work_cpu": round(work, 3),
        "t1_cpu": round(t1, 3),
        "amdahl_s": round(amdahl, 3),
        "amdahl_ratio": round(t1 / amdahl, 3),
        "serial_only_ratio": round(t1 / (serial + work / n), 3),
        "parent_loop_cpu": round(parent_loop, 3),
        "parent_bound_ratio": round(t1 / (serial + parent_loop), 3),
        "replay": rep,
        "replay_s": round(serial + rep["span_s"], 3),
        "replay_ratio": round(t1 / (serial + rep["span_s"]), 3),
    }


def summarise(result: dict[str, Any]) -> None:
    """Add medians, ratios and predictions to ``result`` (in place)."""
    for res in result["specs"].values():
        res["median"] = {}
        for key, runs in res["runs"].items():
            if runs:
                res["median"][key] = median_run(runs)
        for key, runs in res["raw"].items():
            if runs:
                res["median"][f"raw_{key}"] = {
                    "wall": round(statistics.median(r["wall"] for r in runs), 4)
                }
        if "processes_1" not in res["median"]:
            continue
        one = res["median"]["processes_1"]["wall"]
        res["ratios"] = {
            key: round(one / m["wall"], 3)
            for key, m in res["median"].items()
            if not key.startswith("raw")
        }
        raw1 = res["median"].get("raw_1", {}).get("wall")
        res["raw_ratios"] = {
            key: round(raw1 / m["wall"], 3) if raw1 else None
            for key, m in res["median"].items()
            if key.startswith("raw")
        }
        procs = [int(k.split("_")[1]) for k in res["median"] if k.startswith("processes_")]
        many = res["median"][f"processes_{max(procs)}"]
        one_run = res["median"]["processes_1"]
        res["prediction"] = {
            str(n): predict(one_run, many, n) for n in sorted({max(procs), *TARGETS})
        }
        res["replays"] = {
            str(n): replay(
                one_run["estimators_cells"],
                one_run["estimator_costs"],
                n,
                many["worker_startup_cpu_max"],
            )
            for n in REPLAY_WORKERS
        }
        dask = sorted(int(k.split("_")[1]) for k in res["median"] if k.startswith("dask_"))
        res["dask_vs_processes"] = {
            str(w): round(
                res["median"][f"dask_{w}"]["wall"] / res["median"][f"processes_{w}"]["wall"], 3
            )
            for w in dask
            if f"processes_{w}" in res["median"]
        }
        res["dask_vs_processes_cpu"] = {
            str(w): round(
                res["median"][f"dask_{w}"]["cpu"] / res["median"][f"processes_{w}"]["cpu"], 3
            )
            for w in dask
            if f"processes_{w}" in res["median"]
        }
        # per-cell overhead: the sweep's time less the cells' own work, per cell
        res["overhead_per_cell_ms"] = {
            key: round(1000 * (m["wall"] * int(key.split("_")[1]) - m["cells_cpu"]) / m["cells"], 2)
            for key, m in res["median"].items()
            if not key.startswith("raw")
        }
        res["identical_tables"] = {
            key: m.get("table_hash") == one_run.get("table_hash")
            for key, m in res["median"].items()
            if not key.startswith("raw")
        }


#: Worker counts the projections are made for, and the placement replayed for.
TARGETS = (16,)
REPLAY_WORKERS = (1, 2, 4, 8, 16)


def markdown(result: dict[str, Any]) -> str:
    lines = [
        "# Sweep scaling",
        "",
        f"Machine: {result['machine']}, Python {result['python']}. {result['repeats']} repeat(s), "
        "each configuration once per repeat in alternating order; medians. "
        "`python benchmarks/sweep_scaling.py "
        + " ".join(result["argv"])
        + "`. Load average (1, 5, 15 min) before every run is in results.json; over the "
        f"sweeps it ranged {result['load_range'][0]:.1f}-{result['load_range'][1]:.1f} (1 min).",
    ]
    for name, res in result["specs"].items():
        if "prediction" in res:
            lines += _spec_markdown(name, res, result)
    return "\n".join(lines) + "\n"


def _spec_markdown(name: str, res: dict[str, Any], result: dict[str, Any]) -> list[str]:
    med = res["median"]
    keys = sorted(
        (k for k in med if not k.startswith("raw")),
        key=lambda k: (int(k.rsplit("_", 1)[1]), k),
    )
    lines = [
        "",
        f"## {name} ({med['processes_1']['cells']} cells)",
        "",
        "| executor | workers | wall s | speed-up | CPU s | overhead per cell ms | cells per worker"
        " (min-max) | idle while cells waited s | same table | load (1 min) | runs, wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for key in keys:
        m, runs = med[key], res["runs"][key]
        ex, w = key.rsplit("_", 1)
        cpw = m["cells_per_worker"]
        loads = " ".join(f"{r['load_before'][0]:.1f}" for r in runs)
        walls = " ".join(f"{r['wall']:.2f}" for r in runs)
        lines.append(
            f"| {ex} | {w} | {m['wall']:.2f} | {res['ratios'][key]:.2f} | {m['cpu']:.2f} | "
            f"{res['overhead_per_cell_ms'][key]:.1f} | {cpw[0]}-{cpw[-1]} | "
            f"{m['idle_while_waiting_s']:.2f} | {'yes' if res['identical_tables'][key] else 'NO'} "
            f"| {loads} | {walls} |"
        )
    for key in sorted((k for k in med if k.startswith("raw")), key=lambda k: int(k.split("_")[1])):
        runs = res["raw"][key.split("_", 1)[1]]
        loads = " ".join(f"{r['load_before'][0]:.1f}" for r in runs)
        walls = " ".join(f"{r['wall']:.2f}" for r in runs)
        ratio = res["raw_ratios"][key]
        lines.append(
            f"| raw engine | {key.split('_')[1]} | {med[key]['wall']:.2f} | "
            f"{'' if ratio is None else f'{ratio:.2f}'} | | | | | | {loads} | {walls} |"
        )
    lines += [
        "",
        "Overhead per cell: (wall × workers − the cells' CPU) / cells: what a cell costs beyond "
        "its own work (start-up, imports, hand-out, storing, tables, idle workers).",
    ]
    if res["dask_vs_processes"]:
        lines += [
            "",
            "Dask LocalCluster / local processes, same workers (median wall; CPU): "
            + ", ".join(
                f"{w}: {r:.2f} ({res['dask_vs_processes_cpu'][w]:.2f})"
                for w, r in res["dask_vs_processes"].items()
            )
            + ".",
        ]
    for n, p in res["prediction"].items():
        lines += [
            "",
            f"What {n} cores would give, in CPU seconds (see the script's docstring): serial "
            f"phases of the sweep process {p['serial_cpu']:.2f}, one worker's overhead "
            f"{p['overhead_1_cpu']:.2f} (the largest of {n} workers': {p['overhead_n_cpu']:.2f}, "
            "measured, or replayed where no run had as many), the cells' work "
            f"{p['work_cpu']:.2f}; 1 worker "
            f"{p['t1_cpu']:.2f}. The sweep process's CPU in the cell loop: "
            f"{p['parent_loop_cpu']:.2f} for all cells.",
            "",
            f"| model | {n} workers s | speed-up |",
            "|---|---|---|",
            f"| Amdahl: serial + the largest worker overhead + work / {n} | "
            f"{p['amdahl_s']:.2f} | {p['amdahl_ratio']:.2f} |",
            f"| Amdahl, serial phases only | | {p['serial_only_ratio']:.2f} |",
            f"| bound of one sweep process: serial + its cell-loop CPU | "
            f"{p['serial_cpu'] + p['parent_loop_cpu']:.2f} | {p['parent_bound_ratio']:.2f} |",
            f"| placement replayed: serial + replayed span | {p['replay_s']:.2f} | "
            f"{p['replay_ratio']:.2f} |",
        ]
    lines += [
        "",
        "Placement replayed with the 1-worker run's per-estimator costs (CPU s: "
        + ", ".join(
            f"{e} {c['typical'] * 1000:.0f} ms + {c['extra']:.2f} first"
            for e, c in med["processes_1"]["estimator_costs"].items()
        )
        + "):",
        "",
        "| workers | span s | cells per worker | estimators per worker | idle while cells "
        "waited s (largest) |",
        "|---|---|---|---|---|",
    ]
    for n, r in res["replays"].items():
        cpw, epw = r["cells_per_worker"], r["estimators_per_worker"]
        lines.append(
            f"| {n} | {r['span_s']:.2f} | {cpw[0]}-{cpw[-1]} | {epw[0]}-{epw[-1]} | "
            f"{r['idle_while_waiting_s']:.2f} ({r['idle_while_waiting_max_s']:.2f}) |"
        )
    lines += ["", f"Where the {name} sweep's time goes (medians, seconds unless noted):", ""]
    lines += ["| phase | " + " | ".join(k.replace("_", " ") for k in keys) + " |"]
    lines += ["|---|" + "---|" * len(keys)]
    for key, label, fmt in PHASES:
        lines.append(f"| {label} | " + " | ".join(fmt.format(med[k][key]) for k in keys) + " |")
    lines.append(
        "| estimators per worker (min-max) | "
        + " | ".join(
            f"{med[k]['estimators_per_worker'][0]}-{med[k]['estimators_per_worker'][-1]}"
            for k in keys
        )
        + " |"
    )
    for key in [k for k in keys if k.endswith(f"_{max(int(x.rsplit('_', 1)[1]) for x in keys)}")]:
        lines += [
            "",
            f"How the cells spread over the workers, {key.replace('_', ' ')} workers (the median "
            "run; workers in the order of their first cell):",
            "",
            "| worker | cells | estimators | first cell at s | busy s | CPU s | idle while cells "
            "waited s |",
            "|---|---|---|---|---|---|---|",
        ]
        for i, w in enumerate(med[key]["per_worker"]):
            lines.append(
                f"| {i} | {w['cells']} | {' '.join(w['estimators'])} | {w['first_cell_s']:.2f} | "
                f"{w['busy_s']:.2f} | {w['cpu_s']:.2f} | {w['idle_while_waiting_s']:.2f} |"
            )
    return lines


# ---------------------------------------------------------------- main


def _with_seeds(spec: str, seeds: int | None, tmp: Path) -> str:
    """``spec``, or a copy of it with ``seeds`` seeds (fewer cells, for a quick run)."""
    if seeds is None:
        return spec
    import re

    text = Path(spec).read_text()
    text = re.sub(r"(?m)^seeds = .*$", f"seeds = {seeds}", text)
    text = re.sub(r'(?m)^name = "(.*)"$', rf'name = "\1-{seeds}seeds"', text, count=1)
    path = tmp / f"{Path(spec).stem}_{seeds}seeds.toml"
    path.write_text(text)
    return str(path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--workers", type=int, nargs="+", default=list(WORKERS))
    ap.add_argument("--executors", nargs="+", default=list(EXECUTORS), choices=EXECUTORS)
    ap.add_argument(
        "--dask-workers", type=int, nargs="*", help="worker counts Dask runs (default: all)"
    )
    ap.add_argument(
        "--raw-workers", type=int, nargs="*", help="worker counts of raw episodes (default: all)"
    )
    ap.add_argument("--seeds", type=int, help="run the specs with this many seeds instead")
    ap.add_argument("--specs", nargs="+", default=list(SPECS))
    ap.add_argument("--out", default="results/sweep_scaling")
    ap.add_argument("--add", action="store_true", help="add these runs to OUT/results.json")
    ap.add_argument("--child", nargs=5, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        spec, executor, workers, out, events = args.child
        child(spec, executor, int(workers), out, events)
        return
    out = Path(args.out)
    workers = sorted(args.workers)
    dask_w = set(workers if args.dask_workers is None else args.dask_workers)
    raw_w = set(workers if args.raw_workers is None else args.raw_workers)
    configs = [(e, w) for w in workers for e in args.executors if e == "processes" or w in dask_w]
    result: dict[str, Any] = {
        "machine": f"{os.cpu_count()} cores",
        "python": platform.python_version(),
        "argv": sys.argv[1:],
        "repeats": args.repeats,
        "workers": workers,
        "specs": {},
    }
    if args.add and (out / "results.json").exists():
        result = json.loads((out / "results.json").read_text())
        result["argv"] = [*result["argv"], "+", *sys.argv[1:]]
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        specs = {s: _with_seeds(s, args.seeds, Path(tmp)) for s in args.specs}
        items = {s: episodes(specs[s]) for s in args.specs if raw_w}
        for s in args.specs:
            res = result["specs"].setdefault(Path(specs[s]).stem, {"runs": {}, "raw": {}})
            for e, w in configs:
                res["runs"].setdefault(f"{e}_{w}", [])
            for w in raw_w:
                res["raw"].setdefault(str(w), [])
        for r in range(args.repeats):
            for spec in args.specs:
                res = result["specs"][Path(specs[spec]).stem]
                for e, w in configs if r % 2 == 0 else configs[::-1]:
                    run = run_sweep_once(specs[spec], e, w, Path(tmp))
                    res["runs"][f"{e}_{w}"].append(run)
                    print(
                        f"repeat {r + 1}/{args.repeats}, {Path(spec).stem}, {e}, {w} worker(s): "
                        f"{run['wall']:.2f} s, CPU {run['cpu']:.2f} s, cells per worker "
                        f"{run['cells_per_worker'][0]}-{run['cells_per_worker'][-1]}, idle while "
                        f"cells waited {run['idle_while_waiting_s']:.2f} s, load "
                        f"{run['load_before']}",
                        file=sys.stderr,
                    )
                    if e == "processes" and w in raw_w:
                        raw = run_raw_once(w, items[spec])
                        res["raw"][str(w)].append(raw)
                        print(f"  raw engine: {raw['wall']:.2f} s", file=sys.stderr)
                    _write(result, out)
    _write(result, out)
    print((out / "summary.md").read_text())


def _write(result: dict[str, Any], out: Path) -> None:
    """Summarise ``result`` and write OUT/results.json and OUT/summary.md."""
    loads = [
        r["load_before"][0]
        for res in result["specs"].values()
        for runs in res["runs"].values()
        for r in runs
    ]
    result["load_range"] = [min(loads), max(loads)] if loads else [0.0, 0.0]
    summarise(result)
    (out / "results.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "summary.md").write_text(markdown(result))


if __name__ == "__main__":
    main()
