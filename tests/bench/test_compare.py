"""``physbench compare``: an unchanged run is not flagged, an injected regression is (exit 1)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from physbench.bench.compare import compare
from physbench.bench.runner import run_sweep, write_table
from physbench.bench.spec import parse_spec
from physbench.cli import main
from physbench.commands import compare as compare_cmd

SPEC = {
    "name": "cmp",
    "estimators": ["random", {"name": "optuna", "options": {"sampler": "random"}}],
    "seeds": 8,  # the one-sided signed-rank test needs >= 5 seeds to reach p < 0.05
    "iterations": 2,
    "resolution": 16,
    "scenes": [{"name": "three_circles", "unknowns": ["mass"]}],
}


@pytest.fixture(scope="module")
def baseline(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("baseline")
    run_sweep(parse_spec(SPEC), out, executor="serial", progress=False)
    return out


def _variant(baseline: Path, tmp_path: Path, change: str) -> Path:
    new = tmp_path / change
    shutil.copytree(baseline, new)
    df = pd.read_parquet(new / "results.parquet")
    sel = df["estimator"] == "random"
    if change == "regressed":  # every seed of one configuration 3x worse
        df.loc[sel, "best_nmse"] *= 3
    elif change == "one_seed":  # one seed much worse: real, but not significant on its own
        df.loc[sel & (df["seed"] == 0), "best_nmse"] *= 100
    elif change == "improved":
        df.loc[sel, "best_nmse"] /= 3
    elif change == "failing":
        last = df.index[sel & (df["seed"] == 3)]
        df.loc[last, "status"] = "failed"
    write_table(df, new)
    return new


def test_unchanged_run_is_not_flagged(
    baseline: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rerun = tmp_path / "rerun"
    run_sweep(parse_spec(SPEC), rerun, executor="serial", progress=False)  # a fresh run, not a copy
    assert main(["compare", str(rerun), str(baseline)]) == 0
    out = capsys.readouterr().out
    assert "compared 16 cells in 2 configurations: 2 identical" in out and "REGRESSION" not in out


def test_injected_regression_is_flagged(
    baseline: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    new = _variant(baseline, tmp_path, "regressed")
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


@pytest.mark.parametrize(
    ("change", "verdict"), [("one_seed", "ok"), ("improved", "better"), ("failing", "worse")]
)
def test_verdicts(baseline: Path, tmp_path: Path, change: str, verdict: str) -> None:
    new = pd.read_parquet(_variant(baseline, tmp_path, change) / "results.parquet")
    res = compare(new, pd.read_parquet(baseline / "results.parquet"))
    got = res.table.set_index("estimator")["verdict"].to_dict()
    assert got == {"random": verdict, "optuna(sampler=random)": "identical"}


def test_tolerance_and_errors(
    baseline: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = pd.read_parquet(baseline / "results.parquet")
    new = base.copy()
    new.loc[new["estimator"] == "random", "best_nmse"] *= 1.1  # consistent but below --min-ratio
    assert compare(new, base).worse.empty
    assert len(compare(new, base, min_ratio=1.05).worse) == 1
    other = base.copy()
    other["seed"] += 100
    with pytest.raises(Exception, match="no cell of the new sweep matches a baseline cell"):
        compare(other, base)
    assert main(["compare", str(tmp_path / "nothing"), str(baseline)]) == 2
    assert "no results.parquet there" in capsys.readouterr().err
    assert (compare_cmd.ALPHA, compare_cmd.MIN_RATIO) == (0.05, 1.25)
    from physbench.bench import compare as mod

    assert (mod.ALPHA, mod.MIN_RATIO) == (compare_cmd.ALPHA, compare_cmd.MIN_RATIO)
    assert np.isclose(compare(base, base).table["gm_ratio"], 1).all()


def test_holm() -> None:
    from physbench.bench.compare import holm

    assert np.allclose(holm([0.01, 0.04, 0.03, 0.5]), [0.04, 0.09, 0.09, 0.5])
    assert np.allclose(holm([1.0]), [1.0])


def test_a_table_without_renderer_columns_matches_the_default_renderer(
    baseline: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old = tmp_path / "old"
    old.mkdir()
    base = pd.read_parquet(baseline / "results.parquet")
    write_table(base.drop(columns=["renderer", "renderer_name", "renderer_options"]), old)
    assert main(["compare", str(baseline), str(old)]) == 0
    assert "compared 16 cells in 2 configurations: 2 identical" in capsys.readouterr().out
    assert main(["compare", str(old), str(baseline)]) == 0
    assert "2 identical" in capsys.readouterr().out
    # another renderer's cells are other configurations: nothing matches
    other = base.assign(renderer="blocks", renderer_name="blocks")
    with pytest.raises(Exception, match="no cell of the new sweep matches a baseline cell"):
        compare(other, base.drop(columns=["renderer", "renderer_name", "renderer_options"]))
