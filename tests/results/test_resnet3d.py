"""The committed held-out evaluation of ``resnet3d`` (``results/resnet3d``) and the claims drawn
from it.

The sweep itself (``physbench bench benchmarks/resnet3d.toml``, minutes on 2 cores) is a benchmark,
not a test; these tests check that the committed table is generated from the committed results and
that the claims docs/results.md makes about them hold.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.resnet3d_table import table
from physbench.bench.tables import PAPER

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "resnet3d"


@pytest.fixture(scope="module")
def results() -> pd.DataFrame:
    return pd.read_parquet(RESULTS / "results.parquet")


def _resnet3d_after_11(
    results: pd.DataFrame, scene: str, params: frozenset[str], blur: float
) -> pd.DataFrame:
    """The learned estimator's rows after 11 iterations for one Table 1 row (all bodies unknown)."""
    return results[
        (results.estimator_name == "resnet3d")
        & (results.scene == scene)
        & (results.bodies == "all")
        & (results.blur == blur)
        & (results.iteration == 10)
        & (results.unknowns.map(lambda u: frozenset(u.split("+"))) == params)
    ]


def test_committed_table_is_generated_from_the_committed_results() -> None:
    expected = table(RESULTS) + "\n"
    assert (RESULTS / "table.md").read_text() == expected, (
        "results/resnet3d/table.md is stale: python benchmarks/resnet3d_table.py results/resnet3d "
        "> results/resnet3d/table.md"
    )


def test_every_table1_row_ran_on_at_least_ten_held_out_seeds_without_failures(
    results: pd.DataFrame,
) -> None:
    assert (results.status == "ok").all()
    for scene, params in PAPER:
        for blur in (0.0, 3.0):
            rows = _resnet3d_after_11(results, scene, params, blur)
            assert rows.seed.nunique() >= 10, (scene, sorted(params), blur)
            # Training scene seeds start at 2**24 and validation at 2**30: these are held out.
            assert rows.seed.max() < 2**24


@pytest.mark.parametrize(
    "row",
    sorted(PAPER, key=lambda r: (r[0], sorted(r[1]))),
    ids=lambda r: f"{r[0]}-{'+'.join(sorted(r[1]))}",
)
def test_resnet3d_is_at_or_below_the_papers_nn_after_11_iterations(
    results: pd.DataFrame, row: tuple
) -> None:
    sel = _resnet3d_after_11(results, *row, 0.0)
    assert len(sel) and sel.best_nmse.mean() <= PAPER[row]["NN"][0]


def test_resnet3d_beats_every_gradient_free_estimator_on_every_table1_row(
    results: pd.DataFrame,
) -> None:
    at11 = results[(results.iteration == 10) & (results.blur == 0) & (results.bodies == "all")]
    means = at11.groupby(["scene", "unknowns", "estimator_name"]).best_nmse.mean().unstack()
    assert {"tpe", "cmaes", "optuna"} <= set(means.columns)
    others = means.drop(columns="resnet3d")
    assert (means["resnet3d"] < others.min(axis=1)).all(), means
