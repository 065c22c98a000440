"""``tpe``: hyperopt's TPE works on the real pipeline, is deterministic in a fresh process, imports
hyperopt lazily, starts with a few uniform draws (a Latin hypercube on request) and refuses bad
options clearly (the conformance kit runs it in tests/testing/test_builtins.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.estimators.options import EstimatorOptionError
from physbench.estimators.tpe import DEFAULT_STARTUP, HYPEROPT_STARTUP, TPE
from physbench.plugins import get_registry
from physbench.testing import run_toy
from physbench.testing.toy import toy_task


def test_registered_through_entry_points() -> None:
    assert get_registry().info("estimator", "tpe").package == "physbench"


def test_reduces_the_normalized_error_on_three_circles_mass(
    three_circles: Callable[..., Any],
) -> None:
    runs = [three_circles("tpe", seed, ["mass"]) for seed in range(5)]
    initial = np.mean([h.initial_nmse for h in runs])
    final = np.mean([h.best_nmse for h in runs])
    # 11 iterations, best by image MSE; measured ratios are 0.08 (random) to 0.3 (cmaes).
    assert final < 0.5 * initial, (final, initial)
    assert all(len(h) == 11 for h in runs)


def test_same_seed_same_history_in_a_fresh_process(three_circles: Callable[..., Any]) -> None:
    ours = three_circles("tpe", 4, ["mass", "elasticity"]).to_dict(timings=False)
    code = (
        "import json, sys; sys.path[:0] = [sys.argv[1]]\n"
        "from conftest import run_three_circles\n"
        "h = run_three_circles('tpe', 4, ['mass', 'elasticity'])\n"
        "print(json.dumps(h.to_dict(timings=False)))"
    )
    env = {**os.environ, "PYTHONHASHSEED": "99"}
    out = subprocess.run(
        [sys.executable, "-c", code, os.path.dirname(__file__)],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    assert json.loads(out.stdout) == json.loads(json.dumps(ours))


def test_importing_the_module_does_not_import_hyperopt(
    heavy_imports: Callable[..., list[str]],
) -> None:
    assert heavy_imports("physbench.estimators.tpe") == []


def unit_points(h: Any) -> np.ndarray:
    space = toy_task().space
    return np.array([space.to_unit(r.params) for r in h.iterations])


def slices_hit(points: np.ndarray) -> list[int]:
    n = len(points)
    return [len(set(np.floor(points[:, j] * n).astype(int))) for j in range(points.shape[1])]


def test_startup_is_a_setting_with_a_small_budget_default() -> None:
    assert TPE().options == {
        "startup": DEFAULT_STARTUP,
        "design": "random",
        "candidates": 24,
        "gamma": 0.25,
    }
    assert DEFAULT_STARTUP < 11
    # With hyperopt's own default (20) every one of 11 proposals is one of its uniform draws; with
    # the small default the proposals after the start-up phase differ from those draws.
    lib = run_toy(TPE, {"startup": HYPEROPT_STARTUP}, seed=1, iterations=11)
    ours = run_toy(TPE, {}, seed=1, iterations=11)
    n = DEFAULT_STARTUP
    assert [r.params for r in lib.iterations[:n]] == [r.params for r in ours.iterations[:n]]
    assert lib.iterations[-1].params != ours.iterations[-1].params
    pts = unit_points(lib)[1:]
    assert slices_hit(pts) != [10] * pts.shape[1]  # uniform draws: not stratified


def test_a_latin_hypercube_start_up_covers_the_trials_the_budget_allows() -> None:
    # startup 20 > 9 simulations: after the initial guess, 8 points, one per eighth of every
    # unknown's range.
    pts = unit_points(run_toy(TPE, {"design": "lhs", "startup": 20}, seed=1, iterations=9))[1:]
    assert slices_hit(pts) == [8] * pts.shape[1]


def test_tpe_models_after_a_latin_hypercube_start_up() -> None:
    # startup 4: the guess and a 3-point hypercube, then TPE's own proposals.
    h = run_toy(TPE, {"design": "lhs", "startup": 4}, seed=1, iterations=11)
    pts = unit_points(h)
    assert slices_hit(pts[1:4]) == [3] * pts.shape[1]
    assert slices_hit(pts[1:]) != [10] * pts.shape[1]
    assert len({tuple(p) for p in pts}) == 11


def test_first_point_told_is_the_initial_guess() -> None:
    h = run_toy(TPE, {}, seed=2, iterations=3)
    assert h.iterations[0].params == h.initial
    assert h.iterations[1].params != h.initial  # a new point is asked, not the initial one again


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"startup": -1}, r"tpe: startup = -1: expected a whole number >= 0"),
        ({"gamma": "high"}, r"tpe: gamma = 'high': expected a number in \(0, 1\]"),
        ({"design": "sobol"}, r"tpe: design = 'sobol': expected one of lhs, random"),
    ],
)
def test_bad_options_name_the_option_and_the_accepted_values(
    options: dict[str, Any], message: str
) -> None:
    with pytest.raises(EstimatorOptionError, match=message):
        TPE(**options)
