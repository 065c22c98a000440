"""``random``: uniform random search works on the real pipeline, covers the range whatever the
loss, and imports nothing heavy."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from physbench.estimators.random_search import RandomSearch
from physbench.plugins import get_registry
from physbench.testing import run_toy


def test_registered_through_entry_points() -> None:
    assert get_registry().info("estimator", "random").package == "physbench"


def test_reduces_the_normalized_error_on_three_circles_mass(
    three_circles: Callable[..., Any],
) -> None:
    runs = [three_circles("random", seed, ["mass"]) for seed in range(5)]
    initial = np.mean([h.initial_nmse for h in runs])
    final = np.mean([h.best_nmse for h in runs])
    # 11 iterations, best by image MSE; measured ratios are 0.08 (random) to 0.3 (cmaes).
    assert final < 0.5 * initial, (final, initial)
    assert all(len(h) == 11 for h in runs)


def test_importing_the_module_imports_nothing_heavy(
    heavy_imports: Callable[..., list[str]],
) -> None:
    assert heavy_imports("physbench.estimators.random_search") == []


def test_is_uniform_and_ignores_the_loss() -> None:
    h = run_toy(RandomSearch, {}, seed=0, iterations=40)
    xs = np.array([r.params["a.mass"] for r in h.iterations[1:]])
    assert xs.min() < 3 and xs.max() > 8
