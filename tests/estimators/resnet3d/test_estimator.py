"""The estimator in the loop: shipped weights beat random search, the symmetric option."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.errors import PhysbenchError  # noqa: E402
from physbench.estimators.resnet3d import weights  # noqa: E402
from physbench.estimators.resnet3d.training_data import DataSpec  # noqa: E402


def shipped() -> list[weights.WeightsInfo]:
    return [w for w in weights.available() if w.path.parent == weights.SHIPPED]


@pytest.mark.parametrize("info", shipped(), ids=lambda w: f"{w.scene}-{'+'.join(w.params)}")
def test_shipped_weights_beat_the_random_estimator(info: weights.WeightsInfo) -> None:
    from physbench.components import create
    from physbench.estimators.random_search import RandomSearch
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.plugins import get_registry
    from physbench.unknowns import ParamSpace

    spec = DataSpec.from_dict(info.meta["data"])
    gen = get_registry().get("scene", spec.scene)
    sim, renderer = create("simulator", "pymunk"), create("renderer", "raster", resolution=64)
    learned, baseline = [], []
    for seed in range(4):
        scene = gen(seed, **spec.scene_options)
        space = ParamSpace.from_scene(scene, spec.params)
        truth, initial = draw_problem(space, seed)
        obs = simulate_observation(scene, truth, sim, renderer, marked=space.bodies)
        for est, out in (
            (ResNet3DEstimator(weights=str(info.path)), learned),
            (RandomSearch(), baseline),
        ):
            h = refine(
                obs, scene, space, sim, renderer, est, iterations=3, seed=seed, initial=initial
            )
            out.append(h.best_nmse)
    assert np.mean(learned) < np.mean(baseline), (learned, baseline)


@pytest.mark.parametrize("symmetric", [False, True])
def test_symmetric_option_makes_the_truth_an_exact_fixed_point(symmetric: bool) -> None:
    from physbench.components import create
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.plugins import get_registry
    from physbench.unknowns import ParamSpace

    scene = get_registry().get("scene", "three_circles")(3)
    space = ParamSpace.from_scene(scene, ("mass",))
    truth, _ = draw_problem(space, 3)
    sim, renderer = create("simulator", "pymunk"), create("renderer", "raster", resolution=64)
    obs = simulate_observation(scene, truth, sim, renderer, marked=space.bodies)
    # Started at the truth, the simulated frames equal the observed ones.
    h = refine(
        obs,
        scene,
        space,
        sim,
        renderer,
        ResNet3DEstimator(symmetric=symmetric),
        iterations=2,
        seed=3,
        initial=truth,
    )
    moved = max(abs(h.iterations[1].params[k] - truth[k]) for k in truth)
    if symmetric:
        assert moved < 1e-9  # f(o, s) - f(s, o) vanishes when o == s
    else:
        assert moved > 1e-6  # the plain network has a small bias at zero difference


def test_weights_refuse_frames_of_another_renderer(squares_renderer) -> None:  # type: ignore[no-untyped-def]
    from physbench.experiment import RunConfig, run_config

    config = RunConfig(estimator="resnet3d", renderer="squares", iterations=2, resolution=32)
    with pytest.raises(PhysbenchError, match=r"trained on frames of renderer 'raster'.*'squares'"):
        run_config(config)
    accepted = run_config(RunConfig(**{**config.__dict__, "options": {"any_renderer": True}}))
    assert accepted.meta["renderer"] == "squares" and len(accepted) == 2


def test_posterior_samples_give_a_dropout_posterior_around_the_last_correction() -> None:
    from physbench.components import create
    from physbench.estimators.options import EstimatorOptionError
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.plugins import get_registry
    from physbench.unknowns import ParamSpace

    scene = get_registry().get("scene", "three_circles")(2)
    space = ParamSpace.from_scene(scene, ("mass",))
    truth, initial = draw_problem(space, 2)
    sim, renderer = create("simulator", "pymunk"), create("renderer", "raster", resolution=64)
    obs = simulate_observation(scene, truth, sim, renderer, marked=space.bodies)

    def run(**options: object):  # type: ignore[no-untyped-def]
        est = ResNet3DEstimator(**options)  # type: ignore[arg-type]
        return refine(obs, scene, space, sim, renderer, est, iterations=4, seed=2, initial=initial)

    assert run().posterior is None  # off by default: a point only
    h = run(posterior_samples=32)
    p = h.posterior
    assert p is not None and len(p) == 32 and p.keys == space.keys
    spread = p.samples.std(axis=0)
    assert (spread > 0).all()  # dropout on: the passes differ
    # Centred on the correction of the last iterate, far narrower than the range.
    assert max(p.width_ratio().values()) < 0.2
    with pytest.raises(EstimatorOptionError, match="posterior_samples"):
        ResNet3DEstimator(posterior_samples=-1)
