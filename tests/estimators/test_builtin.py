"""The built-in gradient-free estimators: they work on the real pipeline, are deterministic in a
fresh process, import lazily and refuse bad options clearly (the conformance kit runs them in
tests/testing/test_builtins.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from typing import Any

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.cmaes import CMAES
from physbench.estimators.options import EstimatorOptionError
from physbench.estimators.optuna_sampler import Optuna
from physbench.estimators.random_search import RandomSearch
from physbench.estimators.tpe import DEFAULT_STARTUP, TPE
from physbench.loop import draw_problem, refine
from physbench.observation import simulate_observation
from physbench.params import ParamSpace
from physbench.plugins import create, get_registry
from physbench.scenes import resolve_scene
from physbench.testing import run_toy

BUILTINS = ["random", "tpe", "cmaes", "optuna"]


def _three_circles(name: str, seed: int, params: list[str], **options: Any):  # type: ignore[no-untyped-def]
    scene = resolve_scene("three_circles", seed)
    space = ParamSpace.from_scene(scene, params)
    truth, initial = draw_problem(space, seed)
    sim, ren = create("simulator", "pymunk"), create("renderer", "raster", resolution=32)
    obs = simulate_observation(scene, truth, sim, ren)
    return refine(
        obs,
        scene,
        space,
        sim,
        ren,
        create("estimator", name, **options),
        iterations=11,
        seed=seed,
        initial=initial,
    )


def test_builtins_are_registered_through_entry_points() -> None:
    reg = get_registry()
    for name in BUILTINS:
        assert reg.info("estimator", name).package == "physbench"


@pytest.mark.parametrize("name", BUILTINS)
def test_reduces_the_normalized_error_on_three_circles_mass(name: str) -> None:
    runs = [_three_circles(name, seed, ["mass"]) for seed in range(5)]
    initial = np.mean([h.initial_nmse for h in runs])
    final = np.mean([h.best_nmse for h in runs])
    # 11 iterations, best by image MSE; measured ratios are 0.08 (random) to 0.3 (cmaes).
    assert final < 0.5 * initial, (name, final, initial)
    assert all(len(h) == 11 for h in runs)


def test_same_seed_same_history_in_a_fresh_process() -> None:
    ours = _three_circles("tpe", 4, ["mass", "elasticity"]).to_dict(timings=False)
    code = (
        "import json, sys; sys.path[:0] = [sys.argv[1]]\n"
        "from test_builtin import _three_circles\n"
        "print(json.dumps(_three_circles('tpe', 4, ['mass', 'elasticity']).to_dict(timings=False)))"
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


def test_importing_estimator_modules_does_not_import_the_optimisers() -> None:
    code = (
        "import sys\n"
        "import physbench.estimators.tpe, physbench.estimators.cmaes, "
        "physbench.estimators.optuna_sampler\n"
        "import physbench.estimators.random_search, physbench.loop, physbench.testing\n"
        "print([m for m in ('hyperopt', 'nevergrad', 'optuna', 'pandas', 'matplotlib', 'scipy') "
        "if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_startup_is_a_setting_with_a_small_budget_default() -> None:
    assert TPE().options["startup"] == DEFAULT_STARTUP == Optuna().options["startup"] < 11
    # With hyperopt's own default (20) every one of 11 proposals is a random draw; with the small
    # default the proposals after the start-up phase differ from those random draws.
    lib = run_toy(TPE, {"startup": 20}, seed=1, iterations=11)
    ours = run_toy(TPE, {"startup": DEFAULT_STARTUP}, seed=1, iterations=11)
    assert [r.params for r in lib.iterations[:DEFAULT_STARTUP]] == [
        r.params for r in ours.iterations[:DEFAULT_STARTUP]
    ]
    assert lib.iterations[-1].params != ours.iterations[-1].params
    assert ours.options == {"startup": DEFAULT_STARTUP, "candidates": 24, "gamma": 0.25}


def test_first_point_told_is_the_initial_guess() -> None:
    for cls in (TPE, CMAES, Optuna):
        h = run_toy(cls, {}, seed=2, iterations=3)
        assert h.iterations[0].params == h.initial
        assert (
            h.iterations[1].params != h.initial
        )  # a new point is asked, not the initial one again


@pytest.mark.parametrize(
    ("cls", "options", "message"),
    [
        (TPE, {"startup": -1}, r"tpe: startup = -1: expected a whole number >= 0"),
        (TPE, {"gamma": "high"}, r"tpe: gamma = 'high': expected a number in \(0, 1\]"),
        (CMAES, {"sigma": 2.0}, r"cmaes: sigma = 2.0: expected a number in \(0, 1\]"),
        (
            Optuna,
            {"sampler": "grid"},
            r"optuna: sampler = 'grid': expected one of tpe, cmaes, random, qmc",
        ),
    ],
)
def test_bad_options_name_the_option_and_the_accepted_values(
    cls: type, options: dict[str, Any], message: str
) -> None:
    with pytest.raises(EstimatorOptionError, match=message):
        cls(**options)


def test_optuna_samplers() -> None:
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


def test_cmaes_handles_a_single_unknown() -> None:
    h = run_toy(CMAES, {}, seed=0, iterations=6, bodies=("a",))
    assert h.keys == ("a.mass",) and len({r.params["a.mass"] for r in h.iterations}) == 6


def test_random_search_is_uniform_and_ignores_the_loss() -> None:
    h = run_toy(RandomSearch, {}, seed=0, iterations=40)
    xs = np.array([r.params["a.mass"] for r in h.iterations[1:]])
    assert xs.min() < 3 and xs.max() > 8
