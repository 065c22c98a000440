"""When a candidate is a cause (physbench/discover/significance.py)."""

from __future__ import annotations

import math

import pytest

from physbench.discover import CandidateResult, FitResult, Scored, Settings
from physbench.discover.significance import judge


def scored(heldout: float, ssr: float, k: int, n: int = 100) -> Scored:
    fit = FitResult({}, [f"p{i}" for i in range(k)], {}, ssr, n, 1, 1, "")
    return Scored("m", (), None, fit, heldout, 30)  # type: ignore[arg-type]  # no model needed


def candidate(heldout: float, criterion: float) -> CandidateResult:
    return CandidateResult(1, "e", "e", {}, {}, {}, heldout, 0.0, 0.0, criterion, 0.0, False)


def test_a_cause_must_gain_on_held_out_data_and_lower_the_bic():
    base, current = scored(2.0, 4.0, 3), scored(1.0, 1.0, 4)
    bic = 100 * math.log(1.0 / 100) + 4 * math.log(100)
    assert current.bic == pytest.approx(bic)
    c = judge(candidate(0.8, bic - 20), current, base, Settings())
    assert c.significant and c.note == "" and c.previous is current
    assert c.gain == pytest.approx(0.2) and c.gain_vs_base == pytest.approx(0.6)
    assert c.delta_criterion == pytest.approx(-20)

    small = judge(candidate(0.95, bic - 20), current, base, Settings())
    assert not small.significant and small.note == "held-out gain +5.0% < 10%"
    flat = judge(candidate(0.5, bic - 5), current, base, Settings())
    assert not flat.significant and flat.note == "ΔBIC -5.0 > -10"
    # the thresholds are settings
    assert judge(
        candidate(0.95, bic - 5), current, base, Settings(min_gain=0.04, min_delta_bic=4)
    ).significant


def test_judging_returns_a_new_result():
    c = candidate(0.8, -500.0)
    judged = judge(c, scored(1.0, 1.0, 4), scored(2.0, 4.0, 3), Settings())
    assert judged is not c and c.gain == 0.0 and c.previous is None
