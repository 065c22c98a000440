"""Profile-likelihood intervals of the named causes (physbench/discover/profile.py)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from physbench.discover import Settings
from physbench.discover.profile import profile_interval, threshold
from physbench.discover.results import FitResult


def _fit(**kw) -> FitResult:
    base = dict(
        values={"e.c": 1.0},
        free=["e.c"],
        stderr={"e.c": 0.1},
        ssr=2.0,
        n=21,
        nfev=1,
        simulations=1,
        status="",
        half_widths={"e.c": 0.3},
    )
    return FitResult(**{**base, **kw})


def test_the_threshold_is_the_rise_a_linear_model_reaches_at_the_sandwich_end():
    # s² = 2/20 = 0.1; a linear model's sum of squares rises by s² (d / stderr)² at distance d.
    assert threshold(_fit(), "e.c") == pytest.approx(0.1 * (0.3 / 0.1) ** 2)
    assert threshold(_fit(stderr={"e.c": float("nan")}), "e.c") is None
    assert threshold(_fit(half_widths={}), "e.c") is None


def test_in_a_smooth_scene_the_profile_agrees_with_the_sandwich(drag_discovery):
    c = drag_discovery.cause_results[0]
    assert c.scored is not None
    sandwich = c.scored.fit.intervals["linear_drag.c"]
    low, high = profile_interval(c.scored, "linear_drag.c", Settings())
    assert c.intervals["c"] == (low, high)
    for got, want in ((low, sandwich[0]), (high, sandwich[1])):
        assert got == pytest.approx(want, abs=0.25 * (sandwich[1] - sandwich[0]))


def test_a_fit_without_a_usable_standard_error_keeps_no_profile(drag_discovery):
    c = drag_discovery.cause_results[0]
    assert c.scored is not None
    broken = replace(c.scored, fit=replace(c.scored.fit, half_widths={}))
    assert profile_interval(broken, "linear_drag.c", Settings()) is None
