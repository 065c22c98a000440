"""Held-out evaluation of trained weights with the loop's metric (normalized min MSE)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from physbench.simulators.base import DEFAULT_SIMULATOR


def evaluate_weights(
    path: str | Path,
    seeds: Iterable[int],
    *,
    iterations: int = 11,
    engine: str = DEFAULT_SIMULATOR,
    blur: float = 0.0,
    resolution: int = 64,
    scene_options: Mapping[str, Any] | None = None,
    bodies: Sequence[str] | None = None,
) -> list[dict[int, float]]:
    """Per seed: ``{n: normalized min MSE after n iterations}`` for n = 1..iterations.

    Seeds are scene-instance and problem seeds; training and validation use seeds from 2**24 up,
    so small seeds are held out. ``scene_options`` override the training ones (e.g. ``n_balls``);
    ``bodies`` restricts the unknowns to those bodies (the others keep the scene's values).
    """
    from physbench.components import create, make_renderer
    from physbench.estimators.resnet3d import weights
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator
    from physbench.estimators.resnet3d.training_data import DataSpec
    from physbench.loop import draw_problem, refine
    from physbench.observation import simulate_observation
    from physbench.render.sensor import SensorModel
    from physbench.unknowns import ParamSpace

    _, meta = weights.load(path)
    spec = DataSpec.from_dict(meta["data"])
    sim = create("simulator", engine)

    def renderer():  # the renderer the weights were trained on
        return make_renderer(
            spec.renderer, spec.renderer_options, resolution=resolution, mode="mark"
        )

    model, observer = renderer(), renderer()
    sensor = SensorModel(blur=blur)
    rows = []
    for seed in seeds:
        scene = spec.instance(seed, **(scene_options or {}))
        space = ParamSpace.from_scene(scene, spec.params, bodies)
        truth, initial = draw_problem(space, seed)
        obs = simulate_observation(scene, truth, sim, observer, marked=space.bodies, sensor=sensor)
        hist = refine(
            obs,
            scene,
            space,
            sim,
            model,
            ResNet3DEstimator(weights=str(path)),
            iterations=iterations,
            seed=seed,
            initial=initial,
        )
        rows.append(
            {
                r.iteration + 1: float(r.best_nmse)
                for r in hist.iterations
                if r.best_nmse is not None
            }
        )
    return rows
