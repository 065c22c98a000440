"""The long table's schema: tables written before the renderer and observer columns existed (the
committed ones among them) read with the default renderer, the sharp observer and no options. And
the summaries' bootstrap intervals: BCa, seeded, and a point where BCa is undefined."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from physbench.bench.runner import read_table, run_sweep
from physbench.bench.spec import parse_spec
from physbench.bench.tables import (
    ADDED,
    CONFIG,
    MATCH,
    SCHEMA,
    bootstrap_ci,
    ratio_ci,
    stats,
    upgrade,
    without_timings,
)
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


def test_bootstrap_interval_is_scipys_bca_and_seeded() -> None:
    v = np.random.default_rng(3).lognormal(sigma=1.0, size=20)  # heavy-tailed, as the errors are
    lo, hi = bootstrap_ci(v)
    assert bootstrap_ci(v) == (lo, hi)
    assert lo < v.mean() < hi
    bca = sps.bootstrap(
        (v,), np.mean, n_resamples=4000, confidence_level=0.95, method="BCa", rng=0
    ).confidence_interval
    assert (lo, hi) == pytest.approx((bca.low, bca.high), rel=1e-12)
    # The mean of a right-skewed sample: BCa reaches further up than down.
    assert hi - v.mean() > v.mean() - lo
    assert bootstrap_ci(v, seed=1) != (lo, hi)


def test_bootstrap_interval_where_bca_is_undefined() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no DegenerateDataWarning, no division warnings
        assert bootstrap_ci([5.0]) == (5.0, 5.0)
        assert bootstrap_ci([0.25] * 20) == (0.25, 0.25)
        assert np.isnan(bootstrap_ci([])).all()


def test_ratio_ci_is_a_paired_bca_bootstrap_of_the_ratio_of_means() -> None:
    rng = np.random.default_rng(1)
    den = rng.lognormal(size=30)
    num = den * rng.lognormal(sigma=0.5, size=30)
    point, lo, hi = ratio_ci(num, den)
    assert lo < point < hi and point == pytest.approx(num.mean() / den.mean())
    assert ratio_ci(num, den) == (point, lo, hi)  # seeded
    bca = sps.bootstrap(
        (num, den),
        lambda a, b, axis=-1: a.mean(axis=axis) / b.mean(axis=axis),
        paired=True,
        vectorized=True,
        n_resamples=4000,
        confidence_level=0.9,
        method="BCa",
        rng=0,
    ).confidence_interval
    assert (lo, hi) == pytest.approx((bca.low, bca.high), rel=1e-12)
    # Pairing: with the pairs shuffled apart, the seeds' shared spread widens the interval.
    _, lo_apart, hi_apart = ratio_ci(num, rng.permutation(den))
    assert hi - lo < 0.7 * (hi_apart - lo_apart)  # measured 0.37 against 0.72
    # Fewer seeds, wider interval.
    lo10, hi10 = ratio_ci(num[:10], den[:10])[1:]
    assert hi10 - lo10 > hi - lo


def test_ratio_ci_where_bca_is_undefined() -> None:
    den = np.random.default_rng(1).lognormal(size=30)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert ratio_ci(2 * den, den) == (2.0, 2.0, 2.0)  # pairing cancels all the spread
        assert ratio_ci([3.0], [2.0]) == (1.5, 1.5, 1.5)
