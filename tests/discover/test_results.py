"""Discovery's result types: the information criterion, the gains and the JSON of a candidate;
results cannot be changed once built (stages return new ones)."""

from __future__ import annotations

import dataclasses
import math

import pytest

from physbench.discover.results import CandidateResult, Finding, FitResult


def fit(ssr: float, n: int, free: int) -> FitResult:
    keys = [f"p{i}" for i in range(free)]
    return FitResult(dict.fromkeys(keys, 1.0), keys, {}, ssr, n, 10, 10, "converged")


def test_bic_is_n_log_mean_square_plus_k_log_n() -> None:
    f = fit(ssr=2.0, n=100, free=3)
    assert f.k == 3 and f.rms == pytest.approx(math.sqrt(0.02))
    assert f.bic() == pytest.approx(100 * math.log(0.02) + 3 * math.log(100))
    assert f.bic(extra_k=1) - f.bic() == pytest.approx(math.log(100))
    assert math.isfinite(fit(ssr=0.0, n=10, free=1).bic())  # a perfect fit stays finite
    assert math.isnan(fit(ssr=1.0, n=0, free=1).rms)


def test_a_candidates_json_writes_missing_numbers_as_null_and_results_are_frozen() -> None:
    c = CandidateResult(
        round=1, effect="drag_a", name="linear_drag", params={"c": 0.2}, stderr={"c": 0.01},
        fixed={}, heldout_error=math.inf, gain=0.4, gain_vs_base=0.4, criterion=-120.0,
        delta_criterion=math.nan, significant=True,
    )  # fmt: skip
    d = c.to_dict()
    assert d["heldout_error"] is None and d["delta_criterion"] is None and d["gain"] == 0.4
    assert list(d)[:3] == ["effect", "name", "round"] and d["quick_fit_only"] is False
    for result, field in ((c, "chosen"), (fit(1.0, 10, 1), "ssr")):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(result, field, 1)
    f = Finding("drift", "run1", "ball", "free", "slope", 0.3, suggests=("table_tilt",))
    assert math.isnan(f.stderr) and f.trend == "" and f.values == {}
