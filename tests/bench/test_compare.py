"""The sweep comparison: verdicts per configuration (worse, better, ok, identical), the
``min_ratio`` tolerance, Holm's correction, and cells matched across tables with and without
renderer columns (``physbench compare`` itself: tests/commands/test_compare.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from physbench.bench.compare import compare, holm

RENDERER_COLUMNS = ["renderer", "renderer_name", "renderer_options"]


@pytest.mark.parametrize(
    ("change", "verdict"), [("one_seed", "ok"), ("improved", "better"), ("failing", "worse")]
)
def test_verdicts(compare_sweep: Any, tmp_path: Path, change: str, verdict: str) -> None:
    new = pd.read_parquet(compare_sweep.variant(tmp_path, change) / "results.parquet")
    res = compare(new, pd.read_parquet(compare_sweep.baseline / "results.parquet"))
    got = res.table.set_index("estimator")["verdict"].to_dict()
    assert got == {"random": verdict, "optuna(sampler=random)": "identical"}


def test_tolerance_and_errors(compare_sweep: Any) -> None:
    base = pd.read_parquet(compare_sweep.baseline / "results.parquet")
    new = base.copy()
    new.loc[new["estimator"] == "random", "best_nmse"] *= 1.1  # consistent but below --min-ratio
    assert compare(new, base).worse.empty
    assert len(compare(new, base, min_ratio=1.05).worse) == 1
    other = base.copy()
    other["seed"] += 100
    with pytest.raises(Exception, match="no cell of the new sweep matches a baseline cell"):
        compare(other, base)
    assert np.isclose(compare(base, base).table["gm_ratio"], 1).all()


def test_holm() -> None:
    assert np.allclose(holm([0.01, 0.04, 0.03, 0.5]), [0.04, 0.09, 0.09, 0.5])
    assert np.allclose(holm([1.0]), [1.0])


def test_another_renderers_cells_match_no_cell_of_a_table_without_renderer_columns(
    compare_sweep: Any,
) -> None:
    base = pd.read_parquet(compare_sweep.baseline / "results.parquet")
    other = base.assign(renderer="blocks", renderer_name="blocks")
    with pytest.raises(Exception, match="no cell of the new sweep matches a baseline cell"):
        compare(other, base.drop(columns=RENDERER_COLUMNS))
