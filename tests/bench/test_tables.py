"""The long table's schema: tables written before the renderer and observer columns existed (the
committed ones among them) read with the default renderer, the sharp observer and no options."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.runner import read_table, run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import ADDED, CONFIG, MATCH, SCHEMA, stats, upgrade, without_timings
from physbench.render.base import DEFAULT_RENDERER

RESULTS = Path(__file__).resolve().parents[2] / "results"
OLD = ["renderer", "renderer_name", "renderer_options", "observer", "observer_options"]


@pytest.mark.parametrize("name", ["baseline", "table1", "resnet3d"])
def test_committed_tables_read_with_the_default_renderer(name: str) -> None:
    raw = pd.read_parquet(RESULTS / name / "results.parquet")
    assert not set(OLD) & set(raw.columns)  # written before the renderer columns
    df = read_table(RESULTS / name)
    assert list(df.columns) == list(SCHEMA)
    assert (df["renderer"] == DEFAULT_RENDERER).all()
    assert (df["renderer_name"] == DEFAULT_RENDERER).all()
    assert (df["renderer_options"] == "{}").all()
    assert (df["observer"] == "sharp").all()
    assert (df["observer_options"] == "{}").all()
    pd.testing.assert_frame_equal(df.drop(columns=OLD), raw[df.drop(columns=OLD).columns])
    assert {"renderer", "renderer_options", "observer", "observer_options"} <= set(CONFIG)
    assert set(CONFIG) <= set(MATCH)


def test_an_old_table_equals_a_new_one_but_for_its_renderer_columns(tmp_path: Path) -> None:
    spec = parse_spec(
        {
            "name": "t",
            "estimators": ["random"],
            "seeds": 2,
            "iterations": 2,
            "resolution": 16,
            "scenes": ["three_circles"],
        }
    )
    new = without_timings(run_sweep(spec, tmp_path, executor="serial", progress=False).table)
    old = new.drop(columns=OLD)
    assert upgrade(new) is new
    pd.testing.assert_frame_equal(upgrade(old), new, check_exact=True)
    assert set(ADDED) == set(OLD)
    pd.testing.assert_frame_equal(stats(old), stats(new))
