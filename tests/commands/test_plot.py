"""``physbench plot DIR``: the figures (Figs. 3, 4, 5 and the win rate) and the self-contained
report, and clear errors for bad counts, a missing or an empty table."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.runner import run_sweep, write_table
from physbench.bench.spec import parse_spec
from physbench.bench.tables import SCHEMA
from physbench.cli import main

PNG = b"\x89PNG\r\n\x1a\n"
#: What building the parser must not import (the work happens in ``main``).
PARSING_HEAVY = ("numpy", "pandas", "physbench.bench.runner", "matplotlib")


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
    assert capsys.readouterr().out.startswith("5 figures in ")
    names = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert names == [
        "convergence_three_circles.png",
        "landscape_three_circles.png",
        "time_to_accuracy_three_circles.png",
        "trajectories_three_circles_mass.png",
        "win_rate.png",
    ]
    for name in names:
        data = (tmp_path / "plots" / name).read_bytes()
        assert data.startswith(PNG) and len(data) < 200_000
    page = (tmp_path / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 5 and "<h2>Table 1 layout</h2>" in page
    assert "<h2>Time to accuracy</h2>" in page
    assert "(2.6 ± 0.9)e-03" in page and "Win rate" in page and 'src="http' not in page
    assert pd.read_csv(tmp_path / "win_rate.csv", index_col=0).shape == (2, 2)
    # the summaries are rebuilt from results.parquet alone, with the time-to-accuracy section
    (tmp_path / "summary.md").unlink()
    (tmp_path / "time_to_accuracy.csv").unlink()
    assert main(["plot", str(tmp_path), "--landscape-seeds", "0"]) == 0
    assert "## Time to accuracy" in (tmp_path / "summary.md").read_text()
    assert len(pd.read_csv(tmp_path / "time_to_accuracy.csv")) == 4  # 2 unknown sets x 2
    assert main(["plot", str(tmp_path / "missing")]) == 2
    assert "no results.parquet there" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--seeds", "0"], "argument --seeds: 0 is not a whole number >= 1"),
        (["--landscape-seeds=-1"], "argument --landscape-seeds: -1 is not a whole number in [0,"),
        (["--threshold", "0"], "argument --threshold: 0 is not a finite number > 0"),
        (["--threshold", "nan"], "argument --threshold: nan is not a finite number > 0"),
    ],
)
def test_bad_counts_are_refused_before_reading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["plot", str(tmp_path / "missing"), *argv])
    assert exit_.value.code == 2
    assert f"physbench plot: error: {message}" in capsys.readouterr().err


def test_a_given_threshold_replaces_the_papers_on_every_row(tmp_path: Path) -> None:
    spec = parse_spec(
        {
            "name": "t",
            "estimators": ["random"],
            "seeds": 3,
            "iterations": 3,
            "resolution": 16,
            # second_order mass+elasticity has no paper value: left out unless a threshold is given
            "scenes": [
                {"name": "three_circles", "unknowns": ["mass"]},
                {"name": "second_order", "unknowns": ["mass+elasticity"]},
            ],
        }
    )
    run_sweep(spec, tmp_path, executor="serial", progress=False)
    read = lambda: pd.read_csv(tmp_path / "time_to_accuracy.csv").set_index("unknowns")  # noqa: E731
    argv = ["plot", str(tmp_path), "--landscape-seeds", "0", "-q"]
    assert main(argv) == 0
    default = read()
    assert (
        default.loc["mass", "source"] == "paper NN" and default.loc["mass", "threshold"] == 2.6e-3
    )
    assert default.loc["mass+elasticity", "source"] != "given"
    assert pd.isna(default.loc["mass+elasticity", "threshold"])
    # any answer is at or below 1e9: every seed reaches it with the initial guess
    assert main([*argv, "--threshold", "1e9"]) == 0
    loose = read()
    assert (loose["threshold"] == 1e9).all() and (loose["source"] == "given").all()
    assert (loose["reached"] == 3).all() and (loose["median_simulations"] == 1).all()
    assert "at or below 1e+09" not in (tmp_path / "summary.md").read_text()
    assert "1.00e+09 (given)" in (tmp_path / "summary.md").read_text()
    assert "1.00e+09 (given)" in (tmp_path / "report.html").read_text()
    # and none reaches 1e-30
    assert main([*argv, "--threshold", "1e-30"]) == 0
    tight = read()
    assert (tight["reached"] == 0).all() and (tight["median_simulations"] == float("inf")).all()


def test_an_empty_table_says_to_run_the_sweep_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write_table(pd.DataFrame({c: pd.Series(dtype=t) for c, t in SCHEMA.items()}), tmp_path)
    assert main(["plot", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "the results table is empty; run `physbench bench SPEC --out" in err, err
    assert not (tmp_path / "plots").exists() and not (tmp_path / "report.html").exists()


def test_argument_parsing_imports_nothing_heavy(heavy_imports: Callable[..., list[str]]) -> None:
    then = "physbench.cli.build_parser('plot')"
    assert heavy_imports("physbench.cli", then=then, heavy=PARSING_HEAVY) == []


@pytest.mark.parametrize("command", ["plot", "compare"])
@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("not parquet", "results.parquet': not a Parquet table"),
        ("no columns", "results.parquet': not a sweep's results table: no column cell, "),
    ],
)
def test_a_table_that_is_not_a_sweeps_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, content: str, message: str
) -> None:
    # Issue 14: these were ArrowInvalid and KeyError tracebacks.
    table = tmp_path / "results.parquet"
    if content == "not parquet":
        table.write_text("t,body,x,y\n")
    else:
        pd.DataFrame({"x": [1.0]}).to_parquet(table)
    argv = [command, str(tmp_path)] + ([str(tmp_path)] if command == "compare" else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"physbench {command}: error: " in err and message in err, err
