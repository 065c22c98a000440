"""``optuna``: an Optuna study works on the real pipeline, starts at the initial guess, offers its
samplers, shares the small-budget ``startup`` default, imports optuna lazily and refuses bad
options clearly."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.options import EstimatorOptionError
from physbench.estimators.optuna_sampler import DEFAULT_STARTUP, Optuna
from physbench.plugins import get_registry
from physbench.testing import run_toy


def test_registered_through_entry_points() -> None:
    assert get_registry().info("estimator", "optuna").package == "physbench"


def test_reduces_the_normalized_error_on_three_circles_mass(
    three_circles: Callable[..., Any],
) -> None:
    runs = [three_circles("optuna", seed, ["mass"]) for seed in range(5)]
    initial = np.mean([h.initial_nmse for h in runs])
    final = np.mean([h.best_nmse for h in runs])
    # 11 iterations, best by image MSE; measured ratios are 0.08 (random) to 0.3 (cmaes).
    assert final < 0.5 * initial, (final, initial)
    assert all(len(h) == 11 for h in runs)


def test_importing_the_module_does_not_import_optuna(
    heavy_imports: Callable[..., list[str]],
) -> None:
    assert heavy_imports("physbench.estimators.optuna_sampler") == []


def test_startup_defaults_to_the_small_budget_default_of_tpe() -> None:
    assert Optuna().options["startup"] == DEFAULT_STARTUP


def test_first_point_told_is_the_initial_guess() -> None:
    h = run_toy(Optuna, {}, seed=2, iterations=3)
    assert h.iterations[0].params == h.initial
    assert h.iterations[1].params != h.initial  # a new point is asked, not the initial one again


def test_samplers() -> None:
    for sampler in ("random", "qmc"):
        h = run_toy(Optuna, {"sampler": sampler}, seed=0, iterations=4)
        assert h.options["sampler"] == sampler and len(h) == 4
    try:
        import cmaes  # noqa: F401
    except ImportError:
        with pytest.raises(PhysbenchError, match="pip install cmaes"):
            run_toy(Optuna, {"sampler": "cmaes"}, iterations=2)
    else:
        assert len(run_toy(Optuna, {"sampler": "cmaes"}, iterations=4)) == 4


def test_bad_options_name_the_option_and_the_accepted_values() -> None:
    with pytest.raises(
        EstimatorOptionError,
        match=r"optuna: sampler = 'grid': expected one of tpe, cmaes, random, qmc",
    ):
        Optuna(sampler="grid")
