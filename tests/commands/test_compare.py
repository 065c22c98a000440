"""``physbench compare``: an unchanged run is not flagged, an injected regression is (exit 1), bad
input exits 2, a table from before renderer columns matches the default renderer, and the defaults
are the library's."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from physbench.bench.runner import run_sweep, write_table
from physbench.bench.spec import parse_spec
from physbench.cli import main
from physbench.commands import compare as compare_cmd

#: What building the parser must not import (the work happens in ``main``).
PARSING_HEAVY = ("numpy", "pandas", "physbench.bench.runner", "matplotlib")


def test_unchanged_run_is_not_flagged(
    compare_sweep: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rerun = tmp_path / "rerun"
    # a fresh run, not a copy
    run_sweep(parse_spec(compare_sweep.spec), rerun, executor="serial", progress=False)
    assert main(["compare", str(rerun), str(compare_sweep.baseline)]) == 0
    out = capsys.readouterr().out
    assert "compared 16 cells in 2 configurations: 2 identical" in out and "REGRESSION" not in out


def test_injected_regression_is_flagged(
    compare_sweep: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    baseline = compare_sweep.baseline
    new = compare_sweep.variant(tmp_path, "regressed")
    assert main(["compare", str(new), str(baseline)]) == 1
    out = capsys.readouterr().out
    assert (
        "REGRESSION: random on three_circles [mass]" in out
        and "optuna" not in out.split("REGRESSION")[1]
    )
    row = next(
        line for line in out.splitlines() if line.startswith("| three_circles | mass | random")
    )
    assert (
        "| 3.000 |" in row and "| 0.00391 | 0.00781 | worse |" in row
    )  # gm ratio 3, p = 2^-8, Holm x2
    # the reverse direction is an improvement, which passes
    assert main(["compare", str(baseline), str(new)]) == 0
    assert "1 better, 1 identical" in capsys.readouterr().out


def test_a_missing_table_exits_2(
    compare_sweep: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["compare", str(tmp_path / "nothing"), str(compare_sweep.baseline)]) == 2
    assert "no results.parquet there" in capsys.readouterr().err


def test_defaults_are_the_librarys() -> None:
    from physbench.bench import compare as mod

    assert (compare_cmd.ALPHA, compare_cmd.MIN_RATIO) == (0.05, 1.25)
    assert (mod.ALPHA, mod.MIN_RATIO) == (compare_cmd.ALPHA, compare_cmd.MIN_RATIO)


def test_a_table_without_renderer_columns_matches_the_default_renderer(
    compare_sweep: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    baseline = compare_sweep.baseline
    old = tmp_path / "old"
    old.mkdir()
    base = pd.read_parquet(baseline / "results.parquet")
    write_table(base.drop(columns=["renderer", "renderer_name", "renderer_options"]), old)
    assert main(["compare", str(baseline), str(old)]) == 0
    assert "compared 16 cells in 2 configurations: 2 identical" in capsys.readouterr().out
    assert main(["compare", str(old), str(baseline)]) == 0
    assert "2 identical" in capsys.readouterr().out


def test_argument_parsing_imports_nothing_heavy(heavy_imports: Callable[..., list[str]]) -> None:
    then = "physbench.cli.build_parser('compare')"
    assert heavy_imports("physbench.cli", then=then, heavy=PARSING_HEAVY) == []
