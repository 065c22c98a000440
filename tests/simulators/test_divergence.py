"""Measuring how two simulations of one scene diverge: outcomes, comparisons, the yardstick."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import UnknownNameError
from physbench.simulators.divergence import (
    MOVED,
    ORDER_MARGIN,
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
