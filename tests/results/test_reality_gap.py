"""The committed physics-gap sweep (``results/reality_gap``, ``benchmarks/reality_gap.toml``):
observe with one engine, model with the other, every estimator. The sweep is a benchmark (about
3 minutes on 2 cores); these tests check that what is committed is the whole sweep the spec
describes and that the table docs/results.md quotes is generated from it."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "reality_gap"


@pytest.fixture(scope="module")
def results() -> pd.DataFrame:
    return pd.read_parquet(RESULTS / "results.parquet")


def test_every_estimator_engine_pair_and_seed_ran_without_failures(results) -> None:
    spec = tomllib.loads((ROOT / "benchmarks" / "reality_gap.toml").read_text())
    names = {e if isinstance(e, str) else e["name"] for e in spec["estimators"]}
    assert names == {"tpe", "cmaes", "optuna", "random", "resnet3d"}
    assert (results.status == "ok").all()
    last = results[results.iteration == spec["iterations"] - 1]
    counts = last.groupby(
        ["scene", "unknowns", "engine", "observe_engine", "estimator_name"]
    ).seed.nunique()
    rows = sum(len(s["unknowns"]) for s in spec["scenes"])
    assert len(counts) == rows * 4 * len(names)  # 2 model engines x 2 observing engines
    assert (counts == spec["seeds"]).all()


def test_committed_spec_is_the_benchmark_spec() -> None:
    assert (RESULTS / "spec.toml").read_text() == (
        ROOT / "benchmarks" / "reality_gap.toml"
    ).read_text()


def test_summary_lists_every_engine_pair() -> None:
    text = (RESULTS / "summary.md").read_text()
    for pair in ("| pymunk | box2d |", "| box2d | pymunk |", "| pymunk | pymunk |"):
        assert pair in text
