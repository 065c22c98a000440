"""Calibration of posteriors against truths: exact posteriors cover at the nominal rates and give
uniform ranks, over-confident ones are caught, and each per-run score means what it says."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import gaussian_kde

from physbench.errors import PhysbenchError
from physbench.posterior.samples import Posterior
from physbench.posterior.scoring import LEVELS, Coverage, Score, coverage, score, summarize


def _post(samples: np.ndarray, low: float = -10.0, high: float = 10.0) -> Posterior:
    return Posterior(("a.mass",), np.asarray(samples).reshape(-1, 1), (low,), (high,), "test")


def _gaussian_runs(runs: int, spread: float, seed: int) -> list[Score]:
    """Runs whose posterior is N(m, spread) while the truth is drawn from N(m, 1): exact for
    ``spread`` 1."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(runs):
        m = rng.uniform(-3, 3)
        truth = m + rng.standard_normal()
        post = _post(m + spread * rng.standard_normal(2000))
        out.append(score(post, {"a.mass": truth})["a.mass"])
    return out


def test_exact_gaussian_posteriors_cover_at_the_nominal_rates() -> None:
    scores = _gaussian_runs(400, 1.0, seed=0)
    for c in coverage(scores):
        lo, hi = c.ci(0.99)  # four levels: 95 % intervals would miss one by chance too often
        assert c.n == 400 and lo <= c.level <= hi, (c, lo, hi)
    summary = summarize(scores)
    assert summary["sbc_p"] > 0.05
    assert summary["coverage90"] == pytest.approx(0.9, abs=0.04)
    assert summary["scored"] == 400
    # a 90 % interval of N(m, 1) is 3.29 wide, of a range 20 wide
    assert summary["width90"] == pytest.approx(3.29 / 20, rel=0.03)


def test_a_too_narrow_posterior_is_flagged() -> None:
    summary = summarize(_gaussian_runs(400, 1 / 3, seed=0))
    assert summary["coverage90"] < 0.5 and summary["coverage50"] < 0.25
    assert summary["sbc_p"] < 1e-6
    # its mean negative log density is worse than the exact posterior's
    assert summary["nld"] > summarize(_gaussian_runs(400, 1.0, seed=0))["nld"] + 0.5


def test_rank_is_the_share_of_samples_below_the_truth() -> None:
    post = _post(np.arange(100.0) / 10 - 5)  # -5.0 ... 4.9
    assert score(post, {"a.mass": -6.0})["a.mass"].rank == 0.0
    assert score(post, {"a.mass": 6.0})["a.mass"].rank == 1.0
    assert score(post, {"a.mass": -2.45})["a.mass"].rank == pytest.approx(0.26)
    assert score(post, {"a.mass": -2.5})["a.mass"].rank == pytest.approx(0.255)  # a tie: half


def test_intervals_contain_the_truth_by_level() -> None:
    rng = np.random.default_rng(1)
    post = _post(rng.standard_normal(20_000))
    # 1.5 sigma: outside the 50 % and 80 % intervals (0.67, 1.28), inside 90 % and 95 %
    s = score(post, {"a.mass": 1.5})["a.mass"]
    assert s.inside == (False, False, True, True)
    assert Score.from_dict(s.to_dict()) == s
    assert list(s.to_dict())[: len(LEVELS)] == ["in50", "in80", "in90", "in95"]


def test_negative_log_density_is_in_unit_range_units() -> None:
    rng = np.random.default_rng(2)
    flat = _post(rng.uniform(0, 10, 4000), 0.0, 10.0)
    # as likely as under the uniform prior, at the ends too (the estimate is reflected there)
    for t in (0.1, 5.0, 9.9):
        assert score(flat, {"a.mass": t})["a.mass"].nld == pytest.approx(0.0, abs=0.15)
    narrow = _post(rng.normal(5.0, 0.5, 4000), 0.0, 10.0)  # sd 0.05 of the range
    # far from the ends: scipy's Gaussian KDE of the unit-range samples
    kde = gaussian_kde(narrow.samples[:, 0] / 10.0)
    assert score(narrow, {"a.mass": 5.5})["a.mass"].nld == pytest.approx(
        -kde.logpdf(0.55)[0], rel=1e-9
    )
    assert score(narrow, {"a.mass": 5.0})["a.mass"].nld == pytest.approx(
        math.log(0.05 * math.sqrt(2 * math.pi)), abs=0.1
    )


def test_equal_samples_give_a_finite_density() -> None:
    point = _post(np.full(50, 3.0), 0.0, 10.0)
    s = score(point, {"a.mass": 3.0})["a.mass"]
    assert s.width90 == 0.0 and s.inside == (True,) * len(LEVELS)
    assert s.nld == pytest.approx(math.log(1e-3 * math.sqrt(2 * math.pi)))
    far = score(point, {"a.mass": 4.0})["a.mass"]  # 100 floor widths away
    assert math.isfinite(far.nld) and far.nld > 1000 and far.inside == (False,) * len(LEVELS)


def test_a_truth_without_a_key_is_refused() -> None:
    with pytest.raises(PhysbenchError, match=r"truth lacks a\.mass"):
        score(_post(np.zeros(3)), {"b.mass": 1.0})


def test_coverage_interval_is_clopper_pearson() -> None:
    c = Coverage(0.9, 9, 10)
    assert c.observed == 0.9
    lo, hi = c.ci()
    assert (lo, hi) == pytest.approx((0.5550, 0.9975), abs=1e-4)
    assert all(math.isnan(v) for v in (*Coverage(0.9, 0, 0).ci(), Coverage(0.9, 0, 0).observed))
    empty = summarize([])
    assert empty["scored"] == 0 and math.isnan(empty["sbc_p"]) and math.isnan(empty["nld"])
