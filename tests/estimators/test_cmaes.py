"""``cmaes``: CMA-ES through nevergrad works on the real pipeline, starts from the best point of a
Latin hypercube (at the initial guess on request), handles one unknown, imports nevergrad lazily
and refuses bad options clearly."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.estimators.cmaes import CMAES, DEFAULT_POPSIZE, DEFAULT_STARTUP
from physbench.estimators.options import EstimatorOptionError
from physbench.plugins import get_registry
from physbench.testing import run_toy
from physbench.testing.toy import toy_task


def test_registered_through_entry_points() -> None:
    assert get_registry().info("estimator", "cmaes").package == "physbench"


def test_reduces_the_normalized_error_on_three_circles_mass(
    three_circles: Callable[..., Any],
) -> None:
    runs = [three_circles("cmaes", seed, ["mass"]) for seed in range(5)]
    initial = np.mean([h.initial_nmse for h in runs])
    final = np.mean([h.best_nmse for h in runs])
    # 11 iterations, best by image MSE; measured ratios are 0.08 (random) to 0.3 (cmaes).
    assert final < 0.5 * initial, (final, initial)
    assert all(len(h) == 11 for h in runs)


def test_importing_the_module_does_not_import_nevergrad(
    heavy_imports: Callable[..., list[str]],
) -> None:
    assert heavy_imports("physbench.estimators.cmaes") == []


def unit_points(h: Any) -> np.ndarray:
    space = toy_task().space
    return np.array([space.to_unit(r.params) for r in h.iterations])


def test_first_point_told_is_the_initial_guess() -> None:
    for options in ({}, {"startup": 0}):
        h = run_toy(CMAES, options, seed=2, iterations=3)
        assert h.iterations[0].params == h.initial
        assert h.iterations[1].params != h.initial  # a new point is asked, not the guess again


def test_cma_starts_at_the_best_point_of_a_latin_hypercube() -> None:
    assert CMAES().options == {
        "sigma": 0.3,
        "popsize": DEFAULT_POPSIZE,
        "elitist": False,
        "startup": DEFAULT_STARTUP,
        "design": "lhs",
    }
    n = DEFAULT_STARTUP - 1
    h = run_toy(CMAES, {"sigma": 0.01}, seed=4, iterations=DEFAULT_STARTUP + 3)
    pts = unit_points(h)
    design = pts[1:DEFAULT_STARTUP]
    assert [len(set(np.floor(design[:, j] * n).astype(int))) for j in range(pts.shape[1])] == [
        n
    ] * pts.shape[1]
    losses = [r.loss for r in h.iterations[:DEFAULT_STARTUP]]
    best = pts[int(np.argmin(losses))]
    # With a 1 % step, every CMA proposal lies next to the design's best point.
    assert np.abs(pts[DEFAULT_STARTUP:] - best).max() < 0.05, (pts, best)


def test_the_previous_defaults_start_cma_at_the_initial_guess() -> None:
    h = run_toy(CMAES, {"startup": 0, "popsize": "auto", "sigma": 0.01}, seed=4, iterations=6)
    pts = unit_points(h)
    assert np.abs(pts[1:] - pts[0]).max() < 0.05
    assert h.options["popsize"] is None


def test_handles_a_single_unknown() -> None:
    h = run_toy(CMAES, {}, seed=0, iterations=6, bodies=("a",))
    assert h.keys == ("a.mass",) and len({r.params["a.mass"] for r in h.iterations}) == 6


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"sigma": 2.0}, r"cmaes: sigma = 2.0: expected a number in \(0, 1\]"),
        ({"popsize": 1}, r'cmaes: popsize = 1: expected a whole number >= 2 or "auto"'),
        ({"popsize": "big"}, r"cmaes: popsize = 'big': expected a whole number >= 2 or \"auto\""),
        ({"startup": -2}, r"cmaes: startup = -2: expected a whole number >= 0"),
        ({"design": "grid"}, r"cmaes: design = 'grid': expected one of lhs, random"),
    ],
)
def test_bad_options_name_the_option_and_the_accepted_values(
    options: dict[str, Any], message: str
) -> None:
    with pytest.raises(EstimatorOptionError, match=message):
        CMAES(**options)
