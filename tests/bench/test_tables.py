"""The long table's schema: tables written before the renderer and observer columns existed read
with the default renderer, the sharp observer and no options. And
the summaries' bootstrap intervals: BCa, seeded, and a point where BCa is undefined. And the
calibration of posteriors: a column and summary columns only where some estimator returned one."""

from __future__ import annotations

import json
import math
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
    final_rows,
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
    df = read_table(RESULTS / name)
    assert list(df.columns) == list(SCHEMA)
    assert (df["renderer"] == DEFAULT_RENDERER).all()
    assert (df["renderer_name"] == DEFAULT_RENDERER).all()
    assert (df["renderer_options"] == "{}").all()
    assert (df["observer"] == "sharp").all()
    assert (df["observer_options"] == "{}").all()
    # Tables written before the renderer columns gain them on reading; the rest are read as written.
    kept = [c for c in df.columns if c in raw.columns]
    assert set(df.columns) - set(kept) <= set(OLD)
    pd.testing.assert_frame_equal(df[kept], raw[kept])
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


CALIBRATION_STATS = [
    "coverage50",
    "coverage80",
    "coverage90",
    "coverage95",
    "sbc_p",
    "width90",
    "nld",
    "scored",
]


def test_cells_with_a_posterior_record_its_scores_against_the_truth(calibrated_sweep) -> None:
    from physbench.bench.store import CellStore
    from physbench.posterior.samples import Posterior
    from physbench.posterior.scoring import score

    from .conftest import SMC

    df = calibrated_sweep.table
    assert list(df.columns) == [*SCHEMA, "calibration"]
    fin = final_rows(df)
    assert (fin["status"] == "ok").all()
    smc, rnd = fin[fin["estimator"] == SMC], fin[fin["estimator"] == "random"]
    assert len(smc) == 3 and rnd["calibration"].isna().all()
    store = CellStore(calibrated_sweep.out)
    for row in smc.to_dict("records"):
        hist = store.load(row["cell"])["history"]
        want = score(Posterior.from_dict(hist["posterior"]), hist["truth"])
        got = json.loads(row["calibration"])
        assert list(got) == ["a.elasticity", "b.elasticity"]
        assert got == {k: s.to_dict() for k, s in want.items()}
        assert set(got["a.elasticity"]) == {
            "in50", "in80", "in90", "in95", "rank", "width90", "nld"
        }  # fmt: skip
    # every row of a cell carries it, like the truth
    assert df.loc[df["estimator"] == SMC, "calibration"].notna().all()


def test_stats_gain_calibration_columns_for_configurations_with_posteriors(
    calibrated_sweep,
) -> None:
    from .conftest import SMC

    df = calibrated_sweep.table
    full = stats(df)
    before = stats(df.drop(columns="calibration"))
    assert list(full.columns) == [*before.columns, *CALIBRATION_STATS]
    pd.testing.assert_frame_equal(full[before.columns], before)
    st = full.set_index("estimator")
    smc, rnd = st.loc[SMC], st.loc["random"]
    assert smc["scored"] == 6  # 3 seeds x 2 unknowns
    covs = [smc[f"coverage{n}"] for n in (50, 80, 90, 95)]
    assert all(0 <= c <= 1 for c in covs) and covs == sorted(covs)  # nested intervals
    assert 0 < smc["sbc_p"] <= 1 and 0 < smc["width90"] < 1 and math.isfinite(smc["nld"])
    assert rnd["scored"] == 0 and all(math.isnan(rnd[c]) for c in CALIBRATION_STATS[:-1])


def test_the_summary_has_a_calibration_section_for_posteriors_only(
    calibrated_sweep, tmp_path: Path
) -> None:
    from physbench.bench.summary import write_summary

    from .conftest import SMC

    write_summary(calibrated_sweep.table, tmp_path, title="t")
    md = (tmp_path / "summary.md").read_text()
    section = md.split("## Calibration\n", 1)[1].split("\n## ", 1)[0]
    assert "| 50 % | 80 % | 90 % | 95 % | SBC p | 90 % width | NLD |" in section
    assert f"| {SMC} | 6 |" in section and "random" not in section
    assert "coverage90" in (tmp_path / "stats.csv").read_text().splitlines()[0]


def test_a_sweep_without_posteriors_keeps_the_tables_it_had(
    calibrated_sweep, tmp_path: Path
) -> None:
    """Only the random cells: no calibration column, no calibration in stats or the summary,
    so such a sweep writes the files it wrote before posteriors existed."""
    from physbench.bench.runner import assemble
    from physbench.bench.store import CellStore
    from physbench.bench.summary import write_summary

    cells = [c for c in calibrated_sweep.spec.cells() if c.label == "random"]
    df = assemble(cells, CellStore(calibrated_sweep.out))
    assert list(df.columns) == list(SCHEMA)
    st = write_summary(df, tmp_path, title="t")
    assert not set(CALIBRATION_STATS) & set(st.columns)
    assert "Calibration" not in (tmp_path / "summary.md").read_text()
