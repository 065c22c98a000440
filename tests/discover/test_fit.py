"""Fitting a model (physbench/discover/fit.py): the black-box start, budgets and horizons."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from physbench.discover import Run, Settings, fit_base
from physbench.discover.fit import budget, estimator_fit, fit_horizons, is_rough
from physbench.discover.pipeline import problem_for, start_model
from physbench.errors import PhysbenchError
from physbench.scene import Body, Circle, Segment
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_black_box_estimator_for_the_base_fit(slide, noisy):
    scene = slide(v=(1.5, 0.0), mass=2.0, frames=31)
    rec = noisy(PymunkSimulator().simulate(scene))
    settings = Settings(estimator="random", estimator_iterations=8)
    base = fit_base([Run("r", scene, recording=rec)], "pymunk", settings)
    assert base.fit.rms < 0.004
    with pytest.raises(PhysbenchError, match="unknown estimator 'nope'"):
        fit_base([Run("r", scene, recording=rec)], "pymunk", Settings(estimator="nope"))


def test_the_estimator_searches_the_fit_parameters_of_several_runs(slide, noisy):
    scene = slide()
    runs = [
        Run(f"r{i}", scene, recording=noisy(PymunkSimulator().simulate(scene), seed=i))
        for i in range(3)
    ]
    settings = Settings()
    model = start_model(problem_for(runs, "pymunk", settings), settings)
    free = model.free_keys()  # the training runs' nuisance, under each run's prefix
    assert free[0] == "r0/ball.x0" and all(k.startswith(("r0/", "r1/")) for k in free)
    best = estimator_fit(model, free, "random", iterations=5, seed=1)
    assert list(best) == free and all(model.values[k] == v for k, v in best.items())
    assert all(model.param(k).contains(v) for k, v in best.items())


def test_budgets_and_horizons_follow_the_settings_and_the_scene(slide, noisy):
    s = Settings()
    assert budget(s, 7) == 120 and budget(s, 15) == 240
    scene = slide()
    floor = replace(scene, statics=(Segment((-3.0, -2.9), (9.0, -2.9)),))
    pair = replace(scene, bodies=(*scene.bodies, Body("b", Circle(0.05), (1.0, 4.0))))
    track = noisy(PymunkSimulator().simulate(scene))
    smooth = Run("r", scene, recording=track)
    assert not is_rough([smooth])
    assert is_rough([Run("r", floor, recording=track)])
    assert is_rough([Run("r", pair, recording=track)])
    assert is_rough([Run("r", scene, frames=np.zeros((41, 1, 8, 8), np.float32))])
    model = start_model(problem_for([smooth], "pymunk", s), s)
    assert fit_horizons(model, s) == (1.0,)
    assert fit_horizons(model, Settings(horizons=(0.3, 2.0))) == (0.3, 1.0)
    walls = start_model(problem_for([Run("r", floor, recording=track)], "pymunk", s), s)
    assert fit_horizons(walls, s) == (0.5, 1.0)


WILD = """
from typing import ClassVar

from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl


class Wild(CorrectionEstimator):
    name: ClassVar[str] = "wild"

    def start(self, task, *, seed):
        self.space = task.space

    def propose(self, step):
        return {k: 1e9 for k in self.space.keys}  # far outside every range


@hookimpl
def register_estimators():
    return [Wild]
"""


def test_discovery_fits_run_through_the_loops_guarded_driver(plugin, slide, noisy):  # type: ignore[no-untyped-def]
    """A black-box fit gets the same proposal checks as the image loop: one driver."""
    from physbench.loop import EstimatorError

    plugin("pb_wild", WILD)
    scene = slide()
    settings = Settings()
    runs = [Run("r", scene, recording=noisy(PymunkSimulator().simulate(scene)))]
    model = start_model(problem_for(runs, "pymunk", settings), settings)
    with pytest.raises(EstimatorError, match=r"estimator 'wild' proposed .* = 1000000000\.0 in"):
        estimator_fit(model, model.free_keys()[:1], "wild", iterations=3)


class _Residuals:
    """A stand-in model whose held-out residuals are given."""

    def __init__(self, r: list[float]) -> None:
        self.r = np.asarray(r)

    def residuals(self, part: str) -> np.ndarray:
        return self.r


@pytest.mark.parametrize(("r", "says"), [([1e300, 1.0], "residuals is inf"), ([], "no held-out")])
def test_a_held_out_error_that_is_no_number_says_why_without_warnings(
    r: list[float], says: str
) -> None:
    import warnings

    from physbench.discover.fit import score

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's overflow would raise here
        scored = score("base", (), _Residuals(r), None)  # type: ignore[arg-type]
    assert not np.isfinite(scored.heldout) and says in scored.failure, scored.failure
