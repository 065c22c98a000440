"""The sweep figures: win rates count ties as half, the landscape is zero at the nominal value and
draws with the table's renderer, and tables from before renderer columns plot (``physbench plot``
itself: tests/commands/test_plot.py). Every axis says its unit, legends lie outside the axes, titles
name the engine and blur, and iterations are numbered as in the long table."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pandas as pd
import pytest

from physbench.bench.plots import landscape, landscape_data, plot_all
from physbench.bench.runner import read_table, run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import final_rows, stats, win_rate_table
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
    assert figures.pop("coverage") == []  # no estimator here returns a posterior
    assert all(figures.values()), figures


@pytest.fixture(scope="module")
def figures(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Every figure ``plot_all`` draws for a two-estimator sweep (3 iterations, blur 0.5 px),
    by file name, kept for inspection."""
    from physbench.bench import plots

    out = tmp_path_factory.mktemp("sweep")
    spec = parse_spec(
        {
            "name": "figs",
            "estimators": ["random", "tpe"],
            "seeds": 2,
            "iterations": 3,
            "resolution": 16,
            "blur": 0.5,
            "scenes": [{"name": "three_circles", "unknowns": ["mass", "elasticity"]}],
        }
    )
    df = run_sweep(spec, out, executor="serial", progress=False).table
    drawn: dict[str, Any] = {}
    save = plots._save

    def keep(fig: Any, path: Path) -> Path:
        drawn[path.name] = fig
        return save(fig, path)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plots, "_save", keep)
        plot_all(df, out / "plots", seeds=2, landscape_seeds=1)
    return drawn


def _legend_outside_the_axes(fig: Any) -> bool:
    """One figure legend, overlapping no axes (and no per-axes legend)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)  # the figure was closed when saved
    canvas.draw()
    renderer = canvas.get_renderer()
    (legend,) = fig.legends
    box = legend.get_window_extent(renderer)
    return all(ax.get_legend() is None for ax in fig.axes) and not any(
        box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes
    )


def test_the_convergence_figure_says_what_it_plots_with_units(figures: dict[str, Any]) -> None:
    fig = figures["convergence_three_circles.png"]
    mass, _ = fig.axes
    assert mass.get_ylabel() == "normalized MSE (dimensionless)"
    assert mass.get_xlabel() == "iteration (0: initial guess)"
    # iterations as numbered in the long table: 0 (the initial guess) to 2
    assert all(line.get_xdata().tolist() == [0, 1, 2] for line in mass.lines[:2])
    title = fig.get_suptitle()
    assert "engine pymunk" in title and "blur 0.5 px" in title
    assert "best-so-far iterate by image MSE" in title
    assert _legend_outside_the_axes(fig)


def test_trajectory_axes_carry_the_unknowns_units(figures: dict[str, Any]) -> None:
    fig = figures["trajectories_three_circles_mass.png"]
    tpe_or_random = fig.axes
    assert [ax.get_xlabel() for ax in tpe_or_random] == ["a.mass (kg)"] * 2
    assert tpe_or_random[0].get_ylabel() == "b.mass (kg)"
    assert "engine pymunk" in fig.get_suptitle() and "blur 0.5 px" in fig.get_suptitle()
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["seed 0", "seed 1"]
    assert _legend_outside_the_axes(fig)


def test_the_landscape_axes_carry_units_and_its_legend_names_bodies(
    figures: dict[str, Any],
) -> None:
    fig = figures["landscape_three_circles.png"]
    mass, elasticity = fig.axes
    assert mass.get_xlabel() == "Δmass from nominal (kg)"
    assert elasticity.get_xlabel() == "Δelasticity from nominal (dimensionless)"
    assert mass.get_ylabel() == "image MSE vs nominal (pixel value²)"
    assert "engine pymunk" in fig.get_suptitle()
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["body a", "body b"]
    assert _legend_outside_the_axes(fig)


def test_the_win_rate_colour_bar_is_labelled(figures: dict[str, Any]) -> None:
    fig = figures["win_rate.png"]
    heat = fig.axes[0]
    assert heat.images[0].colorbar.ax.get_ylabel() == "share won by the row (ties: half)"
    assert heat.get_ylabel() == "estimator (row)" and heat.get_xlabel() == "opponent (column)"


def test_the_coverage_figure_draws_posteriors_against_the_diagonal(
    calibrated_sweep, tmp_path: Path
) -> None:
    from physbench.bench import plots
    from physbench.posterior.scoring import LEVELS

    from .conftest import SMC

    drawn: dict[str, Any] = {}
    save = plots._save

    def keep(fig: Any, path: Path) -> Path:
        drawn[path.name] = fig
        return save(fig, path)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plots, "_save", keep)
        paths = plots.coverage(calibrated_sweep.table, tmp_path)
    assert [p.name for p in paths] == ["coverage_three_circles.png"] and paths[0].is_file()
    fig = drawn["coverage_three_circles.png"]
    (ax,) = fig.axes
    assert ax.get_xlabel() == "nominal coverage of the central interval (dimensionless)"
    assert ax.get_ylabel() == "observed coverage (dimensionless)"
    diagonal, line = ax.lines[0], ax.lines[1]
    assert diagonal.get_xdata().tolist() == [0, 1] == diagonal.get_ydata().tolist()
    # one line, for smc only (random has no posterior): its points are the table's coverages
    assert len(ax.containers) == 1
    row = stats(calibrated_sweep.table).set_index("estimator").loc[SMC]
    assert line.get_xdata() == pytest.approx(LEVELS)
    assert line.get_ydata().tolist() == [row[f"coverage{n}"] for n in (50, 80, 90, 95)]
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["calibrated", f"{SMC}, Elasticity (n=6)"]
    assert "engine pymunk" in fig.get_suptitle() and "Clopper-Pearson" in fig.get_suptitle()
    assert _legend_outside_the_axes(fig)


def test_no_coverage_figure_without_posteriors(calibrated_sweep, tmp_path: Path) -> None:
    from physbench.bench import plots

    df = calibrated_sweep.table
    assert plots.coverage(df[df["estimator"] == "random"], tmp_path) == []
    old = read_table(Path(__file__).resolve().parents[2] / "results" / "baseline")
    assert plots.coverage(old, tmp_path) == []
    assert not list(tmp_path.iterdir())


# ---------------------------------------------- issue 28: no text is cut at the figure's edge


@pytest.fixture(scope="module")
def committed_figures(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """Every figure ``plot_all`` draws for a slice of the committed resnet3d sweep: long
    estimator labels (``resnet3d(threads=1)``), the paper's two reference lines, 4 of its seeds
    (more than the 3 trajectories draw), three unknown sets of three_circles side by side."""
    from physbench.bench import plots

    df = read_table(Path(__file__).resolve().parents[2] / "results" / "resnet3d")
    df = df[
        df["scene"].isin(["three_circles", "bouncing_balls"])
        & (df["blur"] == 0)
        & (df["bodies"] == "all")
        & (df["seed"] < 4)
    ]
    drawn: dict[str, Any] = {}
    save = plots._save

    def keep(fig: Any, path: Path) -> Path:
        drawn[path.name] = fig
        return save(fig, path)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plots, "_save", keep)
        # no landscape: it simulates (the `figures` sweep draws one, checked too)
        plot_all(df, tmp_path_factory.mktemp("committed"), seeds=3, landscape_seeds=0)
    return drawn


def test_no_text_of_a_sweep_figure_lies_outside_it(
    figures: dict[str, Any], committed_figures: dict[str, Any], texts_outside: Any
) -> None:
    kinds = {name.split("_")[0] for name in {**figures, **committed_figures}}
    assert kinds == {"convergence", "trajectories", "landscape", "win", "time"}, kinds
    for name, fig in {**figures, **committed_figures}.items():
        assert texts_outside(fig) == [], name
    legend = committed_figures["convergence_three_circles.png"].legends[0]
    labels = [t.get_text() for t in legend.get_texts()]
    assert "resnet3d(threads=1)" in labels and "paper Hyperopt (11 it.)" in labels


def test_the_coverage_figure_fits_too(calibrated_sweep, tmp_path: Path, texts_outside) -> None:
    from physbench.bench import plots

    drawn: list[Any] = []
    save = plots._save

    def keep(fig: Any, path: Path) -> Path:
        drawn.append(fig)
        return save(fig, path)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(plots, "_save", keep)
        assert plots.coverage(calibrated_sweep.table, tmp_path)
    assert [texts_outside(fig) for fig in drawn] == [[]]


def test_the_trajectories_say_how_many_seeds_they_draw(committed_figures: dict[str, Any]) -> None:
    title = committed_figures["trajectories_three_circles_mass.png"].get_suptitle()
    assert "the first 3 of 4 seeds (physbench plot --seeds N)" in title.replace("\n", " ")
    legend = committed_figures["trajectories_three_circles_mass.png"].legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["seed 0", "seed 1", "seed 2"]
