"""The npe estimator: a posterior over the task's unknowns from the marked observation alone,
the median as its first proposal, and its weights found and checked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.components import create, make_renderer  # noqa: E402
from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.base import Step, Task  # noqa: E402
from physbench.estimators.npe import weights  # noqa: E402
from physbench.estimators.npe.estimator import NPEEstimator  # noqa: E402
from physbench.estimators.npe.network import MDNConfig  # noqa: E402
from physbench.estimators.npe.train import NPETrainConfig, train  # noqa: E402
from physbench.estimators.npe.training_data import NPEDataSpec  # noqa: E402
from physbench.loop import draw_problem  # noqa: E402
from physbench.observation import simulate_observation  # noqa: E402
from physbench.scenes import resolve_scene  # noqa: E402
from physbench.unknowns import ParamSpace  # noqa: E402


def _task(seed: int, params: tuple[str, ...] = ("mass",)) -> Task:
    scene = resolve_scene("three_circles", seed)
    space = ParamSpace.from_scene(scene, params)
    truth, initial = draw_problem(space, seed)
    ren = make_renderer("raster", {}, resolution=64, mode="mark")
    obs = simulate_observation(
        scene, truth, create("simulator", "pymunk"), ren, marked=space.bodies
    )
    return Task(scene, space, obs.frames, initial, ren, 11, obs.marked)


@pytest.fixture(scope="module")
def tiny_weights(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A smoke training: 30 simulations, a small two-member ensemble, a few epochs."""
    torch.set_num_threads(1)
    out = tmp_path_factory.mktemp("npe")
    spec = NPEDataSpec("three_circles", ("mass",), frames=6)
    net = MDNConfig(n_features=0, n_params=0, hidden=8, components=2, members=2)
    path, meta = train(spec, net, NPETrainConfig(samples=30, max_epochs=5), out, progress=False)
    assert meta["training"]["train_rows"] == 60  # one row per unknown body of each simulation
    assert np.isfinite(meta["val_nll"])
    return path


def test_posterior_from_the_observation_alone(tiny_weights: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    task = _task(3)

    def no_simulation(*args: object, **kwargs: object) -> None:
        raise AssertionError("npe simulated")

    monkeypatch.setattr(type(create("simulator", "pymunk")), "simulate", no_simulation)
    est = NPEEstimator(weights=str(tiny_weights), samples=500, refine=False)
    assert est.posterior() is None
    est.start(task, seed=0)
    post = est.posterior()
    assert post is not None and post.method == "npe" and len(post) == 500
    assert post.keys == task.space.keys == ("a.mass", "b.mass")
    assert (post.samples >= task.space.low).all() and (post.samples <= task.space.high).all()
    # Each body's column comes from its own marked view: different views, different draws.
    assert not np.allclose(np.sort(post.samples[:, 0]), np.sort(post.samples[:, 1]))
    step = Step(0, dict(task.initial), task.observation, 1.0, None, task.marked_observation)
    assert est.propose(step) == pytest.approx(post.median())
    assert est.propose(step) == pytest.approx(post.median())  # refine=False: the median again
    # Same seed, same posterior.
    again = NPEEstimator(weights=str(tiny_weights), samples=500, refine=False)
    again.start(task, seed=0)
    np.testing.assert_array_equal(again.posterior().samples, post.samples)  # type: ignore[union-attr]


def test_later_proposals_hand_over_to_resnet3d() -> None:
    task = _task(4)
    est = NPEEstimator(samples=200)  # shipped npe and resnet3d weights for three_circles mass
    est.start(task, seed=0)
    post = est.posterior()
    assert post is not None
    median = post.median()
    first = est.propose(Step(0, dict(task.initial), task.observation, 1.0, None, {}))
    assert first == pytest.approx(median)
    sim = create("simulator", "pymunk")
    ren = make_renderer("raster", {}, resolution=64, mode="mark")
    traj = sim.simulate(task.scene, first)
    marked = {b: ren.render(task.scene, traj, focus=b) for b in task.space.bodies}
    second = est.propose(Step(1, first, ren.render(task.scene, traj), 0.0, traj, marked))
    assert second != pytest.approx(first)  # resnet3d's correction, not the median again
    assert task.space.contains(second)


def test_weights_for_another_range_or_unknown_set_are_refused(tiny_weights: Path) -> None:
    from dataclasses import replace

    task = _task(5)
    narrow = task.space.unknowns[0]
    task.space = ParamSpace((replace(narrow, high=6.0), *task.space.unknowns[1:]))
    with pytest.raises(PhysbenchError, match=r"trained for mass in \[2.0, 8.0\]"):
        NPEEstimator(weights=str(tiny_weights)).start(task, seed=0)
    with pytest.raises(PhysbenchError, match="trained for mass, the task asks for elasticity"):
        NPEEstimator(weights=str(tiny_weights)).start(_task(5, ("elasticity",)), seed=0)
    with pytest.raises(PhysbenchError, match="no npe weights for scene 'three_circles'"):
        weights.find("three_circles", ("friction",))


def test_shipped_weights_cover_three_table1_rows() -> None:
    for scene, params in (
        ("three_circles", ("mass",)),
        ("three_circles", ("elasticity",)),
        ("second_order", ("mass",)),
    ):
        members, meta = weights.load(weights.find(scene, params))
        assert meta["kind"] == "npe" and len(members) == meta["net"]["members"]
