"""Scene-level unknowns (gravity, the camera's scale, an effect's parameter) reach every estimator
that searches the ranges through the ParamSpace/Task contract alone: the built-in ones and a
plugin written against the base class."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from physbench.components import create, make_estimator
from physbench.effects import LinearDrag
from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.loop import History, draw_problem, refine
from physbench.observation import simulate_observation
from physbench.render.raster import RasterRenderer
from physbench.scene import Body, Circle, Scene
from physbench.unknowns import Params, ParamSpace, scene_parameters

TOSS = Scene("toss", (Body("ball", Circle(0.1), (0.5, 0.5), velocity=(2.5, 5.0), mass=0.2),))


class Bisect(CorrectionEstimator):
    """A third party's estimator: it knows nothing of gravity or drag, only the unit cube."""

    name: ClassVar[str] = "bisect"

    def start(self, task: Task, *, seed: int) -> None:
        self.space, self.rng = task.space, np.random.default_rng(seed)

    def propose(self, step: Step) -> Params:
        return self.space.from_unit(self.rng.random(len(self.space)))


def _run(estimator: CorrectionEstimator, seed: int = 3) -> tuple[History, ParamSpace]:
    drag = LinearDrag()
    offered = scene_parameters([drag])
    space = ParamSpace.from_scene(
        TOSS, ["gravity", "camera.scale", "linear_drag.c=0:0.5"], offered=offered
    )
    sim, ren = create("simulator", "pymunk"), RasterRenderer(32)
    truth, _ = draw_problem(space, seed)
    obs = simulate_observation(TOSS, truth, sim, ren, effects=[drag])
    history = refine(
        obs, TOSS, space, sim, ren, estimator, iterations=10, seed=seed, effects=[drag]
    )
    return history, space


@pytest.mark.parametrize("name", ["tpe", "cmaes", "optuna", "random", "smc", "nevergrad", "plugin"])
def test_every_box_estimator_searches_scene_level_unknowns(name: str) -> None:
    make = (lambda: Bisect()) if name == "plugin" else (lambda: make_estimator(name))
    history, space = _run(make())
    assert history.keys == ("gravity", "camera.scale", "linear_drag.c")
    points = np.array([[r.params[k] for k in history.keys] for r in history.iterations])
    assert np.all(points >= space.low) and np.all(points <= space.high)
    assert np.all(points.std(axis=0) > 0)  # every unknown was moved
    assert history.truth is not None and set(history.truth) == set(history.keys)
    again, _ = _run(make())
    assert again.to_dict(timings=False) == history.to_dict(timings=False)


class Marked(CorrectionEstimator):
    """Corrects one marked body at a time, like resnet3d and npe."""

    name: ClassVar[str] = "marked"
    per_object: ClassVar[bool] = True


def test_a_per_object_estimator_refuses_scene_level_unknowns_in_one_sentence() -> None:
    with pytest.raises(PhysbenchError) as err:
        _run(Marked())
    assert str(err.value) == (
        "estimator 'marked' corrects one marked body at a time, so it cannot fit gravity, "
        "camera.scale, linear_drag.c (they belong to no body); use an estimator that searches "
        "the ranges (tpe, cmaes, optuna, random, smc)"
    )
