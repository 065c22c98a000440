"""Posterior: summaries from samples, the not-determined statement, JSON round trip, checks."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.posterior.samples import Posterior


def _post(samples: np.ndarray, **kw: object) -> Posterior:
    return Posterior(("a.mass", "a.elasticity"), samples, (2.0, 0.0), (8.0, 1.0), "test", **kw)


def test_median_and_intervals_are_the_sample_quantiles() -> None:
    rng = np.random.default_rng(0)
    s = np.column_stack([rng.normal(5, 0.1, 20_000), rng.uniform(0, 1, 20_000)])
    p = _post(s)
    assert p.median()["a.mass"] == pytest.approx(5.0, abs=0.005)
    lo, hi = p.interval(0.9)["a.mass"]
    assert (lo, hi) == pytest.approx((5 - 0.1645, 5 + 0.1645), abs=0.005)
    lo, hi = p.interval(0.5)["a.elasticity"]
    assert (lo, hi) == pytest.approx((0.25, 0.75), abs=0.01)


def test_an_unknown_as_wide_as_its_prior_is_not_determined() -> None:
    rng = np.random.default_rng(1)
    s = np.column_stack([rng.normal(5, 0.1, 1000), rng.uniform(0, 1, 1000)])
    p = _post(s)
    assert p.undetermined() == ("a.elasticity",)
    ratio = p.width_ratio()
    assert ratio["a.mass"] < 0.1 and 0.9 < ratio["a.elasticity"] < 1.1
    text = "\n".join(p.describe({"a.mass": 5.02, "a.elasticity": 0.3}))
    assert "a.elasticity" in text and "not determined" in text
    assert "truth 5.02 (inside the 90 %)" in text


def test_json_round_trip_keeps_summaries_and_thins_samples() -> None:
    rng = np.random.default_rng(2)
    p = _post(
        np.column_stack([rng.normal(5, 0.1, 3000), rng.uniform(0, 1, 3000)]),
        complete=False,
        note="ran out",
    )
    d = p.to_dict(max_samples=500)
    assert d["n"] == 3000 and len(d["samples"]) == 500 and d["complete"] is False
    q = Posterior.from_dict(d)
    assert q.keys == p.keys and q.note == "ran out" and not q.complete
    assert q.median()["a.mass"] == pytest.approx(p.median()["a.mass"], abs=0.01)


@pytest.mark.parametrize(
    "samples",
    [np.zeros((10, 3)), np.zeros((1, 2)), np.full((4, 2), np.nan), np.zeros(5)],
)
def test_bad_samples_are_refused(samples: np.ndarray) -> None:
    with pytest.raises(PhysbenchError, match="posterior samples"):
        _post(samples)


def test_interval_level_outside_0_1_is_refused() -> None:
    with pytest.raises(PhysbenchError, match=r"expected a number in \(0, 1\)"):
        _post(np.zeros((4, 2))).interval(1.5)
