"""Training pairs generated on the fly: (p, p') for the unknowns of a random marked object of a
random scene instance, simulated and rendered as the network trains.

A *group* is one scene instance simulated with K random parameter sets; every ordered pair of its
simulations, for every unknown body, is a sample. That reuses each simulation K-1 times per body.
Seeds: training groups use seeds from :data:`TRAIN_SEED0` upward, validation groups from
:data:`VAL_SEED0`; evaluation uses small seeds (0, 1, 2, ...), so the three never meet.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.estimators.resnet3d.inputs import make_input
from physbench.render.base import DEFAULT_RENDERER
from physbench.simulators.base import DEFAULT_SIMULATOR

if TYPE_CHECKING:
    from physbench.scene import Scene

TRAIN_SEED0 = 1 << 24
VAL_SEED0 = 1 << 30


@dataclass(frozen=True)
class DataSpec:
    """What to simulate for training; stored in the weights' sidecar. ``scene``: a registered
    scene generator (a fresh instance per sample group) or a scene TOML file (one instance, only
    the unknowns vary)."""

    scene: str
    params: tuple[str, ...]
    engine: str = DEFAULT_SIMULATOR
    renderer: str = DEFAULT_RENDERER
    renderer_options: dict[str, Any] = field(default_factory=dict)
    render_resolution: int = 64
    resolution: int = 32
    frames: int = 15
    group: int = 4
    scene_options: dict[str, Any] = field(default_factory=dict)
    # Camera-blur augmentation of the *observed* sequence only (the simulated one stays sharp, as
    # at inference): with probability ``blur_prob`` a Gaussian of sigma ~ U(0, blur_max) pixels at
    # the render resolution, the blur of the loop's observation model.
    blur_max: float = 0.0
    blur_prob: float = 0.5
    # Pairs aimed at a later correction: with probability ``near`` a simulation of a group is drawn
    # near another one's parameters (each unknown moved by N(0, ``near_scale``) of its range,
    # clipped), so the group holds pairs as close as the loop's second step sees; 0: every
    # simulation from the prior, as the loop's first step sees them.
    near: float = 0.0
    near_scale: float = 0.05

    def instance(self, seed: int, **options: Any) -> Scene:
        """Called for each sample group, validation group and evaluation run: the scene instance
        ``seed`` (a file's scene for every seed), built with :attr:`scene_options` and
        ``options``."""
        from physbench.errors import PhysbenchError
        from physbench.plugins import get_registry
        from physbench.scene_toml import load_scene
        from physbench.scenes.generator import is_scene_file

        merged = {**self.scene_options, **options}
        if is_scene_file(self.scene):
            if merged:
                raise PhysbenchError(
                    f"scene options {merged} for the scene file {self.scene!r}: a file is one "
                    "instance and takes none; edit the file instead"
                )
            return load_scene(self.scene)
        return get_registry().get("scene", self.scene)(seed, **merged)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["params"] = list(self.params)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> DataSpec:
        """The spec stored in a sidecar; sidecars written before the renderer was a choice lack
        ``renderer`` and ``renderer_options`` and get the defaults, what they were trained on."""
        return cls(**{**d, "params": tuple(d["params"])})


class PairMaker:
    """Builds sample groups for one :class:`DataSpec` (one per worker process)."""

    def __init__(self, spec: DataSpec) -> None:
        from physbench.components import create, make_renderer

        self.spec = spec
        spec.instance(0)  # an unknown name or a bad file fails here, not in a worker
        self.sim = create("simulator", spec.engine)
        self.renderer = make_renderer(
            spec.renderer, spec.renderer_options, resolution=spec.render_resolution, mode="mark"
        )

    def group(self, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Samples ``x (S, 2, 2F, R, R)`` and targets ``y (S, P)`` from the instance ``seed``."""
        from physbench.errors import SimulationError
        from physbench.unknowns import ParamSpace

        spec = self.spec
        scene = spec.instance(seed)
        space = ParamSpace.from_scene(scene, spec.params)
        rng = np.random.default_rng([seed, 7])
        # Per simulation: its parameters and, per unknown body, the frames with that body marked.
        sims: list[tuple[dict[str, float], dict[str, np.ndarray]]] = []
        for _ in range(spec.group * 2):
            if len(sims) == spec.group:
                break
            if sims and self.spec.near > 0 and rng.random() < self.spec.near:
                base = space.to_unit(sims[int(rng.integers(len(sims)))][0])
                moved = base + rng.normal(0.0, self.spec.near_scale, base.shape)
                p = space.from_unit(np.clip(moved, 0.0, 1.0))
            else:
                p = space.sample(rng)
            try:
                traj = self.sim.simulate(scene, p)
            except SimulationError:
                continue
            sims.append((p, {b: self.renderer.render(scene, traj, focus=b) for b in space.bodies}))
        observed = (
            [self._blurred(frames, rng) for _, frames in sims]
            if spec.blur_max > 0
            else [f for _, f in sims]
        )
        pairs = [
            (b, i, j) for b in space.bodies for i in range(len(sims)) for j in range(len(sims))
        ]
        pairs = [(b, i, j) for b, i, j in pairs if i != j]
        subs = {b: space.subset(b) for b in space.bodies}
        xs: np.ndarray | None = None  # allocated once the first sample gives its shape
        ys = []
        for k, (body, i, j) in enumerate(pairs):
            sub = subs[body]
            obs, sim = observed[i][body], sims[j][1][body]
            if xs is None:
                first = make_input(obs, sim, spec.frames, spec.resolution)
                xs = np.empty((len(pairs), *first.shape), np.float32)
                xs[0] = first
            else:
                make_input(obs, sim, spec.frames, spec.resolution, out=xs[k])
            ys.append(
                (sub.to_vector(sims[i][0]) - sub.to_vector(sims[j][0])) / (sub.high - sub.low)
            )
        if xs is None:
            raise ValueError(f"scene instance {seed}: no pair of simulations to train on")
        return xs, np.asarray(ys, dtype=np.float32)

    def _blurred(
        self, frames: dict[str, np.ndarray], rng: np.random.Generator
    ) -> dict[str, np.ndarray]:
        """One simulation's marked views as a blurry camera might see them (one sigma for all)."""
        from physbench.render.sensor import gaussian_blur

        if rng.random() >= self.spec.blur_prob:
            return frames
        sigma = float(rng.uniform(0.0, self.spec.blur_max))
        return {b: gaussian_blur(f, sigma) if sigma > 0 else f for b, f in frames.items()}


def validation_set(spec: DataSpec, groups: int) -> tuple[np.ndarray, np.ndarray]:
    """The fixed, seeded validation set: ``groups`` instances from :data:`VAL_SEED0`."""
    maker = PairMaker(spec)
    parts = [maker.group(VAL_SEED0 + g) for g in range(groups)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def stream(
    spec: DataSpec, start_group: int, worker: int = 0, workers: int = 1, buffer: int = 256
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Endless shuffled samples from training groups ``start_group + worker + k·workers``."""
    maker = PairMaker(spec)
    rng = np.random.default_rng([start_group, worker])
    pool_x: list[np.ndarray] = []
    pool_y: list[np.ndarray] = []
    g = start_group + worker
    while True:
        while len(pool_x) < buffer:
            x, y = maker.group(TRAIN_SEED0 + g)
            g += workers
            pool_x.extend(x)
            pool_y.extend(y)
        # Draw from a shuffle buffer so samples of one instance do not arrive together.
        k = int(rng.integers(len(pool_x)))
        pool_x[k], pool_x[-1] = pool_x[-1], pool_x[k]
        pool_y[k], pool_y[-1] = pool_y[-1], pool_y[k]
        yield pool_x.pop(), pool_y.pop()
