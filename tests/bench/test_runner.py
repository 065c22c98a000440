"""Running a sweep: the long table, summaries, failed cells, resume-by-skipping, identical tables
from every executor, and the renderer of a spec really drawing (``physbench bench`` itself:
tests/commands/test_bench.py)."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest

from physbench.bench.runner import run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import SCHEMA, TIMINGS, without_timings
from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl
from physbench.plugins import build_registry, get_registry, reset_registry
from physbench.render.base import DEFAULT_RENDERER

TINY = {
    "name": "tiny",
    "estimators": ["random", {"name": "optuna", "options": {"startup": 2}}],
    "seeds": 2,
    "iterations": 3,
    "resolution": 32,
    "scenes": [{"name": "three_circles", "unknowns": ["mass", "mass+elasticity"]}],
}


class Flaky(CorrectionEstimator):
    """Random search that fails in ``start`` when told to: a cell that raises."""

    name: ClassVar[str] = "flaky"

    def __init__(self, fail: bool = False) -> None:
        self.options = {"fail": fail}

    def start(self, task: Any, *, seed: int) -> None:
        if self.options["fail"]:
            raise PhysbenchError("flaky: asked to fail")
        self.space, self.rng = task.space, np.random.default_rng(seed)

    def propose(self, step: Any) -> dict[str, float]:
        return self.space.from_unit(self.rng.random(len(self.space)))


class _Plugin:
    @staticmethod
    @hookimpl
    def register_estimators() -> list[type]:
        return [Flaky]


@pytest.fixture
def flaky_registry() -> Iterator[None]:
    reset_registry(build_registry(extra=[("test-flaky", _Plugin())]))
    yield
    reset_registry(None)


def test_long_table_summary_and_failed_cells(tmp_path: Path, flaky_registry: None) -> None:
    spec = parse_spec(
        {
            **TINY,
            "estimators": ["random", {"name": "flaky", "label": "bad", "options": {"fail": True}}],
        }
    )
    res = run_sweep(spec, tmp_path, executor="serial", progress=False)
    df = pd.read_parquet(tmp_path / "results.parquet")
    assert list(df.columns) == list(SCHEMA) and res.failed == 4 and res.ran == 8
    ok, bad = df[df["status"] == "ok"], df[df["status"] == "failed"]
    assert len(ok) == 4 * 3 and len(bad) == 4  # one row per iteration; one row per failed cell
    assert (
        bad["iteration"].isna().all()
        and (bad["error"] == "PhysbenchError: flaky: asked to fail").all()
    )
    assert ok["iteration"].tolist() == [0, 1, 2] * 4
    first = ok.iloc[0]
    assert json.loads(first["keys"]) == ["a.mass", "b.mass"] and set(
        json.loads(first["params"])
    ) == {"a.mass", "b.mass"}
    assert json.loads(ok.iloc[6]["keys"]) == ["a.mass", "a.elasticity", "b.mass", "b.elasticity"]
    assert (ok["best_nmse"] <= ok.groupby("cell")["nmse"].transform("max")).all()
    assert json.loads(first["versions"])["physbench"] and first["t_cell"] > 0

    st = pd.read_csv(tmp_path / "stats.csv")
    row = st[(st["estimator"] == "random") & (st["unknowns"] == "mass")].iloc[0]
    finals = ok[(ok["unknowns"] == "mass") & (ok["iteration"] == 2)]["best_nmse"]
    assert (
        row["n"] == 2
        and row["mean"] == pytest.approx(finals.mean())
        and row["median"] == pytest.approx(finals.median())
    )
    assert row["ci_low"] <= row["mean"] <= row["ci_high"] and row["paper_nn"] == "(2.6 ± 0.9)e-03"
    assert st[st["estimator"] == "bad"]["failed"].tolist() == [2, 2]
    md = (tmp_path / "summary.md").read_text()
    assert (
        "| 3 circles | paper NN | (2.6 ± 0.9)e-03 | (1.4 ± 0.5)e-02 |" in md and "failed (2)" in md
    )
    assert "flaky: asked to fail" in md
    assert r"$(2.6 \pm 0.9) \times 10^{-3}$" in (tmp_path / "summary.tex").read_text()
    assert pd.read_csv(tmp_path / "summary.csv").columns.tolist() == [
        "scene",
        "estimator",
        "Mass",
        "Mass + Elasticity",
    ]

    again = run_sweep(
        spec, tmp_path, executor="serial", progress=False
    )  # everything is done: nothing runs
    assert (again.ran, again.skipped) == (0, 8)
    pd.testing.assert_frame_equal(again.table, df)
    retried = run_sweep(spec, tmp_path, executor="serial", progress=False, retry_failed=True)
    assert (retried.ran, retried.failed) == (4, 4)
    log = json.loads((tmp_path / "run.json").read_text())
    assert [r["ran"] for r in log["runs"]] == [8, 0, 4]


#: An estimator ``exiting`` (random search) whose process exits in ``propose`` in the cell of
#: seed 1.
EXITING = """
import os
from typing import ClassVar

import numpy as np

from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl
from physbench.loop import derive_seeds


class Exiting(CorrectionEstimator):
    name: ClassVar[str] = "exiting"

    def __init__(self):
        self.options = {}

    def start(self, task, *, seed):
        self.space, self.rng, self.seed = task.space, np.random.default_rng(seed), seed

    def propose(self, step):
        if self.seed == derive_seeds(1).estimator:
            os._exit(3)
        return self.space.from_unit(self.rng.random(len(self.space)))


@hookimpl
def register_estimators():
    return [Exiting]
"""


@pytest.mark.parametrize(
    ("executor", "how"),
    [
        (
            "processes",
            "the worker process died: exit code 3, also when run again alone in a fresh process",
        ),
        (
            "dask",
            "the Dask worker process died running it (KilledWorker), also when run again "
            "alone on the cluster",
        ),
    ],
)
def test_a_cell_that_kills_its_worker_is_recorded_failed_and_the_sweep_goes_on(
    tmp_path: Path, plugin: Any, executor: str, how: str
) -> None:
    if executor == "dask":
        pytest.importorskip("distributed")
    plugin("pb_exiting", EXITING)
    spec = parse_spec(
        {
            "name": "exits",
            "estimators": ["random", "exiting"],
            "seeds": 3,
            "iterations": 2,
            "resolution": 16,
            "scenes": [{"name": "second_order", "unknowns": ["elasticity"]}],
        }
    )
    res = run_sweep(spec, tmp_path, executor=executor, workers=2, progress=False)
    assert (res.ran, res.failed) == (6, 1)
    df = pd.read_parquet(tmp_path / "results.parquet")
    cells = df.drop_duplicates("cell").set_index(["estimator", "seed"])
    assert cells.loc[("exiting", 1), "status"] == "failed"
    assert cells.loc[("exiting", 1), "error"] == f"WorkerDied: {how}"
    assert (cells.drop(index=("exiting", 1))["status"] == "ok").all() and len(cells) == 6
    assert "WorkerDied" in (tmp_path / "summary.md").read_text()


def test_the_table_is_made_as_cells_are_stored_and_equals_the_one_read_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.bench.runner import assemble
    from physbench.bench.store import CellStore

    loads: list[str] = []
    load = CellStore.load

    def counted_load(self: CellStore, key: str) -> dict[str, Any] | None:
        loads.append(key)
        return load(self, key)

    monkeypatch.setattr(CellStore, "load", counted_load)
    spec = parse_spec({**TINY, "seeds": 2})
    res = run_sweep(spec, tmp_path, executor="serial", progress=False)
    cells = spec.cells()
    # once each, to find what is done before the sweep; the table came from the rows made while
    # storing, not from reading every cell again
    assert sorted(loads) == sorted(c.key for c in cells)
    pd.testing.assert_frame_equal(res.table, assemble(cells, CellStore(tmp_path)), check_exact=True)


@pytest.mark.slow
def test_executors_give_identical_tables(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    reset_registry(None)
    get_registry()
    spec = parse_spec(TINY)
    tables = {}
    for name, kw in [("serial", {}), ("processes", {"workers": 2}), ("dask", {"workers": 2})]:
        tables[name] = run_sweep(spec, tmp_path / name, executor=name, progress=False, **kw).table
    assert len(tables["serial"]) == 8 * 3 and (tables["serial"]["status"] == "ok").all()
    base = without_timings(tables["serial"])
    assert not any(c in base.columns for c in TIMINGS)
    for name in ("processes", "dask"):
        pd.testing.assert_frame_equal(without_timings(tables[name]), base, check_exact=True)
        on_disk = pd.read_parquet(tmp_path / name / "results.parquet")
        pd.testing.assert_frame_equal(without_timings(on_disk), base, check_exact=True)


def test_a_plugin_renderer_is_selected_by_the_spec(tmp_path: Path, blocks: ModuleType) -> None:
    small = {**TINY, "estimators": ["random"], "scenes": ["second_order"]}
    base = run_sweep(parse_spec(small), tmp_path / "default", executor="serial", progress=False)
    assert blocks.CALLS == 0 and (base.table["renderer"] == DEFAULT_RENDERER).all()
    assert (base.table["renderer_options"] == "{}").all()

    spec = parse_spec({**small, "renderer": {"name": "blocks", "options": {"gain": 0.5}}})
    res = run_sweep(spec, tmp_path / "blocks", executor="serial", progress=False)
    # per cell at least the observation and one render per iteration
    assert blocks.CALLS >= 2 * (1 + 3)
    df = res.table
    assert list(df.columns) == list(SCHEMA) and (df["status"] == "ok").all()
    assert set(df["renderer"]) == {"blocks(gain=0.5)"} and set(df["renderer_name"]) == {"blocks"}
    assert set(df["renderer_options"]) == {'{"gain":0.5}'}
    # the same truths and guesses, seen through other frames: other image errors
    assert df["params"].tolist() == base.table["params"].tolist()
    assert not np.allclose(df["image_mse"], base.table["image_mse"])
    st = pd.read_csv(tmp_path / "blocks" / "stats.csv")
    assert st["renderer"].tolist() == ["blocks(gain=0.5)"]


def test_several_renderers_split_the_summary(tmp_path: Path, blocks: ModuleType) -> None:
    spec = parse_spec(
        {
            **TINY,
            "estimators": ["random"],
            "scenes": ["second_order"],
            "renderer": [DEFAULT_RENDERER, "blocks"],
        }
    )
    run_sweep(spec, tmp_path, executor="serial", progress=False)
    summary = pd.read_csv(tmp_path / "summary.csv")
    assert summary.columns.tolist() == ["scene", "renderer", "estimator", "Mass"]
    ours = summary[summary["estimator"] == "random"]
    assert ours["renderer"].tolist() == [DEFAULT_RENDERER, "blocks"]


#: Builds a finished sweep's tables in a fresh interpreter after ``_import_tables`` and prints
#: the modules that building them still imported.
LATE_IMPORTS = """
import sys
from pathlib import Path
from physbench.bench import runner
from physbench.bench.spec import parse_spec
from physbench.bench.store import CellStore
from physbench.bench.summary import write_summary
from physbench.plugins import get_registry

out = Path(sys.argv[1])
cells = parse_spec(SPEC).cells()
get_registry()  # a sweep has loaded the plugins before its cells run
runner._import_tables()
before = set(sys.modules)
table = runner.assemble(cells, CellStore(out))
runner.write_table(table, out)
write_summary(table, out, title="tiny")
print(" ".join(sorted(set(sys.modules) - before)))
"""


def test_building_the_tables_imports_no_library_after_the_cells(tmp_path: Path) -> None:
    import subprocess
    import sys

    spec = {**TINY, "seeds": 1, "estimators": ["random"]}
    run_sweep(parse_spec(spec), tmp_path, executor="serial", progress=False)
    code = LATE_IMPORTS.replace("SPEC", repr(spec))
    late = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, check=True
    ).stdout.split()
    libraries = {"pandas", "pyarrow.parquet", "pyarrow.pandas_compat", "scipy.stats"}
    assert not set(late) & {*libraries, "physbench.posterior.scoring"}


def test_the_tables_libraries_are_imported_while_the_cells_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.bench import runner

    imported = threading.Event()
    seen: list[bool] = []
    run_cell = runner.run_cell

    def waiting_cell(config: Any) -> dict[str, Any]:
        # a cell long enough for the import to happen meanwhile (at most 5 s)
        seen.append(imported.wait(timeout=5))
        return run_cell(config)

    monkeypatch.setattr(runner, "_import_tables", imported.set)
    monkeypatch.setattr(runner, "run_cell", waiting_cell)
    spec = parse_spec({**TINY, "seeds": 1, "estimators": ["random"]})
    res = run_sweep(spec, tmp_path, executor="serial", progress=False)
    assert res.ran == 2 and seen == [True, True]
