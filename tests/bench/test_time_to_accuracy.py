"""Time to accuracy from a hand-made long table with known crossings and timings: simulations count
the initial guess, seconds add the estimator's start and stop at the crossing's render, unreached
seeds are censored, rows without a paper value need a threshold, and sweeps without timings or
with one iteration still give a table, a summary section, a report section and a figure."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from physbench.bench import time_to_accuracy as tta
from physbench.bench.summary import write_summary
from physbench.bench.tables import to_frame
from physbench.errors import PhysbenchError

#: per-iteration timings of every hand-made cell: simulate, render, propose; and start()
T_SIM, T_REN, T_EST, T_START = 0.1, 0.01, 1.0, 5.0


def _cell(
    index: int,
    seed: int,
    best: list[float],
    *,
    scene: str = "three_circles",
    estimator: str = "A",
    timed: bool = True,
) -> list[dict[str, Any]]:
    """The long-table rows of one finished cell whose best-so-far normalized MSE is ``best``."""
    base = {
        "cell": f"{scene}-{estimator}-{seed}",
        "cell_index": index,
        "scene": scene,
        "unknowns": "mass",
        "bodies": "all",
        "estimator": estimator,
        "options": "{}",
        "engine": "pymunk",
        "observe_engine": "pymunk",
        "renderer": "pygame",
        "renderer_name": "pygame",
        "renderer_options": "{}",
        "observer": "sharp",
        "observer_options": "{}",
        "blur": 0.0,
        "noise": 0.0,
        "resolution": 16,
        "render_mode": "mark",
        "iterations": len(best),
        "seed": seed,
        "status": "ok",
        "t_start": T_START if timed else None,
    }
    return [
        {
            **base,
            "iteration": k,
            "nmse": v,
            "best_iteration": k,
            "best_nmse": v,
            **({"t_simulate": T_SIM, "t_render": T_REN, "t_estimator": T_EST} if timed else {}),
        }
        for k, v in enumerate(best)
    ]


PAPER_NN = 2.6e-3  # three circles, mass


@pytest.fixture
def table() -> Any:
    """Estimator A on three circles (mass): seed 0 crosses at iteration 1 and rises again, seed 1
    at the initial guess (equal counts), seed 2 never; estimator B: one seed in three crosses."""
    rows = [
        *_cell(0, 0, [1e-2, 2e-3, 5e-3]),
        *_cell(1, 1, [PAPER_NN, 1e-3, 1e-3]),
        *_cell(2, 2, [1.0, 1.0, 1.0]),
        *_cell(3, 0, [1e-2, 1e-2, 1e-3], estimator="B"),
        *_cell(4, 1, [1.0, 1.0, 1.0], estimator="B"),
        *_cell(5, 2, [1.0, 1.0, 1.0], estimator="B"),
    ]
    return to_frame(rows)


def test_each_seed_costs_its_first_crossing(table: Any) -> None:
    seeds = tta.per_seed(table)
    a = seeds[seeds["estimator"] == "A"].set_index("seed")
    assert a["threshold"].tolist() == [PAPER_NN] * 3
    assert a.loc[0, "simulations"] == 2  # the initial guess, then the crossing
    # start, all of iteration 0, iteration 1's simulate and render (not its proposal)
    assert a.loc[0, "seconds"] == pytest.approx(T_START + T_SIM + T_REN + T_EST + T_SIM + T_REN)
    assert a.loc[1, "simulations"] == 1
    assert a.loc[1, "seconds"] == pytest.approx(T_START + T_SIM + T_REN)
    assert a.loc[2, "simulations"] == math.inf and a.loc[2, "seconds"] == math.inf


def test_the_medians_are_censored_by_unreached_seeds(table: Any) -> None:
    t = tta.table(table).set_index("estimator")
    assert t.loc["A", "source"] == "paper NN"
    assert (t.loc["A", "seeds"], t.loc["A", "reached"]) == (3, 2)
    assert t.loc["A", "share"] == pytest.approx(2 / 3)
    assert t.loc["A", "median_simulations"] == 2  # of 1, 2 and never
    assert t.loc["A", "median_seconds"] == pytest.approx(T_START + 2 * T_SIM + 2 * T_REN + T_EST)
    # B: one seed of three reached (at 3 simulations), so its median is beyond the budget
    assert (t.loc["B", "reached"], t.loc["B", "median_simulations"]) == (1, math.inf)
    shown = tta.formatted(tta.table(table)).set_index("estimator")
    assert shown.loc["A", "reached"] == "2/3" and shown.loc["A", "simulations"] == "2"
    assert shown.loc["A", "seconds"] == "6.22 s"
    assert shown.loc["B", "simulations"] == "> 3"
    assert shown.loc["B", "seconds"] == "median seed did not reach it"


def test_exactly_half_of_an_even_count_is_no_median() -> None:
    df = to_frame([*_cell(0, 0, [1e-3, 1e-3]), *_cell(1, 1, [1.0, 1.0])])
    (row,) = tta.table(df).to_dict("records")
    assert row["share"] == 0.5 and row["median_simulations"] == math.inf


def test_a_given_threshold_replaces_the_papers(table: Any) -> None:
    t = tta.table(table, threshold=1.5e-3).set_index("estimator")
    assert t.loc["A", "source"] == "given" and t.loc["A", "threshold"] == 1.5e-3
    assert t.loc["A", "reached"] == 1 and t.loc["B", "reached"] == 1  # A seed 1, B seed 0


def test_a_row_without_a_paper_value_needs_a_threshold() -> None:
    df = to_frame(_cell(0, 0, [1e-2, 1e-4], scene="custom"))
    (row,) = tta.table(df).to_dict("records")
    assert math.isnan(row["threshold"]) and math.isnan(row["median_simulations"])
    assert row["source"] == "no paper NN value for this row; pass a threshold"
    assert tta.per_seed(df).empty
    assert tta.formatted(tta.table(df))["note"].tolist() == [row["source"]]
    (given,) = tta.table(df, threshold=1e-3).to_dict("records")
    assert given["median_simulations"] == 2 and given["reached"] == 1


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_a_bad_threshold_is_refused(table: Any, bad: float) -> None:
    with pytest.raises(PhysbenchError, match="expected a finite normalized MSE > 0"):
        tta.table(table, threshold=bad)


def test_no_timings_or_one_iteration_do_not_crash(tmp_path: Path) -> None:
    untimed = to_frame([*_cell(0, 0, [1e-2, 1e-3], timed=False), *_cell(1, 1, [1e-3])])
    seeds = tta.per_seed(untimed).set_index("seed")
    assert seeds["simulations"].tolist() == [2, 1]
    assert math.isnan(seeds.loc[0, "seconds"])  # reached, but nothing timed
    assert seeds.loc[1, "seconds"] == pytest.approx(T_START + T_SIM + T_REN)
    write_summary(untimed, tmp_path, title="untimed")
    assert "## Time to accuracy" in (tmp_path / "summary.md").read_text()


def test_the_summary_writes_the_table_and_a_section(table: Any, tmp_path: Path) -> None:
    import pandas as pd

    write_summary(table, tmp_path, title="t")
    csv = pd.read_csv(tmp_path / "time_to_accuracy.csv")
    assert csv["reached"].tolist() == [2, 1]
    md = (tmp_path / "summary.md").read_text()
    assert "## Time to accuracy" in md and "| three_circles | mass | A | 2.60e-03 (paper NN)" in md


def test_the_report_has_a_time_to_accuracy_section(table: Any, tmp_path: Path) -> None:
    from physbench.bench.report import build

    page = build(table, tmp_path, {}, title="t").read_text()
    assert "<h2>Time to accuracy</h2>" in page and "6.22 s" in page


def test_the_figure_draws_share_reached_against_simulations_and_seconds(
    table: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("matplotlib")
    from physbench.bench import plots

    drawn: dict[str, Any] = {}
    save = plots._save

    def keep(fig: Any, path: Path) -> Path:
        drawn[path.name] = fig
        return save(fig, path)

    monkeypatch.setattr(plots, "_save", keep)
    paths = plots.time_to_accuracy(table, tmp_path)
    assert [p.name for p in paths] == ["time_to_accuracy_three_circles.png"]
    top, bottom = drawn[paths[0].name].axes
    assert top.get_xlabel() == "simulations (1: the initial guess)"
    assert bottom.get_xlabel() == "wall-clock time (s)" and bottom.get_xscale() == "log"
    assert [line.get_label() for line in top.lines] == ["A", "B"]
    # A: a third of the seeds at 1 simulation, two thirds from 2 on, up to the budget
    x, y = top.lines[0].get_data()
    assert list(x) == [0, 1, 2, 3] and np.allclose(y, [0, 1 / 3, 2 / 3, 2 / 3])
    xs, ys = bottom.lines[0].get_data()
    first, second = T_START + T_SIM + T_REN, T_START + 2 * T_SIM + 2 * T_REN + T_EST
    assert np.allclose(xs[1:3], [first, second]) and np.allclose(ys, [0, 1 / 3, 2 / 3, 2 / 3])
    assert top.lines[0].get_color() == bottom.lines[0].get_color() != top.lines[1].get_color()
    assert "threshold 0.0026" in top.get_title()


def test_no_figure_where_no_row_has_a_threshold(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    from physbench.bench import plots

    df = to_frame(_cell(0, 0, [1e-2, 1e-4], scene="custom"))
    assert plots.time_to_accuracy(df, tmp_path) == []
