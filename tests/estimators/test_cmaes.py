"""``cmaes``: CMA-ES through nevergrad works on the real pipeline, starts at the initial guess,
handles one unknown, imports nevergrad lazily and refuses bad options clearly."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.estimators.cmaes import CMAES
from physbench.estimators.options import EstimatorOptionError
from physbench.plugins import get_registry
from physbench.testing import run_toy


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


def test_first_point_told_is_the_initial_guess() -> None:
    h = run_toy(CMAES, {}, seed=2, iterations=3)
    assert h.iterations[0].params == h.initial
    assert h.iterations[1].params != h.initial  # a new point is asked, not the initial one again


def test_handles_a_single_unknown() -> None:
    h = run_toy(CMAES, {}, seed=0, iterations=6, bodies=("a",))
    assert h.keys == ("a.mass",) and len({r.params["a.mass"] for r in h.iterations}) == 6


def test_bad_options_name_the_option_and_the_accepted_values() -> None:
    with pytest.raises(
        EstimatorOptionError, match=r"cmaes: sigma = 2.0: expected a number in \(0, 1\]"
    ):
        CMAES(sigma=2.0)
