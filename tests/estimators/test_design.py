"""Start-up designs: a Latin hypercube puts one point in each of ``n`` equal slices of every
coordinate; random draws need not; both are seeded and inside the unit cube."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.estimators.design import startup_design


def slices_hit(points: np.ndarray) -> list[int]:
    """Per coordinate, how many of the ``n`` equal slices of [0, 1] hold a point."""
    n = len(points)
    return [len(set(np.floor(points[:, j] * n).astype(int))) for j in range(points.shape[1])]


@pytest.mark.parametrize(("n", "dim"), [(1, 1), (6, 2), (10, 4)])
def test_a_latin_hypercube_has_one_point_per_slice_of_every_coordinate(n: int, dim: int) -> None:
    pts = startup_design("lhs", n, dim, np.random.default_rng(3))
    assert pts.shape == (n, dim)
    assert ((pts >= 0) & (pts < 1)).all()
    assert slices_hit(pts) == [n] * dim


def test_random_draws_are_not_stratified() -> None:
    # Over 20 seeds, 10 uniform draws in 2-D leave some slice empty almost every time.
    misses = [
        slices_hit(startup_design("random", 10, 2, np.random.default_rng(s))) != [10, 10]
        for s in range(20)
    ]
    assert sum(misses) >= 18


def test_same_seed_same_design_and_none_when_no_points() -> None:
    a = startup_design("lhs", 5, 3, np.random.default_rng(7))
    b = startup_design("lhs", 5, 3, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    assert startup_design("lhs", 0, 3, np.random.default_rng(7)).shape == (0, 3)
