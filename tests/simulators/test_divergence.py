"""Measuring how two simulations of one scene diverge: outcomes, comparisons, the yardstick."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import UnknownNameError
from physbench.simulators.divergence import (
    MOVED,
    ORDER_MARGIN,
    Comparison,
    Outcome,
    compare,
    paper_scene,
    same_outcome,
    sensitivity,
)


def test_same_outcome_needs_the_same_bodies_moved_and_the_same_order():
    base = Outcome(travel={"a": 1.0, "b": 0.0}, final_x={"a": 2.0, "b": 1.0})
    assert same_outcome(base, base) and base.moved == {"a"}
    stayed = Outcome(travel={"a": MOVED / 4, "b": 0.0}, final_x={"a": 2.0, "b": 1.0})
    assert not same_outcome(base, stayed)
    unclear = Outcome(travel={"a": 0.75 * MOVED, "b": 0.0}, final_x={"a": 2.0, "b": 1.0})
    assert same_outcome(base, unclear)  # between half and all of MOVED: too close to call
    swapped = Outcome(travel={"a": 1.0, "b": 0.0}, final_x={"a": 0.5, "b": 1.0})
    assert not same_outcome(base, swapped)
    close = Outcome(travel={"a": 1.0, "b": 0.0}, final_x={"a": 1.0 - ORDER_MARGIN / 2, "b": 1.0})
    assert same_outcome(base, close)  # opposite order, but within ORDER_MARGIN


def test_an_engine_against_itself_does_not_diverge():
    c = sensitivity("three_circles", 0, "pymunk", shift=0.0)
    assert c is not None and c.same
    np.testing.assert_array_equal(c.final_diff, 0.0)
    moved = sensitivity("three_circles", 0, "pymunk", shift=1e-3)
    assert moved is not None and moved.path_diff[0] >= 1e-3 - 1e-12  # the moved body, at t = 0


def test_compare_times_both_engines_and_refuses_unknown_ones():
    c = compare("second_order", 1)
    assert c is not None and c.scene == "second_order" and c.seed == 1
    assert set(c.seconds) == {"pymunk", "box2d"} and c.final_diff.shape == c.path_diff.shape
    assert paper_scene("no_such_scene", 0) is None and compare("no_such_scene", 0) is None
    with pytest.raises(UnknownNameError, match="'bullet'"):
        sensitivity("three_circles", 0, "bullet")


# ------------------------------------------------------------- the paper scenes in both engines

#: Per scene, limits on the final-position difference per body between engines (m) over seeds
#: 0-9: (mean, max). About 2x the mean and 1.4x the max measured by
#: benchmarks/engine_divergence.py (docs/engines.md). Before the step-order and skin fixes
#: three_circles measured mean 0.025, max 0.055 and failed them (and one stacked_boxes seed's
#: outcome differed).
PAPER_LIMITS = {
    "three_circles": (0.02, 0.04),
    "second_order": (0.035, 0.11),
    "stacked_boxes": (0.09, 0.5),
    "bouncing_balls": (0.15, 0.3),
}


#: Seeds (of 10) allowed a different qualitative outcome: only the chaotic pool table, where a 1 mm
#: shift of the start already changes one seed's outcome within Box2D.
ALLOWED_MISSES = {"bouncing_balls": 1}


def _paper_rows(name: str, **kwargs: float) -> list[Comparison]:
    rows = [c for seed in range(10) if (c := compare(name, seed, **kwargs)) is not None]
    if not rows:
        pytest.skip(f"scene {name} not available")
    return rows


@pytest.mark.parametrize("name", sorted(PAPER_LIMITS))
def test_paper_scenes_agree_between_engines(name: str) -> None:
    """Same parameters, both engines: same bodies move and no two bodies swap sides, and final
    positions within the measured divergence."""
    rows = _paper_rows(name)
    misses = [c.seed for c in rows if not c.same]
    assert len(misses) <= ALLOWED_MISSES.get(name, 0), misses
    final = np.concatenate([c.final_diff for c in rows])
    mean_limit, max_limit = PAPER_LIMITS[name]
    assert final.mean() <= mean_limit
    assert final.max() <= max_limit


def test_second_order_agrees_closely_once_the_velocity_threshold_matches() -> None:
    """second_order is not chaotic (1 mm at the start moves the end < 1 cm); with Box2D's 1 m/s
    restitution threshold mimicked in pymunk the engines agree to 0.3 cm mean, 1.8 cm max
    (measured), so anything systematic (step order, skin, mixing) shows here."""
    rows = _paper_rows("second_order", velocity_threshold=1.0)
    assert all(c.same for c in rows)
    final = np.concatenate([c.final_diff for c in rows])
    assert final.mean() <= 0.008
    assert final.max() <= 0.03
