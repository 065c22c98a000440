"""Intervals that allow for residuals correlated in time (physbench/discover/intervals.py)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from physbench.discover.data import DiscoverError
from physbench.discover.intervals import LEVEL, _ar1_apply, ar1_covariance, lag1


def _ar1(rng: np.random.Generator, n: int, rho: float) -> np.ndarray:
    e = rng.normal(0, 1, n)
    out = np.empty(n)
    out[0] = e[0] / np.sqrt(1 - rho**2)
    for i in range(1, n):
        out[i] = rho * out[i - 1] + e[i]
    return out


def _coverage(rho: float, trials: int = 400, n: int = 120) -> tuple[float, float]:
    """Coverage of the slope of a straight-line fit to AR(1) noise: the i.i.d. Jacobian interval
    and the AR(1) sandwich, over seeded trials."""
    rng = np.random.default_rng(7)
    t = np.linspace(0, 1, n)
    jac = np.column_stack([np.ones(n), t])
    iid = ar1 = 0
    for _ in range(trials):
        y = 0.3 * t + _ar1(rng, n, rho)
        beta, *_ = np.linalg.lstsq(jac, y, rcond=None)
        r = jac @ beta - y
        s2 = float(r @ r) / (n - 2)
        se = np.sqrt(s2 * np.linalg.inv(jac.T @ jac)[1, 1])
        iid += abs(beta[1] - 0.3) <= stats.t.ppf(0.5 + LEVEL / 2, n - 2) * se
        u = ar1_covariance(jac, r, np.zeros(n, dtype=int))
        ar1 += abs(beta[1] - 0.3) <= u.half_width()[1]
    return iid / trials, ar1 / trials


def test_ar1_intervals_cover_at_the_nominal_rate_where_iid_ones_do_not():
    iid, ar1 = _coverage(rho=0.7)
    assert iid < 0.65  # the i.i.d. interval is far too narrow
    assert 0.84 <= ar1 <= 0.96


def test_without_correlation_the_interval_is_about_the_iid_one():
    iid, ar1 = _coverage(rho=0.0)
    assert 0.85 <= iid <= 0.95 and 0.85 <= ar1 <= 0.96


def test_ar1_filter_is_the_correlation_matrix_product():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(30, 3))
    rho = 0.6
    i = np.arange(30)
    r = rho ** np.abs(i[:, None] - i[None, :])
    np.testing.assert_allclose(_ar1_apply(x, rho), r @ x, atol=1e-12)


def test_series_are_separate_and_a_negative_correlation_counts_as_none():
    rng = np.random.default_rng(2)
    a, b = _ar1(rng, 200, 0.9), rng.normal(size=200)
    assert lag1(a) > 0.6 and lag1(np.array([1.0, -1.0, 1.0, -1.0])) == 0.0
    jac = np.ones((400, 1))
    u = ar1_covariance(jac, np.r_[a, b], np.r_[np.zeros(200), np.ones(200)])
    assert u.rho[0] == lag1(a) and u.rho[1] == lag1(b) and u.rho[1] < 0.15
    # The correlated series counts for far fewer independent entries than the other.
    n_eff = [200 * (1 - r) / (1 + r) for r in u.rho]
    assert n_eff[0] < 50 < 150 < n_eff[1]
    assert u.dof == pytest.approx(sum(n_eff) - 1)


def test_mismatched_shapes_name_what_was_expected():
    with pytest.raises(DiscoverError, match=r"expected \(5, p\), \(5,\) and \(5,\)"):
        ar1_covariance(np.ones((5, 2)), np.ones(4), np.zeros(5))
