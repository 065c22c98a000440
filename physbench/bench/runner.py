"""Run a sweep: every cell of a spec through an executor into the cell store, then the tables.

A cell that raises (an exploding simulation that the loop does not absorb, an estimator without
weights, ...) is stored as failed with its error and the sweep goes on. Re-running on the same
output folder runs only the cells without a stored result, and the long table is rebuilt from the
stored cells in spec order, so an interrupted-and-resumed sweep ends with exactly the rows of an
uninterrupted one. A cell whose worker process dies (``os._exit``, a segfault) is retried once on
its own, then stored as failed (executor ``processes``). One sweep at a time writes an output
folder: a second one refuses, or waits with ``wait``. Every stored cell carries a stamp of what
produced it (:mod:`physbench.bench.stamp`); a resume refuses finished cells whose stamp differs
from now.
"""

from __future__ import annotations

import contextlib
import functools
import json
import sys
import threading
import time
import traceback
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from physbench.bench.spec import Cell, Spec
from physbench.bench.store import RESULTS, CellStore, CellWriter, atomic_write
from physbench.errors import PhysbenchError, counted
from physbench.experiment import RunConfig

if TYPE_CHECKING:
    import pandas as pd

    from physbench.bench.executors import Executor

#: Distributions whose versions are recorded with every cell (those installed).
VERSIONED = (
    "physbench",
    "numpy",
    "scipy",
    "pymunk",
    "box2d",
    "hyperopt",
    "optuna",
    "nevergrad",
    "cmaes",
    "torch",
)


@functools.cache
def versions() -> dict[str, str]:
    """Python and the installed versions of :data:`VERSIONED` in this process."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for dist in VERSIONED:
        with contextlib.suppress(PackageNotFoundError):
            out[dist] = version(dist)
    return out


def run_cell(config: RunConfig) -> dict[str, Any]:
    """Run one cell; called by the executor, in whatever process it chooses. Never raises for a
    failing cell: the error is returned, with its traceback for the cell file."""
    from physbench.experiment import run_config

    t0 = time.perf_counter()
    out: dict[str, Any] = {
        "config": config.to_dict(),
        "status": "ok",
        "error": None,
        "history": None,
    }
    try:
        out["history"] = run_config(config, probe=False).to_dict()  # a sweep scores against truth
    except Exception as exc:  # any failure of one cell is data, not the end of the sweep
        out.update(
            status="failed",
            error=f"{type(exc).__name__}: {exc}",
            traceback=traceback.format_exc(limit=8),
        )
    out["t_cell"] = time.perf_counter() - t0
    out["versions"] = versions()
    return out


def libraries(config: RunConfig) -> tuple[str, ...]:
    """What a cell's first run in a process imports beyond physbench (its estimator's, engines'
    and renderer's libraries, up to a second): the executor's ``affinity``, so that a worker keeps
    to the cells whose libraries it has loaded."""
    return (config.estimator, config.engine, config.observe_engine or "", config.renderer)


def died_cell(config: RunConfig, error: str) -> dict[str, Any]:
    """The failed cell for a ``config`` whose process died running it (see
    :mod:`~physbench.bench.executors`); called by the executor in the main process."""
    return {
        "config": config.to_dict(),
        "status": "failed",
        "error": f"WorkerDied: {error}",
        "history": None,
        "t_cell": None,
        "versions": versions(),
    }


@dataclass
class SweepResult:
    """What :func:`run_sweep` did and produced."""

    out: Path
    cells: int
    ran: int
    skipped: int
    failed: int
    wall_s: float
    executor: str
    table: pd.DataFrame
    stats: pd.DataFrame


class SweepFailedError(PhysbenchError):
    """Every cell of a sweep failed (raised after the tables are written, which hold each cell's
    error); ``result`` is what :func:`run_sweep` would have returned."""

    def __init__(self, result: SweepResult, name: str) -> None:
        self.result = result
        errors = result.table.drop_duplicates("cell")["error"].fillna("no error recorded")
        common = errors.astype(str).str.split("\n").str[0].str.slice(0, 300).value_counts()
        shown = "; ".join(f"{counted(int(n), 'cell')}: {e}" for e, n in common.head(3).items())
        more = f"; and {len(common) - 3} other errors" if len(common) > 3 else ""
        super().__init__(
            f"sweep {name!r}: all {counted(result.cells, 'cell')} failed ({shown}{more}); each "
            f"cell's error and traceback are in {result.out / 'cells'}, the table in "
            f"{result.out / RESULTS}"
        )


def identity(c: Cell) -> dict[str, Any]:
    """What the long table says of ``c`` beyond its stored data (:func:`~.tables.cell_rows`)."""
    return {
        "key": c.key,
        "index": c.index,
        "scene": c.scene,
        "label": c.label,
        "renderer_label": c.renderer_label,
        "observer_label": c.observer_label,
    }


def assemble(
    cells: list[Cell], store: CellStore, built: dict[str, list[dict[str, Any]]] | None = None
) -> pd.DataFrame:
    """The long table from the stored cells, in cell order (cells without a result are left
    out). ``built`` holds rows already made from stored cells, by key (a sweep makes them as it
    stores its cells); the other cells are read from ``store``."""
    from physbench.bench.tables import cell_rows, to_frame

    rows: list[dict[str, Any]] = []
    for c in cells:
        if built is not None and c.key in built:
            rows += built[c.key]
        elif (data := store.load(c.key)) is not None:
            rows += cell_rows(identity(c), data)
    return to_frame(rows)


def write_table(df: pd.DataFrame, out: Path) -> Path:
    import io

    buf = io.BytesIO()
    df.to_parquet(buf, index=False)
    atomic_write(out / RESULTS, buf.getvalue())
    return out / RESULTS


def read_table(path: str | Path) -> pd.DataFrame:
    """A sweep's long table from its folder or its ``results.parquet``, checked and upgraded:
    :func:`~.tables.read_results` (kept under this name for its callers)."""
    from physbench.bench.tables import read_results

    return read_results(path)


#: Bytes the list of a sweep's cells holds per cell: 640 measured with tracemalloc for the 40,000
#: cells of benchmarks/smoke.toml at 2,000 seeds, rounded up.
CELL_BYTES = 1000


def check_size(spec: Spec, workers: int | None = None) -> None:
    """Called before a sweep starts (before its cells are even listed): refuse one this machine
    cannot finish (:mod:`physbench.cost`). Each cell is a run
    (:func:`physbench.experiment.check_size`) of its scene's first seed; ``workers`` cells (default:
    every core) run at once, so their memory adds up; the time is their compute added up."""
    import math
    import os

    from physbench import cost
    from physbench.scenes import resolve_scene

    parallel = max(1, workers or os.cpu_count() or 1)
    n_cells, total, scene = 0, cost.Cost(0.0, 0.0), None
    fixed = math.prod(len(spec.axes[a]) for a in spec.axes if a not in ("resolution", "iterations"))
    per_unknowns = len(spec.renderers) * len(spec.observers) * fixed
    per_unknowns *= len(spec.estimators) * len(spec.seeds)
    for sc in spec.scenes:
        scene = resolve_scene(sc.path, spec.seeds[0] if spec.seeds else 0)
        n = len(sc.unknowns) * per_unknowns
        n_unknowns = max(len(u) for u in sc.unknowns) if sc.unknowns else 1
        for resolution in spec.axes["resolution"]:
            channels = max(cost.channels(m, len(scene.bodies)) for m in spec.axes["render_mode"])
            one = cost.simulation(
                scene.frames,
                scene.substeps,
                len(scene.bodies),
                resolution=resolution,
                n_channels=channels,
                held=3,
            )
            for iterations in spec.axes["iterations"]:
                sims = iterations + 1 + 2 * n_unknowns
                total = total + one.times(n * sims)
                n_cells += n
    if scene is None:
        return
    held = total.memory * min(parallel, n_cells) + n_cells * CELL_BYTES
    cost.check(
        cost.Cost(held, total.seconds),
        f"this sweep ({n_cells} cells, {parallel} at a time; e.g. scene {scene.name}: "
        f"{cost.simulations(max(spec.axes['iterations']), scene)} per cell)",
        "the seeds, estimators, axes or iterations of the spec",
    )


def run_sweep(
    spec: Spec,
    out: str | Path,
    *,
    executor: str = "processes",
    workers: int | None = None,
    address: str | None = None,
    fresh: bool = False,
    retry_failed: bool = False,
    allow_stale: bool = False,
    wait: bool = False,
    progress: bool = True,
    command: str = "",
) -> SweepResult:
    """Run the cells of ``spec`` that ``out`` lacks, then write ``results.parquet``, the summary
    tables and ``run.json`` (one entry per invocation: executor, workers, cells run, wall time).
    Before anything runs, refuses (:class:`~physbench.bench.stamp.StaleCellsError`) to keep
    finished cells whose stamp differs from now, unless ``allow_stale``. Holds the folder's lock
    throughout: another sweep writing ``out`` is refused (:class:`~.store.FolderBusyError`), or
    waited for with ``wait``. A sweep whose every cell failed raises :class:`SweepFailedError`
    once its tables are written."""
    from physbench.bench.executors import make_executor

    check_size(spec, 1 if executor == "serial" else workers)
    out = Path(out)
    ex = make_executor(executor, workers=workers, address=address)
    with CellStore(out).writing(wait=wait) as store:
        return _run_locked(
            spec,
            store,
            ex,
            fresh=fresh,
            retry_failed=retry_failed,
            allow_stale=allow_stale,
            progress=progress,
            command=command,
        )


def _import_tables() -> None:
    """Import what :func:`assemble`, :func:`write_table` and the summary need; run in a thread
    while the cells run, so that building the tables after the last cell does not start with
    the imports."""
    # pandas and pyarrow.parquet (DataFrame.to_parquet imports them on its first call, pandas
    # takes ~0.2 s), the bootstrap intervals, the posterior scores of the stats
    import pandas  # noqa: F401
    import pyarrow.pandas_compat
    import pyarrow.parquet  # noqa: F401
    import scipy.stats  # noqa: F401

    import physbench.bench.summary
    import physbench.posterior.scoring  # noqa: F401

    versions()  # for run.json


def _log_run(spec: Spec, out: Path, entry: dict[str, Any], *, cells: int, failed: int) -> None:
    """Add this invocation's ``entry`` to ``out/run.json`` and update its totals."""
    log_path = out / "run.json"
    try:
        log = json.loads(log_path.read_text())
    except (OSError, ValueError):
        log = {"runs": []}
    log.update(spec=spec.name, spec_path=spec.path, cells=cells, failed=failed, versions=versions())
    log["runs"].append(entry)
    atomic_write(log_path, (json.dumps(log, indent=1) + "\n").encode())


def _run_cells(
    ex: Executor,
    todo: list[Cell],
    store: CellStore,
    stamps: dict[str, dict[str, Any]],
    bar: Any,
    built: dict[str, list[dict[str, Any]]],
) -> int:
    """Run ``todo`` on ``ex``, storing each cell as it arrives (in a :class:`CellWriter`, which
    also fills ``built`` with each stored cell's table rows) and counting it on ``bar``; returns
    how many failed."""
    from physbench.bench.tables import cell_rows

    by_config = {id(c.config): c for c in todo}  # executors hand back the objects they were given
    by_key = {c.key: c for c in todo}

    def saved(key: str, data: dict[str, Any]) -> None:
        # a cell whose rows cannot be made here is read again by assemble, which says why
        with contextlib.suppress(Exception):
            built[key] = cell_rows(identity(by_key[key]), data)

    failed = 0
    with ex, CellWriter(store, saved) as writer:
        configs = [c.config for c in todo]
        for config, data in ex.map_unordered(run_cell, configs, died_cell, libraries):
            key = by_config[id(config)].key
            writer.put(key, {**data, "stamp": stamps[key]})
            if data["status"] != "ok":
                failed += 1
                bar.set_postfix(failed=failed, refresh=False)
            bar.update(1)
    return failed


def _run_locked(
    spec: Spec,
    store: CellStore,
    ex: Executor,
    *,
    fresh: bool,
    retry_failed: bool,
    allow_stale: bool,
    progress: bool,
    command: str,
) -> SweepResult:
    """:func:`run_sweep` once it holds the lock on ``store``'s folder."""
    from tqdm import tqdm

    from physbench.bench.stamp import StaleCellsError, Stamper, describe, find_stale
    from physbench.bench.summary import write_summary

    out = store.out
    cells = spec.cells()
    store.prepare(fresh=fresh)

    stored = {c.key: data for c in cells if (data := store.load(c.key)) is not None}
    kept = [
        c
        for c in cells
        if c.key in stored and not (retry_failed and stored[c.key].get("status") != "ok")
    ]
    stamper = Stamper()
    stamps = {c.key: stamper.stamp(c.config) for c in cells}
    stale = find_stale(kept, stored, stamps)
    if stale and not allow_stale:
        raise StaleCellsError(describe(stale, len(kept), str(out)))
    if spec.source:
        atomic_write(out / "spec.toml", spec.source.encode())

    done = {c.key for c in kept}
    todo = [c for c in cells if c.key not in done]
    # The tables' libraries take ~0.6 s to import: do it while the workers run the cells.
    warm = threading.Thread(target=_import_tables, name="physbench-import-tables", daemon=True)
    warm.start()
    t0 = time.perf_counter()
    started = datetime.now(UTC).isoformat(timespec="seconds")
    n_failed = 0
    bar = tqdm(
        total=len(cells),
        initial=len(cells) - len(todo),
        desc=spec.name,
        unit="cell",
        file=sys.stderr,
        disable=None if progress else True,
        dynamic_ncols=True,
    )
    built: dict[str, list[dict[str, Any]]] = {}
    try:
        if todo:
            n_failed = _run_cells(ex, todo, store, stamps, bar, built)
    finally:
        bar.close()
    wall = time.perf_counter() - t0

    warm.join()
    table = assemble(cells, store, built)
    write_table(table, out)
    st = write_summary(table, out, title=spec.name)
    failed = int((table.drop_duplicates("cell")["status"] != "ok").sum())
    _log_run(
        spec,
        out,
        {
            "started": started,
            "executor": ex.describe(),
            "workers": ex.workers,
            "ran": len(todo),
            "skipped": len(cells) - len(todo),
            "failed_now": n_failed,
            "kept_stale": len(stale),
            "wall_s": round(wall, 2),
            "command": command,
        },
        cells=len(cells),
        failed=failed,
    )
    result = SweepResult(
        out, len(cells), len(todo), len(cells) - len(todo), failed, wall, ex.describe(), table, st
    )
    if cells and failed == len(cells):
        raise SweepFailedError(result, spec.name)
    return result
