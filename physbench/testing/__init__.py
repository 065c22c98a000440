"""Conformance kits for the four component kinds, for plugin authors and the built-ins alike.

Each check is a plain function that raises :class:`ConformanceError` saying what is wrong; the
checks that apply to a component are chosen by its kind (the base class it subclasses) and its
declared traits (``per_object``, ``modes``, ``applies_forces``/``changes_contacts``/``measures``,
``scene_needs``). Run them all at once::

    from physbench.testing import check_effect, check_estimator, check_renderer, check_simulator

    check_simulator(MyEngine, iterations=20)        # keyword options go to MyEngine(...)
    check_renderer(MyRenderer)                       # every mode in MyRenderer.modes
    check_effect(MyDrag)                             # on a probe scene chosen by its traits
    check_estimator(MyEstimator, step=0.2, bad_options=[{"step": -1.0}])

or as one pytest test per component x check (ids like ``MyRenderer-check_marking``)::

    from physbench.testing import Subject, parametrize_with_checks

    @parametrize_with_checks([MyEngine, MyRenderer, Subject(MyEstimator, {"step": 0.2})])
    def test_conformance(component, check):
        check(component)

:class:`EstimatorConformance` is a pytest base class for the estimator checks. The kits live in
:mod:`physbench.testing.simulators`, :mod:`~physbench.testing.renderers`,
:mod:`~physbench.testing.effects` and :mod:`~physbench.testing.estimators` (each check is public
there, with its docstring saying what it checks); :mod:`~physbench.testing.toy` holds the
closed-form toy task the estimator kit runs on.
"""

from __future__ import annotations

from physbench.testing.effects import check_effect
from physbench.testing.estimators import (
    EstimatorConformance,
    check_bad_input,
    check_deterministic,
    check_deterministic_in_subprocess,
    check_estimator,
    check_protocol,
    check_respects_ranges,
)
from physbench.testing.kit import (
    Check,
    ConformanceError,
    Subject,
    checks_for,
    parametrize_with_checks,
)
from physbench.testing.renderers import check_renderer
from physbench.testing.simulators import check_simulator
from physbench.testing.toy import ToyRenderer, ToySimulator, run_toy, toy_scene, toy_task

__all__ = [
    "Check",
    "ConformanceError",
    "EstimatorConformance",
    "Subject",
    "ToyRenderer",
    "ToySimulator",
    "check_bad_input",
    "check_deterministic",
    "check_deterministic_in_subprocess",
    "check_effect",
    "check_estimator",
    "check_protocol",
    "check_renderer",
    "check_respects_ranges",
    "check_simulator",
    "checks_for",
    "parametrize_with_checks",
    "run_toy",
    "toy_scene",
    "toy_task",
]
