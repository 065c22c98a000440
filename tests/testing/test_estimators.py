"""The conformance suite catches deliberately broken estimators, and its pytest base class works."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.estimators.random_search import RandomSearch
from physbench.testing import (
    Check,
    ConformanceError,
    EstimatorConformance,
    Subject,
    check_bad_input,
    check_deterministic,
    check_deterministic_in_subprocess,
    check_estimator,
    check_protocol,
    check_respects_ranges,
    checks_for,
    parametrize_with_checks,
)
from physbench.testing.estimators import check_marked_views
from physbench.unknowns import Params


class Base(CorrectionEstimator):
    """A correct minimal estimator (uniform draws); the broken ones below change one thing."""

    name: ClassVar[str] = "base"

    def __init__(self, width: float = 1.0) -> None:
        if not 0 < width <= 1:
            raise PhysbenchError(f"width = {width!r}: expected a number in (0, 1]")
        self.width = width
        self.task: Task | None = None

    def start(self, task: Task, *, seed: int) -> None:
        self.task, self.rng = task, np.random.default_rng(seed)

    def propose(self, step: Step) -> Params:
        if self.task is None:
            raise PhysbenchError("base: propose() called before start()")
        return self.task.space.from_unit(self.rng.random(len(self.task.space)) * self.width)


class OutOfRange(Base):
    def propose(self, step: Step) -> Params:
        p = super().propose(step)
        key = next(iter(p))
        return {**p, key: self.task.space.high[0] * 1.5}  # type: ignore[union-attr]


class DropsAKey(Base):
    def propose(self, step: Step) -> Params:
        p = super().propose(step)
        p.pop(next(iter(p)))
        return p


class Unseeded(Base):
    def start(self, task: Task, *, seed: int) -> None:
        self.task, self.rng = task, np.random.default_rng()


class SeededByProcess(Base):
    """Deterministic within one process, different in another: the in-process check cannot tell."""

    def start(self, task: Task, *, seed: int) -> None:
        self.task, self.rng = task, np.random.default_rng([seed, os.getpid()])


class UnseededOutOfRange(OutOfRange, Unseeded):
    pass


class Nameless(Base):
    name: ClassVar[str] = ""


class OutsideTheContract:
    """Duck-typed: the right methods, but not a CorrectionEstimator."""

    name: ClassVar[str] = "outside"

    def start(self, task: Task, *, seed: int) -> None: ...

    def propose(self, step: Step) -> Params:
        return {}


class PerObjectNotABool(Base):
    per_object: ClassVar[bool] = "yes"  # type: ignore[assignment]


class SwallowsOptions(Base):
    def __init__(self, **options: Any) -> None:
        super().__init__()


class CrashesBeforeStart(Base):
    def propose(self, step: Step) -> Params:
        # AttributeError on None
        return self.task.space.sample(self.rng)  # type: ignore[union-attr]


class AcceptsBadWidth(Base):
    def __init__(self, width: float = 1.0) -> None:
        self.width, self.task = width, None


class PerObject(Base):
    """Corrects one marked object at a time (here: ignores them), and checks it gets them."""

    per_object: ClassVar[bool] = True

    def start(self, task: Task, *, seed: int) -> None:
        for body in task.space.bodies:
            if body not in task.marked_observation:
                raise PhysbenchError(f"per_object: no marked view of body {body!r}")
        super().start(task, seed=seed)


class PerObjectUnchecked(Base):
    per_object: ClassVar[bool] = True


class MassOnly(Base):
    """Can only be asked for masses (like a learned estimator trained for mass)."""

    def start(self, task: Task, *, seed: int) -> None:
        asked = sorted({u.name for u in task.space.unknowns})
        if asked != ["mass"]:
            raise PhysbenchError(f"mass_only: cannot estimate {asked}")
        super().start(task, seed=seed)


def test_a_correct_estimator_passes() -> None:
    check_estimator(Base, width=0.5, bad_options=[{"width": 0.0}, {"width": 3}])


def test_out_of_range_proposals_fail() -> None:
    with pytest.raises(
        ConformanceError, match=r"proposed a.mass = 15.0 .*expected a finite number in \[1, 10\]"
    ):
        check_respects_ranges(OutOfRange)
    with pytest.raises(ConformanceError, match=r"missing \['a.mass'\]"):
        check_respects_ranges(DropsAKey)


def test_unseeded_randomness_fails() -> None:
    with pytest.raises(ConformanceError, match="two runs with seed 3 differ at iteration 1"):
        check_deterministic(Unseeded)


def test_process_dependent_randomness_fails_only_in_another_process() -> None:
    check_deterministic(SeededByProcess)
    with pytest.raises(ConformanceError, match="different history in another process"):
        check_deterministic_in_subprocess(SeededByProcess)


def test_classes_the_child_cannot_import_are_explained() -> None:
    class Local(Base):
        pass

    with pytest.raises(ConformanceError, match="define it at module level"):
        check_deterministic_in_subprocess(Local)


def test_protocol_shape() -> None:
    with pytest.raises(ConformanceError, match="'name' must be a non-empty string"):
        check_protocol(Nameless)
    with pytest.raises(ConformanceError, match=r"does not subclass .*CorrectionEstimator"):
        check_protocol(OutsideTheContract)
    with pytest.raises(ConformanceError, match="'per_object' must be True or False"):
        check_protocol(PerObjectNotABool)
    with pytest.raises(ConformanceError, match=r"Base\(\*\*\{'width': 5\}\) raised PhysbenchError"):
        check_protocol(Base, width=5)


def test_unclear_errors_fail() -> None:
    with pytest.raises(
        ConformanceError, match="unknown option 'no_such_option_xyz' was accepted silently"
    ):
        check_bad_input(SwallowsOptions)
    with pytest.raises(
        ConformanceError, match="propose\\(\\) before start\\(\\) raised AttributeError"
    ):
        check_bad_input(CrashesBeforeStart)
    with pytest.raises(ConformanceError, match=r"bad options \{'width': -1\} were accepted"):
        check_bad_input(AcceptsBadWidth, [{"width": -1}])


def test_check_estimator_lists_every_failure() -> None:
    with pytest.raises(ConformanceError) as info:
        check_estimator(Unseeded, subprocess=False)
    assert "fails 1 conformance check(s)" in str(info.value) and "- check_deterministic:" in str(
        info.value
    )
    with pytest.raises(ConformanceError, match=r"fails 2 conformance check\(s\)"):
        check_estimator(UnseededOutOfRange, subprocess=False)


class TestBaseThroughTheBaseClass(EstimatorConformance):
    estimator = Base
    options: ClassVar[Mapping[str, Any]] = {"width": 0.8}
    bad_options: ClassVar[Sequence[Mapping[str, Any]]] = [{"width": 0}]


class TestRandomSearchThroughTheBaseClass(EstimatorConformance):
    estimator = RandomSearch


def test_the_base_class_reports_a_broken_estimator() -> None:
    class TestBroken(EstimatorConformance):
        estimator = OutOfRange

    with pytest.raises(ConformanceError):
        TestBroken().test_respects_ranges()
    with pytest.raises(ConformanceError, match="set the class attribute 'estimator'"):
        EstimatorConformance().test_protocol()


@parametrize_with_checks(
    [
        Subject(Base, {"width": 0.8}, {"bad_options": [{"width": 0}]}),
        Subject(MassOnly, kit={"unknowns": ("mass",)}),
        PerObject,
    ]
)
def test_correct_estimators_pass_every_parametrized_check(component: Subject, check: Check) -> None:
    check(component)


def test_the_unknowns_setting_limits_what_the_toy_task_asks() -> None:
    with pytest.raises(
        ConformanceError,
        match=r"raised PhysbenchError: mass_only: cannot estimate \['elasticity', 'mass'\] \(if",
    ):
        check_respects_ranges(MassOnly)
    check_respects_ranges(MassOnly, unknowns=("mass",))
    check_deterministic(MassOnly, unknowns=("mass",))
    with pytest.raises(ConformanceError, match=r"kit setting unknowns = \('friction',\)"):
        check_deterministic(MassOnly, unknowns=("friction",))


class TestMassOnlyThroughTheBaseClass(EstimatorConformance):
    estimator = MassOnly
    unknowns: ClassVar[Sequence[str]] = ("mass",)


def test_per_object_estimators_must_ask_for_their_marked_views() -> None:
    assert "check_marked_views" in [c.name for c in checks_for(PerObject)]
    assert "check_marked_views" not in [c.name for c in checks_for(Base)]
    check_marked_views(PerObject)
    with pytest.raises(
        ConformanceError,
        match="start\\(\\) accepted a task without the marked view of unknown body 'b'",
    ):
        check_marked_views(PerObjectUnchecked)
