"""Sweep scaling: smoke48 (960 cells) with 1..N workers, on local processes and on a Dask
LocalCluster, against raw engine episodes with as many processes, in the same run; where each
sweep's time goes; and how its cells spread over the workers.

    python benchmarks/sweep_scaling.py [--repeats 3] [--workers 1 2 4 8 16]
        [--executors processes dask] [--specs benchmarks/smoke48.toml] [--out results/sweep_scaling]

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
workers (measured in the N-worker run: each pays it at once) + work / N. And the schedule: serial
+ the busiest worker's CPU (overhead and cells) in the N-worker run as it was measured.

Writes ``OUT/sweep_scaling.json`` (every run, the load averages before each) and
``OUT/sweep_scaling.md``.
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

    put = store.CellWriter.put

    def put_timed(self: Any, key: str, data: dict[str, Any]) -> None:
        timing = data.pop("_timing")
        _EVENTS["cells"].append(
            {**timing, "received": time.time(), "est": data["config"]["estimator"]}
        )
        put(self, key, data)

    save_many = store.CellStore.save_many

    def save_many_timed(self: Any, cells: list[Any], flush: Any = map) -> list[str]:
        t0 = time.time()
        try:
            return save_many(self, cells, flush)
        finally:
            _EVENTS["batches"].append((t0, time.time(), len(cells)))

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
    return {
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
    return res


def _cpu_of_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_sweep_once(spec: str, executor: str, workers: int, tmp: Path) -> dict[str, Any]:
    # a folder per spec and executor: --fresh would otherwise time deleting another run's cells
    out = tmp / f"{Path(spec).stem}_{executor}_w{workers}"
    events = tmp / "events.json"
    cmd = [sys.executable, __file__, "--child", spec, executor, str(workers), str(out), str(events)]
    load = os.getloadavg()
    cpu, launched = _cpu_of_children(), time.time()
    subprocess.run(cmd, check=True, env={**os.environ, "PYTHONPATH": os.getcwd()})
    ended = time.time()
    res = breakdown(json.loads(events.read_text()), launched, ended, workers)
    # the sweep's workers ended before it, so their CPU time is counted with it
    res["cpu"] = _cpu_of_children() - cpu
    res["load_before"] = [round(x, 2) for x in load]
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


def predict(one: dict[str, Any], many: dict[str, Any], n: int) -> dict[str, float]:
    """What ``n`` cores would give (see the module's docstring), from the medians of the
    1-worker processes run ``one`` and of the ``n``-worker run ``many``, in CPU seconds."""
    serial = one["parent_serial_cpu"]
    overhead_1 = one["worker_overhead_cpu_max"]
    work = one["cells_cpu"] - one["worker_first_cells_cpu_mean"]
    t1 = serial + overhead_1 + work
    amdahl = serial + many["worker_overhead_cpu_max"] + work / n
    schedule = serial + many["busiest_worker_cpu"]
    return {
        "workers": n,
        "serial_cpu": round(serial, 3),
        "overhead_1_cpu": round(overhead_1, 3),
        "overhead_n_cpu": round(many["worker_overhead_cpu_max"], 3),
        "work_cpu": round(work, 3),
        "t1_cpu": round(t1, 3),
        "amdahl_s": round(amdahl, 3),
        "amdahl_ratio": round(t1 / amdahl, 3),
        "serial_only_ratio": round(t1 / (serial + work / n), 3),
        "schedule_s": round(schedule, 3),
        "schedule_ratio": round(t1 / schedule, 3),
    }


def summarise(result: dict[str, Any]) -> None:
    """Add medians, ratios and predictions to ``result`` (in place)."""
    for res in result["specs"].values():
        res["median"] = {}
        for key, runs in res["runs"].items():
            res["median"][key] = median_run(runs)
        for key, runs in res["raw"].items():
            res["median"][f"raw_{key}"] = {
                "wall": round(statistics.median(r["wall"] for r in runs), 4)
            }
        one = res["median"]["processes_1"]["wall"]
        raw1 = res["median"]["raw_1"]["wall"]
        res["ratios"] = {
            key: round(one / m["wall"], 3)
            for key, m in res["median"].items()
            if not key.startswith("raw")
        }
        res["raw_ratios"] = {
            key: round(raw1 / m["wall"], 3)
            for key, m in res["median"].items()
            if key.startswith("raw")
        }
        n = max(result["workers"])
        res["prediction"] = predict(
            res["median"]["processes_1"], res["median"][f"processes_{n}"], n
        )
        dask = [w for w in result["workers"] if f"dask_{w}" in res["median"]]
        res["dask_vs_processes"] = {
            str(w): round(
                res["median"][f"dask_{w}"]["wall"] / res["median"][f"processes_{w}"]["wall"], 3
            )
            for w in dask
        }
        res["dask_vs_processes_cpu"] = {
            str(w): round(
                res["median"][f"dask_{w}"]["cpu"] / res["median"][f"processes_{w}"]["cpu"], 3
            )
            for w in dask
        }


def markdown(result: dict[str, Any]) -> str:
    lines = [
        "# Sweep scaling",
        "",
        f"Machine: {result['machine']}. {result['repeats']} repeats, each configuration once per "
        "repeat in alternating order; medians. `python benchmarks/sweep_scaling.py "
        + " ".join(result["argv"])
        + "`. Load average (1, 5, 15 min) before every run is in sweep_scaling.json; over the "
        f"sweeps it ranged {result['load_range'][0]:.1f}-{result['load_range'][1]:.1f} (1 min).",
    ]
    for name, res in result["specs"].items():
        lines += _spec_markdown(name, res, result)
    return "\n".join(lines) + "\n"


def _spec_markdown(name: str, res: dict[str, Any], result: dict[str, Any]) -> list[str]:
    med = res["median"]
    keys = [k for k in med if not k.startswith("raw")]
    lines = [
        "",
        f"## {name}",
        "",
        "| executor | workers | wall s | speed-up | CPU s | cells per worker (min-max) "
        "| idle while cells waited s | load (1 min) | runs, wall s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for key in keys:
        m, runs = med[key], res["runs"][key]
        ex, w = key.rsplit("_", 1)
        cpw = m["cells_per_worker"]
        loads = " ".join(f"{r['load_before'][0]:.1f}" for r in runs)
        walls = " ".join(f"{r['wall']:.2f}" for r in runs)
        lines.append(
            f"| {ex} | {w} | {m['wall']:.2f} | {res['ratios'][key]:.2f} | {m['cpu']:.2f} | "
            f"{cpw[0]}-{cpw[-1]} | {m['idle_while_waiting_s']:.2f} | {loads} | {walls} |"
        )
    for key in sorted((k for k in med if k.startswith("raw")), key=lambda k: int(k.split("_")[1])):
        runs = res["raw"][key.split("_", 1)[1]]
        loads = " ".join(f"{r['load_before'][0]:.1f}" for r in runs)
        walls = " ".join(f"{r['wall']:.2f}" for r in runs)
        lines.append(
            f"| raw engine | {key.split('_')[1]} | {med[key]['wall']:.2f} | "
            f"{res['raw_ratios'][key]:.2f} | | | | {loads} | {walls} |"
        )
    p = res["prediction"]
    lines += [
        "",
        f"What {p['workers']} cores would give, in CPU seconds (see the script's docstring): "
        f"serial phases {p['serial_cpu']:.2f}, one worker's overhead {p['overhead_1_cpu']:.2f} "
        f"(the largest of {p['workers']} workers': {p['overhead_n_cpu']:.2f}), cells' work "
        f"{p['work_cpu']:.2f}; 1 worker {p['t1_cpu']:.2f}.",
        "",
        f"| model | {p['workers']} workers s | speed-up |",
        "|---|---|---|",
        f"| Amdahl: serial + largest worker overhead + work / {p['workers']} | "
        f"{p['amdahl_s']:.2f} | {p['amdahl_ratio']:.2f} |",
        f"| Amdahl, serial phases only | | {p['serial_only_ratio']:.2f} |",
        f"| measured schedule: serial + busiest worker | {p['schedule_s']:.2f} | "
        f"{p['schedule_ratio']:.2f} |",
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
    return lines


# ---------------------------------------------------------------- main


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--workers", type=int, nargs="+", default=list(WORKERS))
    ap.add_argument("--executors", nargs="+", default=list(EXECUTORS), choices=EXECUTORS)
    ap.add_argument("--specs", nargs="+", default=list(SPECS))
    ap.add_argument("--out", default="results/sweep_scaling")
    ap.add_argument("--child", nargs=5, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        spec, executor, workers, out, events = args.child
        child(spec, executor, int(workers), out, events)
        return
    if 1 not in args.workers or "processes" not in args.executors:
        ap.error("the speed-ups are relative to processes with 1 worker: include both")
    configs = [(e, w) for w in sorted(args.workers) for e in args.executors]
    result: dict[str, Any] = {
        "machine": f"{os.cpu_count()} cores",
        "python": platform.python_version(),
        "argv": sys.argv[1:],
        "repeats": args.repeats,
        "workers": sorted(args.workers),
        "specs": {},
    }
    items = {s: episodes(s) for s in args.specs}
    for s in args.specs:
        result["specs"][Path(s).stem] = {
            "runs": {f"{e}_{w}": [] for e, w in configs},
            "raw": {str(w): [] for w in sorted(args.workers)},
        }
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            for spec in args.specs:
                res = result["specs"][Path(spec).stem]
                for e, w in configs if r % 2 == 0 else configs[::-1]:
                    run = run_sweep_once(spec, e, w, Path(tmp))
                    res["runs"][f"{e}_{w}"].append(run)
                    print(
                        f"repeat {r + 1}/{args.repeats}, {Path(spec).stem}, {e}, {w} worker(s): "
                        f"{run['wall']:.2f} s, CPU {run['cpu']:.2f} s, load {run['load_before']}",
                        file=sys.stderr,
                    )
                    if e == args.executors[0]:
                        raw = run_raw_once(w, items[spec])
                        res["raw"][str(w)].append(raw)
                        print(f"  raw engine: {raw['wall']:.2f} s", file=sys.stderr)
    loads = [
        r["load_before"][0]
        for res in result["specs"].values()
        for runs in res["runs"].values()
        for r in runs
    ]
    result["load_range"] = [min(loads), max(loads)]
    summarise(result)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_scaling.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "sweep_scaling.md").write_text(markdown(result))
    print(markdown(result))


if __name__ == "__main__":
    main()
