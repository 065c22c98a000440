"""The ask/tell base of the black-box optimisers: ``start`` maps the initial guess to the unit
cube, ``propose`` tells the step's loss and returns the next point asked, clipped into the ranges,
and refuses to run before ``start``."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.ask_tell import AskTellEstimator
from physbench.estimators.base import Step, Task
from physbench.testing import toy_task


class Scripted(AskTellEstimator):
    """Asks the unit-cube points it is given, in order; records what it was told."""

    name: ClassVar[str] = "scripted"

    def __init__(self, *points: list[float], step: float = 0.5) -> None:
        super().__init__()
        self.options = {"step": step}
        self.points = [np.asarray(p, dtype=float) for p in points]
        self.begun: list[tuple[Any, int]] = []
        self.told: list[float] = []

    def _begin(self, task: Task, seed: int) -> None:
        self.begun.append((task, seed))

    def _tell(self, loss: float) -> None:
        self.told.append(loss)

    def _ask(self) -> np.ndarray:
        return self.points[len(self.told) - 1]


def _task(initial: dict[str, float]) -> Task:
    t = toy_task(("mass",))  # unknowns a.mass and b.mass, both in [1, 10]
    return Task(t.scene, t.space, t.observation.frames, initial, t.renderer, iterations=3)


def _step(loss: float) -> Step:
    return Step(iteration=0, params={}, frames=np.zeros((1, 2, 4, 4)), loss=loss)


def test_start_maps_the_initial_guess_to_the_unit_cube_and_passes_the_seed() -> None:
    est = Scripted()
    task = _task({"a.mass": 1.0, "b.mass": 7.75})
    est.start(task, seed=np.int64(3))  # type: ignore[arg-type]
    assert est.x0.tolist() == [0.0, 0.75]
    assert est.space is task.space
    (begun,) = est.begun
    assert begun[0] is task and begun[1] == 3 and type(begun[1]) is int


def test_propose_tells_the_loss_then_returns_the_point_asked() -> None:
    est = Scripted([0.5, 0.25], [0.0, 1.0])
    est.start(_task({"a.mass": 1.0, "b.mass": 1.0}), seed=0)
    step = _step(np.float32(0.25))  # type: ignore[arg-type]
    assert est.propose(step) == {"a.mass": 5.5, "b.mass": 3.25}
    assert est.propose(_step(0.125)) == {"a.mass": 1.0, "b.mass": 10.0}
    assert est.told == [0.25, 0.125] and all(type(v) is float for v in est.told)


def test_points_asked_outside_the_unit_cube_are_clipped_into_the_ranges() -> None:
    est = Scripted([-0.5, 1.5])
    est.start(_task({"a.mass": 1.0, "b.mass": 1.0}), seed=0)
    assert est.propose(_step(1.0)) == {"a.mass": 1.0, "b.mass": 10.0}


def test_propose_before_start_names_the_estimator() -> None:
    with pytest.raises(
        PhysbenchError, match=r"estimator 'scripted': propose\(\) called before start\(\)"
    ):
        Scripted([0.5, 0.5]).propose(_step(0.0))


def test_a_subclass_must_implement_the_optimiser_steps() -> None:
    est = AskTellEstimator()
    assert est.options == {} and est.x0.shape == (0,)
    with pytest.raises(NotImplementedError):
        est.start(_task({"a.mass": 1.0, "b.mass": 1.0}), seed=0)


def test_repr_shows_the_options() -> None:
    assert repr(Scripted(step=0.25)) == "Scripted(step=0.25)"
    assert repr(AskTellEstimator()) == "AskTellEstimator()"
