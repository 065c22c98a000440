"""Shared fixtures of the estimator tests: a short run of a registered estimator on the real
pipeline (three_circles, pymunk, a 32-pixel raster)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from physbench.components import create
from physbench.loop import History, draw_problem, refine
from physbench.observation import simulate_observation
from physbench.scenes import resolve_scene
from physbench.unknowns import ParamSpace


def run_three_circles(name: str, seed: int, params: list[str], **options: Any) -> History:
    """11 iterations of the estimator ``name`` on three_circles for ``seed`` (a module-level
    function, so that a fresh interpreter can import and run it too)."""
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


@pytest.fixture
def three_circles() -> Callable[..., History]:
    """``three_circles(name, seed, params, **options)``: see :func:`run_three_circles`."""
    return run_three_circles
