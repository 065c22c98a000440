"""The correction loop and its history, on the closed-form toy task."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import ClassVar

import numpy as np
import pytest

from physbench.errors import PhysbenchError, SimulationError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.estimators.random_search import RandomSearch
from physbench.loop import (
    FAILED_LOSS,
    EstimatorError,
    History,
    derive_seeds,
    draw_problem,
    refine,
)
from physbench.metrics import running_best
from physbench.observation import (
    Observation,
    ObservationError,
    simulate_observation,
)
from physbench.testing import ToyRenderer, ToySimulator, toy_task
from physbench.unknowns import ParamSpace


class Scripted(CorrectionEstimator):
    """Proposes a fixed list of points (then repeats the last); records what it was given."""

    name: ClassVar[str] = "scripted"
    per_object: ClassVar[bool] = False

    def __init__(self, points: list[dict[str, float]]) -> None:
        self.points = points
        self.steps: list[Step] = []
        self.task: Task | None = None

    def start(self, task: Task, *, seed: int) -> None:
        self.task = task

    def propose(self, step: Step) -> dict[str, float]:
        self.steps.append(step)
        return self.points[min(len(self.steps) - 1, len(self.points) - 1)]


class CountingSimulator(ToySimulator):
    def __init__(self) -> None:
        self.calls: list[dict[str, float]] = []

    def simulate(self, scene, params=None, *, effects=()):  # type: ignore[no-untyped-def]
        self.calls.append(dict(params or {}))
        return super().simulate(scene, params, effects=effects)


def _run(  # type: ignore[no-untyped-def]
    estimator,
    *,
    iterations: int = 6,
    params=("mass",),
    sim=None,
    obs=None,
    seed: int = 0,
    **kwargs,
):
    t = toy_task(params, seed=seed)
    return refine(
        obs if obs is not None else t.observation,
        t.scene,
        t.space,
        sim or t.simulator,
        t.renderer,
        estimator,
        iterations=iterations,
        seed=seed,
        **kwargs,
    )


def test_importing_the_loop_imports_no_optimiser(heavy_imports: Callable[..., list[str]]) -> None:
    assert heavy_imports("physbench.loop") == []


def test_one_simulation_and_one_propose_per_iteration() -> None:
    t = toy_task(("mass",), seed=0)
    points = [{"a.mass": 1.0 + i, "b.mass": 9.0 - i} for i in range(7)]
    est, sim = Scripted(points), CountingSimulator()
    h = _run(est, iterations=7, sim=sim)
    assert len(h) == 7 and len(sim.calls) == 7 and len(est.steps) == 7
    _, initial = draw_problem(t.space, 0)
    assert sim.calls[0] == initial == h.initial == est.task.initial  # type: ignore[union-attr]
    assert sim.calls[1:] == points[:6]  # iteration k simulates proposal k-1
    assert [s.iteration for s in est.steps] == list(range(7))
    for s, r in zip(est.steps, h.iterations, strict=True):
        assert (
            s.params == r.params
            and s.loss == r.loss
            and s.frames.shape == t.observation.frames.shape
        )
        assert r.t_simulate >= 0 and r.t_render >= 0 and r.t_estimator >= 0


def test_best_is_chosen_by_image_mse_without_peeking_at_the_truth() -> None:
    t = toy_task(("mass",), seed=0)
    looks_right = {"a.mass": 2.0, "b.mass": 3.0}  # reproduces the frames exactly
    truly_right = {"a.mass": 8.0, "b.mass": 7.0}  # what we claim the truth is
    frames = simulate_observation(t.scene, looks_right, t.simulator, t.renderer).frames
    obs = Observation(frames, truth=truly_right)
    h = _run(Scripted([truly_right, looks_right, truly_right]), iterations=4, obs=obs)
    assert h.iterations[1].nmse == 0.0 and h.iterations[2].loss == 0.0
    assert h.best.iteration == 2 and h.best.params == looks_right
    assert (
        h.best_nmse == pytest.approx(t.space.normalized_mse(looks_right, truly_right))
        and h.best_nmse > 0
    )
    losses = [r.loss for r in h.iterations]
    assert [r.best_iteration for r in h.iterations] == running_best(losses)
    assert all(r.best_nmse == h.iterations[r.best_iteration].nmse for r in h.iterations)


def test_history_round_trips_through_json_and_pandas() -> None:
    h = _run(RandomSearch(), iterations=5, params=("mass", "elasticity"))
    d = json.loads(h.to_json())
    assert d["timings"].keys() == {"simulate", "render", "estimator"}
    again = History.from_dict(d)
    assert again.to_dict() == h.to_dict()
    assert again.best_nmse == h.best_nmse and again.best == h.best
    frame = h.to_frame()
    assert list(frame.index) == list(range(5))
    assert {"loss", "nmse", "best_nmse", "t_simulate", *h.keys} <= set(frame.columns)
    # JSON written before the renames: "records" and "min_nmse" (0.1)
    old = {k: v for k, v in d.items() if k not in ("iterations", "best_nmse")}
    old.update(records=d["iterations"], min_nmse=d["best_nmse"])
    assert History.from_dict(old).to_dict() == h.to_dict()


def test_seeds_are_derived_from_one_seed_sequence() -> None:
    a, b = derive_seeds(7), derive_seeds(7)
    assert a.estimator == b.estimator and a.truth.random() == b.truth.random()
    assert derive_seeds(8).estimator != a.estimator
    space = toy_task().space
    truth, initial = draw_problem(space, 3)
    assert truth != initial and space.contains(truth) and space.contains(initial)
    with pytest.raises(PhysbenchError, match="seed = -1"):
        derive_seeds(-1)


@pytest.mark.parametrize("bad", [0, -3, 2.5])
def test_impossible_iteration_counts_are_refused(bad: object) -> None:
    with pytest.raises(PhysbenchError, match=f"iterations = {bad!r}: expected a whole number >= 1"):
        _run(RandomSearch(), iterations=bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("proposal", "message"),
    [
        (
            {"a.mass": 11.0, "b.mass": 5.0},
            r"a.mass = 11.0 .* expected a finite number in \[1, 10\]",
        ),
        ({"a.mass": float("nan"), "b.mass": 5.0}, r"a.mass = nan"),
        ({"a.mass": 5.0}, r"missing \['b.mass'\]"),
        ({"a.mass": 5.0, "b.mass": 5.0, "c.mass": 1.0}, r"extra \['c.mass'\]"),
        ([5.0, 5.0], r"returned list .* expected a dict"),
    ],
)
def test_bad_proposals_name_the_estimator_key_and_range(proposal: object, message: str) -> None:
    with pytest.raises(EstimatorError, match="estimator 'scripted'") as info:
        _run(Scripted([proposal]), iterations=3)  # type: ignore[list-item]
    assert info.match(message)


def test_initial_guess_outside_the_ranges_is_refused() -> None:
    t = toy_task()
    with pytest.raises(PhysbenchError, match=r"a.mass in \[1, 10\]"):
        refine(
            t.observation,
            t.scene,
            t.space,
            t.simulator,
            t.renderer,
            RandomSearch(),
            iterations=2,
            initial={"a.mass": 0.5, "b.mass": 2.0},
        )


def test_unknowns_can_be_given_as_parameter_names() -> None:
    t = toy_task(("mass", "elasticity"))
    h = refine(
        t.observation,
        t.scene,
        ["elasticity"],
        t.simulator,
        t.renderer,
        RandomSearch(),
        iterations=2,
    )
    assert h.keys == ("a.elasticity", "b.elasticity")
    with pytest.raises(PhysbenchError, match="unknown parameter 'friction' of scene 'toy'"):
        refine(
            t.observation,
            t.scene,
            ["friction"],
            t.simulator,
            t.renderer,
            RandomSearch(),
            iterations=2,
        )


def test_observation_of_the_wrong_shape_names_expected_and_got() -> None:
    t = toy_task()
    bad = t.observation.frames[:, :1]
    with pytest.raises(
        ObservationError,
        match=r"shape \(12, 1, 16, 16\), expected .* \(12, 2, 16, 16\) \(C 1 != 2\)",
    ):
        _run(RandomSearch(), obs=bad)
    with pytest.raises(
        ObservationError, match=r"values span \[0, 1.98.*expected values in \[0, 1\]"
    ):
        _run(RandomSearch(), obs=t.observation.frames * 2)


def test_a_failed_simulation_costs_an_iteration_with_the_worst_loss() -> None:
    class Fragile(ToySimulator):
        def simulate(self, scene, params=None, *, effects=()):  # type: ignore[no-untyped-def]
            if params and params["a.mass"] > 5:
                raise SimulationError("exploded", engine="toy", frame=3, body="a")
            return super().simulate(scene, params, effects=effects)

    est = Scripted([{"a.mass": 9.0, "b.mass": 2.0}, {"a.mass": 2.0, "b.mass": 2.0}])
    h = _run(est, iterations=3, sim=Fragile())
    assert (
        h.iterations[1].failed
        and "exploded" in h.iterations[1].failed
        and h.iterations[1].loss == FAILED_LOSS
    )
    assert h.iterations[2].failed is None and len(est.steps) == 3


class PerObject(Scripted):
    per_object: ClassVar[bool] = True


def test_per_object_estimators_get_each_unknown_body_marked() -> None:
    t = toy_task(("mass",), seed=1)
    est = PerObject([{"a.mass": 3.0, "b.mass": 3.0}])
    h = _run(est, iterations=2, seed=1)
    assert h.meta["per_object"] is True
    assert set(est.task.marked_observation) == {"a", "b"}  # type: ignore[union-attr]
    for step in est.steps:
        assert set(step.marked) == {"a", "b"}
        assert step.marked["a"][:, 1].sum() > 0 and step.frames[:, 1].sum() == 0
    with pytest.raises(ObservationError, match="no marked frames for a, b"):
        _run(PerObject([{"a.mass": 3.0, "b.mass": 3.0}]), obs=Observation(t.observation.frames))


def test_any_number_of_unknown_bodies() -> None:
    from physbench.scene import Body, Circle, Scene, body_unknown

    bodies = tuple(Body(f"b{i}", Circle(0.2), (0.5 + 0.5 * i, 1.0)) for i in range(6))
    scene = Scene(
        "six",
        bodies,
        frames=8,
        unknowns=tuple(body_unknown(b.name, "mass", 1.0, 10.0) for b in bodies),
    )
    space = ParamSpace.from_scene(scene)
    sim, ren = ToySimulator(), ToyRenderer()
    obs = simulate_observation(scene, draw_problem(space, 0)[0], sim, ren)
    h = refine(obs, scene, space, sim, ren, RandomSearch(), iterations=4)
    assert len(h.keys) == 6 and all(len(r.params) == 6 for r in h.iterations)


def test_bouncing_balls_end_to_end_with_six_masses_and_marked_objects() -> None:
    from physbench.components import create
    from physbench.scenes import bouncing_balls

    scene = bouncing_balls.generate(0, n_balls=6)
    space = ParamSpace.from_scene(scene, ["mass"])
    sim, ren = create("simulator", "pymunk"), create("renderer", "raster", resolution=32)
    truth, _ = draw_problem(space, 0)
    obs = simulate_observation(scene, truth, sim, ren, marked=space.bodies)
    est = PerObject([space.sample(np.random.default_rng(1))])
    h = refine(obs, scene, space, sim, ren, est, iterations=2)
    assert est.task is not None
    assert len(space) == 6 and set(est.task.marked_observation) == set(space.bodies)
    step = est.steps[-1]
    assert len(step.marked) == 6
    assert all(f[:, 1].max() > 0.5 for f in step.marked.values())  # the marked ball is in channel 1
    assert h.iterations[0].nmse is not None and h.iterations[1].params == est.points[0]


def test_an_estimate_at_an_end_of_its_range_is_flagged() -> None:
    from physbench.components import create
    from physbench.render.raster import RasterRenderer
    from physbench.scenes.generator import resolve_scene

    scene = resolve_scene("three_circles", 0)
    space = ParamSpace.from_scene(scene, ("mass",))
    obs = simulate_observation(
        scene,
        space.sample(np.random.default_rng(0)),
        create("simulator", "pymunk"),
        RasterRenderer(resolution=32),
    )
    (a, b), ranges = space.keys, space.unknowns
    at_edge = {a: ranges[0].high, b: 0.5 * (ranges[1].low + ranges[1].high)}
    history = refine(
        obs,
        scene,
        space,
        create("simulator", "pymunk"),
        RasterRenderer(resolution=32),
        create("estimator", "random"),
        iterations=1,
        initial=at_edge,
    )
    assert history.at_bound == (a,)
    assert History.from_dict(history.to_dict()).at_bound == (a,)
    assert space.at_bound({a: ranges[0].low, b: ranges[1].high}) == (a, b)
    inside = {a: ranges[0].low + 0.01 * (ranges[0].high - ranges[0].low), b: at_edge[b]}
    assert space.at_bound(inside) == ()


def test_a_fit_far_above_the_noise_floor_is_flagged_one_at_the_floor_is_not() -> None:
    from physbench.render.sensor import SensorModel

    t = toy_task(("mass",), seed=0)
    truth = dict(t.observation.truth or {})
    noisy = simulate_observation(
        t.scene, truth, t.simulator, t.renderer, sensor=SensorModel(noise=0.02, seed=0)
    )
    good = _run(Scripted([truth]), iterations=3, obs=noisy)
    assert good.fit is not None and good.fit.noise_ratio == pytest.approx(1.0, abs=0.1)
    assert not good.fit.failed and good.fit.describe() is None
    wrong = {"a.mass": 1.0, "b.mass": 10.0}
    bad = _run(Scripted([wrong]), iterations=2, initial=wrong, obs=noisy)  # never near the truth
    assert bad.fit is not None and bad.fit.failed and bad.fit.noise_ratio > 10
    assert (bad.fit.describe() or "").startswith("the fit looks failed: its best image MSE")
    again = History.from_dict(json.loads(bad.to_json()))
    assert again.fit == bad.fit
    # Frames stated noise-free have no noise floor to compare with.
    sharp = simulate_observation(t.scene, truth, t.simulator, t.renderer, sensor=SensorModel())
    clean = _run(Scripted([wrong]), iterations=2, obs=sharp)
    assert clean.fit is not None and clean.fit.noise_floor is None and not clean.fit.failed


def test_a_restart_simulates_design_points_while_the_fit_looks_failed() -> None:
    from physbench.loop import Restart

    t = toy_task(("mass",), seed=0)
    wrong = {"a.mass": 1.0, "b.mass": 10.0}
    sim = CountingSimulator()
    est = Scripted([wrong])  # stuck: proposes the same wrong point for ever
    h = _run(est, iterations=10, sim=sim, initial=wrong, restart=Restart(threshold=1e-12))
    assert h.restarts == (3, 6, 9)  # from iteration `after` on, once every `every` iterations
    for k in range(10):
        moved = sim.calls[k] != wrong
        assert moved == (k in h.restarts), k  # the rest simulate the estimator's proposal
        assert est.steps[k].params == sim.calls[k]  # the estimator sees what was simulated
    assert len({tuple(sim.calls[k].values()) for k in h.restarts}) == 3
    assert all(t.space.contains(sim.calls[k]) for k in h.restarts)
    # A threshold no loss exceeds: the same run as without a restart.
    same = _run(Scripted([wrong]), iterations=10, initial=wrong, restart=Restart(threshold=10.0))
    plain = _run(Scripted([wrong]), iterations=10, initial=wrong)
    assert same.restarts == () and same.to_dict(timings=False) == plain.to_dict(timings=False)
    with pytest.raises(PhysbenchError, match="restart every = 0"):
        Restart(threshold=1.0, every=0)
