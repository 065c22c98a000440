"""The closed-form toy task: its scene, a simulator whose speeds and hops follow the documented
formulas, a blob renderer with the ``mark`` layout, the task with its marked frames, and
``run_toy``'s short refine."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.estimators.random_search import RandomSearch
from physbench.loop import draw_problem
from physbench.render.base import RenderError
from physbench.simulators.base import Simulator
from physbench.testing import (
    ConformanceError,
    ToyRenderer,
    ToySimulator,
    checks_for,
    run_toy,
    toy_scene,
    toy_task,
)


def test_the_scene_has_a_test_body_and_two_bodies_with_mass_and_elasticity_unknown() -> None:
    scene = toy_scene(frames=5).validate()
    assert scene.body_names == ("test", "a", "b") and scene.test_body == "test"
    assert scene.frames == 5 and toy_scene().frames == 12
    assert [(u.key, u.low, u.high) for u in scene.unknowns] == [
        ("a.mass", 1.0, 10.0),
        ("a.elasticity", 0.1, 1.0),
        ("b.mass", 1.0, 10.0),
        ("b.elasticity", 0.1, 1.0),
    ]


def test_speed_falls_with_mass_and_the_hop_grows_with_elasticity() -> None:
    scene = toy_scene(frames=31)  # 1 s at 30 fps
    traj = ToySimulator().simulate(scene, {"a.mass": 6.0, "b.elasticity": 0.5})
    assert traj.engine == "toy" and traj.bodies == scene.body_names
    assert np.allclose(traj.times, np.arange(31) / 30)
    a, b, test = traj.body("a"), traj.body("b"), traj.body("test")
    # speed 8 / (mass + 2): a (mass 6) 1 m/s, b (the default mass 1) 8/3 m/s
    assert np.allclose(a[:, 3], 1.0) and np.allclose(a[:, 0], 1.6 + traj.times)
    assert np.allclose(b[:, 3], 8 / 3)
    # hop 1.2 x elasticity at mid-run: b (0.5) 0.6 m up, a (the default 0.5) as much
    assert b[15, 1] == pytest.approx(1.0 + 0.6) and b[-1, 1] == pytest.approx(1.0)
    assert np.allclose(test, test[0]) and tuple(test[0, :2]) == (0.6, 2.0)  # never moves


def test_the_simulator_is_deterministic() -> None:
    scene, params = toy_scene(), {"a.mass": 3.0, "b.mass": 7.0}
    one, two = ToySimulator().simulate(scene, params), ToySimulator().simulate(scene, params)
    assert np.array_equal(one.states, two.states)


def test_the_toy_simulator_is_a_simulator_but_not_physics() -> None:
    # The closed-form stand-in of the estimator kit is typed as a Simulator, and the simulator
    # kit says plainly why it is not an engine.
    from physbench.testing.simulators import check_free_fall

    assert issubclass(ToySimulator, Simulator)
    assert checks_for(ToySimulator)[0].name == "check_protocol"
    with pytest.raises(ConformanceError, match="free fall"):
        check_free_fall(ToySimulator)


def test_the_renderer_draws_blobs_with_the_focus_body_in_channel_1() -> None:
    scene = toy_scene(frames=3)
    traj = ToySimulator().simulate(scene)
    ren = ToyRenderer(resolution=9)
    assert ToyRenderer.modes == ("mark",) and ren.shape(scene) == (3, 2, 9, 9)
    assert ren.shape(scene, frames=7) == (7, 2, 9, 9)
    frames = ren.render(scene, traj, focus="a")
    assert frames.shape == (3, 2, 9, 9) and frames.dtype == np.float32
    assert frames.min() >= 0.0 and frames.max() <= 1.0
    # channel 1 holds a alone: at x 1.6 m, y 1.0 m of a 4 m world, in pixels of 4/9 m the
    # nearest pixel centre is column 3 (1.56 m), row 6 (1.11 m up)
    row, col = np.unravel_index(frames[0, 1].argmax(), (9, 9))
    assert (row, col) == (6, 3)
    unfocused = ren.render(scene, traj)
    assert not unfocused[:, 1].any()
    assert np.array_equal(unfocused[:, 0], np.maximum(frames[:, 0], frames[:, 1]))
    out = np.full((3, 2, 9, 9), 7.0, np.float32)
    assert ren.render(scene, traj, focus="a", out=out) is out and np.array_equal(out, frames)


def test_the_renderer_refuses_non_square_images() -> None:
    with pytest.raises(RenderError, match=r"resolution = \(8, 4\): the toy renderer draws square"):
        ToyRenderer(resolution=(8, 4))


def test_the_task_observes_the_seeds_truth_with_every_unknown_body_marked() -> None:
    t = toy_task(("mass",), seed=3)
    assert t.space.keys == ("a.mass", "b.mass")
    assert t.observation.truth == draw_problem(t.space, 3)[0]
    assert t.observation.frames.shape == (12, 2, 16, 16)
    assert set(t.observation.marked) == {"a", "b"}
    assert t.observation.marked["a"][:, 1].max() > 0.5  # a drawn in the marked channel
    assert toy_task(("elasticity",), ("b",)).space.keys == ("b.elasticity",)


def test_run_toy_is_a_short_seeded_refine() -> None:
    h = run_toy(RandomSearch, {}, seed=4, iterations=5, params=("mass", "elasticity"))
    assert len(h) == 5 and h.estimator == "random" and h.seed == 4
    assert h.keys == ("a.mass", "a.elasticity", "b.mass", "b.elasticity")
    again = run_toy(RandomSearch, {}, seed=4, iterations=5, params=("mass", "elasticity"))
    assert again.to_dict(timings=False) == h.to_dict(timings=False)
