"""The CorrectionEstimator contract's documented defaults: no options, not ``per_object``, and
``start``/``propose`` that say which class must implement them; what :class:`Task` and
:class:`Step` hold when the loop leaves the optional fields out."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from physbench.estimators.base import DEFAULT_ESTIMATOR, CorrectionEstimator, Step, Task
from physbench.plugins import get_registry
from physbench.testing import toy_task


class Bare(CorrectionEstimator):
    """Declares a name and nothing else."""

    name: ClassVar[str] = "bare"


def test_defaults_are_no_options_and_one_object_at_a_time() -> None:
    est = Bare()
    assert dict(est.options) == {} and Bare.per_object is False
    assert CorrectionEstimator.name == ""
    with pytest.raises(TypeError):  # the shared default cannot be changed through one instance
        est.options["step"] = 1.0  # type: ignore[index]


def test_start_and_propose_name_the_class_that_must_implement_them() -> None:
    est = Bare()
    t = toy_task()
    task = Task(t.scene, t.space, t.observation.frames, {}, t.renderer, iterations=1)
    with pytest.raises(NotImplementedError, match=r"^Bare must implement start\(\)$"):
        est.start(task, seed=0)
    with pytest.raises(NotImplementedError, match=r"^Bare must implement propose\(\)$"):
        est.propose(Step(0, {}, np.zeros((1, 2, 4, 4)), 0.0))


def test_task_and_step_hold_no_marked_views_unless_given() -> None:
    t = toy_task()
    a = Task(t.scene, t.space, t.observation.frames, {}, None, iterations=1)
    b = Task(t.scene, t.space, t.observation.frames, {}, None, iterations=1)
    assert dict(a.marked_observation) == {} and a.marked_observation is not b.marked_observation
    step = Step(0, {}, np.zeros((1, 2, 4, 4)), 0.5)
    assert step.trajectory is None and dict(step.marked) == {}


def test_the_default_estimator_is_registered() -> None:
    assert DEFAULT_ESTIMATOR in get_registry().names("estimator")
