"""The sweep figures: win rates count ties as half, the landscape is zero at the nominal value and
draws with the table's renderer, and tables from before renderer columns plot (``physbench plot``
itself: tests/commands/test_plot.py)."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import numpy as np
import pandas as pd
import pytest

from physbench.bench.plots import landscape, landscape_data, plot_all
from physbench.bench.runner import run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import final_rows, win_rate_table
from physbench.render.base import DEFAULT_RENDERER


def test_win_rate_counts_ties_as_half() -> None:
    rows = []
    for seed, (a, b) in enumerate([(1.0, 2.0), (3.0, 2.0), (1.0, 1.0)]):
        for est, v in (("A", a), ("B", b)):
            rows.append(
                {
                    "cell_index": seed,
                    "scene": "s",
                    "unknowns": "mass",
                    "bodies": "all",
                    "engine": "e",
                    "observe_engine": "e",
                    "blur": 0.0,
                    "noise": 0.0,
                    "resolution": 8,
                    "render_mode": "mark",
                    "iterations": 1,
                    "estimator": est,
                    "options": "{}",
                    "seed": seed,
                    "status": "ok",
                    "iteration": 0,
                    "best_nmse": v,
                }
            )
    rate, n = win_rate_table(final_rows(pd.DataFrame(rows)))
    assert rate.loc["A", "B"] == pytest.approx(1.5 / 3) and rate.loc["B", "A"] == pytest.approx(
        1.5 / 3
    )
    assert n.loc["A", "B"] == 3


def test_landscape_is_zero_at_the_nominal_value() -> None:
    data = landscape_data("three_circles", "mass", resolution=16, seeds=[0], points=5)
    x = data.pop("x")
    assert list(data) == ["a.mass", "b.mass"] and x[2] == 0
    for y in data.values():
        assert y[0, 2] == 0 and (y[0, [0, 4]] > 0).all()


def test_landscape_draws_with_the_tables_renderer(tmp_path: Path, blocks: ModuleType) -> None:
    base = landscape_data("three_circles", "mass", resolution=16, seeds=[0], points=3)
    assert blocks.CALLS == 0
    data = landscape_data(
        "three_circles",
        "mass",
        renderer="blocks",
        renderer_options={"gain": 0.5},
        resolution=16,
        seeds=[0],
        points=3,
    )
    assert blocks.CALLS == 1 + 2 * 3  # the nominal view, then each key at each point
    assert data["a.mass"][0, 1] == 0 and not np.allclose(data["a.mass"], base["a.mass"])

    spec = parse_spec(
        {
            "name": "ren",
            "estimators": ["random"],
            "seeds": 1,
            "iterations": 2,
            "resolution": 16,
            "renderer": [DEFAULT_RENDERER, {"name": "blocks", "options": {"gain": 0.5}}],
            "scenes": [{"name": "three_circles", "unknowns": ["mass"]}],
        }
    )
    df = run_sweep(spec, tmp_path, executor="serial", progress=False).table
    blocks.CALLS = 0
    paths = landscape(df, tmp_path, seeds=1, points=3)
    assert [p.name for p in paths] == [
        f"landscape_three_circles_renderer{DEFAULT_RENDERER}.png",
        "landscape_three_circles_rendererblocks-gain-0.5-.png",
    ]
    assert blocks.CALLS == 1 + 2 * 3  # only the blocks figure used it


def test_a_table_without_renderer_columns_plots(tmp_path: Path) -> None:
    spec = parse_spec(
        {
            "name": "old",
            "estimators": ["random", "optuna"],
            "seeds": 2,
            "iterations": 2,
            "resolution": 16,
            "scenes": [{"name": "three_circles", "unknowns": ["mass"]}],
        }
    )
    df = run_sweep(spec, tmp_path, executor="serial", progress=False).table
    old = df.drop(columns=["renderer", "renderer_name", "renderer_options"])
    figures = plot_all(old, tmp_path / "plots", seeds=1, landscape_seeds=1)
    assert [p.name for p in figures["landscape"]] == ["landscape_three_circles.png"]
    assert all(figures.values()), figures
