"""``physbench plot DIR``: the figures (Figs. 3, 4, 5 and the win rate) and the self-contained report."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.plots import landscape_data
from physbench.bench.runner import run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import final_rows, win_rate_table
from physbench.cli import main

PNG = b"\x89PNG\r\n\x1a\n"


def test_plot_command_writes_figures_and_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = parse_spec(
        {
            "name": "plots",
            "estimators": ["random", "optuna"],
            "seeds": 2,
            "iterations": 3,
            "resolution": 16,
            "scenes": [{"name": "three_circles", "unknowns": ["mass", "mass+elasticity"]}],
        }
    )
    run_sweep(spec, tmp_path, executor="serial", progress=False)
    assert main(["plot", str(tmp_path), "--landscape-seeds", "1"]) == 0
    assert capsys.readouterr().out.startswith("4 figures in ")
    names = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert names == [
        "convergence_three_circles.png",
        "landscape_three_circles.png",
        "trajectories_three_circles_mass.png",
        "win_rate.png",
    ]
    for name in names:
        data = (tmp_path / "plots" / name).read_bytes()
        assert data.startswith(PNG) and len(data) < 200_000
    page = (tmp_path / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 4 and "<h2>Table 1 layout</h2>" in page
    assert "(2.6 ± 0.9)e-03" in page and "Win rate" in page and 'src="http' not in page
    assert pd.read_csv(tmp_path / "win_rate.csv", index_col=0).shape == (2, 2)
    assert main(["plot", str(tmp_path / "missing")]) == 2
    assert "no results.parquet there" in capsys.readouterr().err


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
