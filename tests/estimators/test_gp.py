"""``gp``: Optuna's GP sampler works on the real pipeline, starts at the initial guess (then a
Latin hypercube on request), is told the loss itself, imports optuna and torch lazily, names what
it needs and refuses bad options clearly."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.gp import DEFAULT_STARTUP, GaussianProcess
from physbench.estimators.options import EstimatorOptionError
from physbench.loop import refine
from physbench.plugins import get_registry
from physbench.testing import run_toy
from physbench.testing.toy import toy_task

pytest.importorskip("torch")


def test_registered_through_entry_points_and_names_its_extra() -> None:
    info = get_registry().info("estimator", "gp")
    assert info.package == "physbench" and info.obj is GaussianProcess
    assert dict(GaussianProcess.requires) == {"torch": "physbench[learn]"}


def test_beats_random_search_on_three_circles_mass(three_circles: Callable[..., Any]) -> None:
    seeds = range(4)
    gp = np.mean([three_circles("gp", s, ["mass"]).best_nmse for s in seeds])
    rnd = np.mean([three_circles("random", s, ["mass"]).best_nmse for s in seeds])
    # measured on these seeds (32 px): gp 5.0e-4, random 5.3e-3
    assert gp < 0.3 * rnd, (gp, rnd)


def test_importing_the_module_imports_neither_optuna_nor_torch(
    heavy_imports: Callable[..., list[str]],
) -> None:
    assert heavy_imports("physbench.estimators.gp", heavy=("optuna", "torch")) == []


def unit_points(h: Any) -> np.ndarray:
    space = toy_task().space
    return np.array([space.to_unit(r.params) for r in h.iterations])


def test_defaults_and_the_initial_guess_first() -> None:
    assert GaussianProcess().options == {"startup": DEFAULT_STARTUP, "design": "random"}
    h = run_toy(GaussianProcess, {}, seed=2, iterations=8)
    assert h.iterations[0].params == h.initial
    assert len({tuple(p) for p in unit_points(h)}) == len(h)  # no point asked twice


def test_a_latin_hypercube_start_up_on_request() -> None:
    h = run_toy(GaussianProcess, {"design": "lhs"}, seed=2, iterations=8)
    assert h.iterations[0].params == h.initial
    design = unit_points(h)[1:DEFAULT_STARTUP]
    # one point in each of the n equal slices of every unknown's range
    n = len(design)
    for column in design.T:
        assert sorted(np.floor(column * n).astype(int)) == list(range(n))
    default = unit_points(run_toy(GaussianProcess, {}, seed=2, iterations=8))
    assert not np.allclose(default[1:DEFAULT_STARTUP], design)


def test_the_gp_is_told_each_loss_itself() -> None:
    t = toy_task()
    est = GaussianProcess()
    h = refine(t.observation, t.scene, t.space, t.simulator, t.renderer, est, iterations=7, seed=1)
    told = [trial.value for trial in est._study.trials if trial.value is not None]
    assert told == [r.loss for r in h.iterations]


def test_bad_options_name_the_option_and_the_accepted_values() -> None:
    with pytest.raises(EstimatorOptionError, match=r"gp: startup = 0: expected a whole number"):
        GaussianProcess(startup=0)
    with pytest.raises(EstimatorOptionError, match=r"gp: design = 'sobol': expected one of"):
        GaussianProcess(design="sobol")
    with pytest.raises(EstimatorOptionError, match=r"gp: startup = 2.5: expected a whole number"):
        GaussianProcess(startup=2.5)  # type: ignore[arg-type]


def test_an_optuna_without_gp_sampler_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    import optuna

    monkeypatch.delattr(optuna.samplers, "GPSampler")
    with pytest.raises(PhysbenchError, match=r"needs Optuna 3.6 or newer .*pip install -U optuna"):
        run_toy(GaussianProcess, {}, iterations=2)
