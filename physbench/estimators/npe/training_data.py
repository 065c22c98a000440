"""Training pairs (summary features, the body's unknowns in unit space): a fresh scene instance
per simulation, its unknowns drawn from the prior (uniform on their ranges), simulated and rendered
once per unknown body with that body marked, noise-free (the Table 1 observation).

Seeds as resnet3d's (:mod:`physbench.estimators.resnet3d.training_data`): training instances from
``TRAIN_SEED0``, validation from ``VAL_SEED0``, evaluation and the benchmark's rows from small
seeds (0, 1, 2, ...), so none of them meet.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.estimators.npe.features import summarize
from physbench.estimators.resnet3d.training_data import TRAIN_SEED0, VAL_SEED0

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.unknowns import ParamSpace

__all__ = ["TRAIN_SEED0", "VAL_SEED0", "NPEDataSpec", "simulate_pairs"]


@dataclass(frozen=True)
class NPEDataSpec:
    """What to simulate; stored in the weights' sidecar. ``frames``: summary frames per view."""

    scene: str
    params: tuple[str, ...]
    engine: str = "pymunk"
    renderer: str = "raster"
    renderer_options: dict[str, Any] = field(default_factory=dict)
    render_resolution: int = 64
    frames: int = 30

    def instance(self, seed: int) -> Scene:
        from physbench.plugins import get_registry

        return get_registry().get("scene", self.scene)(seed)

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "params": list(self.params)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> NPEDataSpec:
        return cls(**{**d, "params": tuple(d["params"])})


def unit_vector(space: ParamSpace, keys: list[str], params: dict[str, float]) -> np.ndarray:
    """``params[keys]`` mapped to the unit interval by their ranges in ``space``."""
    by_key = {u.key: u for u in space.unknowns}
    return np.array([(params[k] - by_key[k].low) / (by_key[k].high - by_key[k].low) for k in keys])


def simulate_pairs(spec: NPEDataSpec, seeds: range) -> tuple[np.ndarray, np.ndarray]:
    """Features ``(N, F)`` and unit targets ``(N, P)``, one row per unknown body of each seed's
    simulation (a simulation that fails is skipped). Called by training for its data sets."""
    from physbench.components import create, make_renderer
    from physbench.errors import SimulationError
    from physbench.unknowns import ParamSpace

    sim = create("simulator", spec.engine)
    renderer = make_renderer(
        spec.renderer, spec.renderer_options, resolution=spec.render_resolution, mode="mark"
    )
    xs, ys = [], []
    for seed in seeds:
        scene = spec.instance(seed)
        space = ParamSpace.from_scene(scene, spec.params)
        truth = space.sample(np.random.default_rng([seed, 11]))
        try:
            traj = sim.simulate(scene, truth)
        except SimulationError:
            continue
        for body in space.bodies:
            keys = [f"{body}.{p}" for p in spec.params]  # the net's output order
            xs.append(summarize(renderer.render(scene, traj, focus=body), spec.frames))
            ys.append(unit_vector(space, keys, truth))
    return np.stack(xs), np.asarray(ys, dtype=np.float32)
