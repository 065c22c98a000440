"""The committed held-out study of ``gp`` at the paper's budget (``results/gp_small_budget``,
made by ``physbench bench benchmarks/gp_small_budget.toml``, about 10 minutes on one shared core):
the figures docs/results.md states, read back from the table. Issue 29 item 3 asked for a mean of
at most 5e-3 on three_circles mass after 11 iterations over at least 200 held-out seeds, with a
BCa interval."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.tables import bootstrap_ci, ratio_ci

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "results" / "gp_small_budget"


@pytest.fixture(scope="module")
def final() -> pd.DataFrame:
    d = pd.read_parquet(FOLDER / "results.parquet")
    d = d[d.iteration == d.iteration.max()]
    return d.pivot_table(index="seed", columns="estimator", values="best_nmse")


def test_every_estimator_ran_the_same_300_held_out_seeds(final: pd.DataFrame) -> None:
    # 600..899: none is among the seeds any estimator's defaults were chosen on (gp: 1000..1199,
    # tpe and cmaes: 100..399)
    assert list(final.index) == list(range(600, 900))
    assert set(final.columns) == {"gp", "optuna", "tpe", "cmaes", "random"}
    assert not final.isna().any().any()


def test_gp_mean_is_below_5e_3_with_its_bca_interval(final: pd.DataFrame) -> None:
    gp = final["gp"].to_numpy()
    lo, hi = bootstrap_ci(gp, level=0.95)
    assert gp.mean() <= 5e-3
    assert round(gp.mean(), 5) == 0.00285
    assert (round(lo, 5), round(hi, 5)) == (0.00186, 0.0057)
    # the interval's upper end is above 5e-3: the target is met by the mean, not by the interval
    assert lo < 5e-3 < hi
    # the sweep's own statistics say the same
    stats = pd.read_csv(FOLDER / "stats.csv").set_index("estimator")
    assert stats.loc["gp", "n"] == 300
    assert (stats.loc["gp", "ci_low"], stats.loc["gp", "ci_high"]) == pytest.approx((lo, hi))


def test_gp_is_below_the_others_paired_on_the_same_seeds(final: pd.DataFrame) -> None:
    means = final.mean()
    assert means.idxmin() == "gp"
    assert [round(means[e], 4) for e in ("optuna", "cmaes", "tpe", "random")] == [
        0.0075,
        0.0117,
        0.0154,
        0.0167,
    ]
    point, lo, hi = ratio_ci(final["gp"], final["optuna"], level=0.95)
    assert round(point, 2) == 0.38 and (round(lo, 2), round(hi, 2)) == (0.25, 0.70)
    assert hi < 1  # lower than optuna's, significantly; half of it is inside the interval
    for other in ("cmaes", "tpe", "random"):
        assert ratio_ci(final["gp"], final[other], level=0.95)[2] < 0.55, other
    assert (final["gp"] < final["optuna"]).sum() == 242
    assert final["gp"].median() < final["optuna"].median() / 10  # 3.2e-4 against 4.1e-3
    assert final["gp"].mean() < 1.1e-2 / 2  # below half the paper's Hyperopt (1.1e-2)


def test_one_seed_holds_a_quarter_of_gps_error(final: pd.DataFrame) -> None:
    # seed 629: the start-up points all fell on the plateau of b's mass (gp.py's docstring)
    gp = final["gp"]
    assert gp.idxmax() == 629 and round(gp.max(), 3) == 0.215
    assert 0.24 < gp[629] / gp.sum() < 0.26
    assert gp.drop(629).max() < 0.07


def test_a_latin_hypercube_start_up_did_not_change_the_mean_on_tuning_seeds() -> None:
    # results/gp_tuning (benchmarks/gp_tuning.toml): why gp.py keeps Optuna's own draws
    d = pd.read_parquet(ROOT / "results" / "gp_tuning" / "results.parquet")
    d = d[d.iteration == d.iteration.max()]
    w = d.pivot_table(index="seed", columns="estimator", values="best_nmse")
    assert list(w.index) == list(range(1000, 1200)) and set(w.columns) == {"gp", "gp lhs 5"}
    point, lo, hi = ratio_ci(w["gp lhs 5"], w["gp"], level=0.95)
    assert round(point, 2) == 0.96 and (round(lo, 2), round(hi, 2)) == (0.57, 1.69)
    assert round(w["gp"].max(), 3) == 0.036  # no tuning seed fails as 629 does
