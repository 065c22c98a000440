"""The closed-form toy task the estimator kit runs on: no physics engine, 16x16 frames, about
50 µs per simulation. Tests of the loop use it too."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.loop import History, draw_problem, refine
from physbench.observation import Observation, simulate_observation
from physbench.render.base import Renderer, RenderError
from physbench.scene import Body, Circle, Scene, body_unknown
from physbench.simulators.base import Simulator
from physbench.trajectory import Trajectory
from physbench.unknowns import ParamSpace


def toy_scene(frames: int = 12) -> Scene:
    """A test body and two unknown bodies ``a``, ``b`` with mass and elasticity unknown."""
    bodies = (
        Body("test", Circle(0.3), (0.6, 2.0), mass=5.0),
        Body("a", Circle(0.3), (1.6, 1.0)),
        Body("b", Circle(0.3), (2.4, 1.0)),
    )
    unknowns = tuple(
        body_unknown(n, p, lo, hi)
        for n in ("a", "b")
        for p, lo, hi in (("mass", 1.0, 10.0), ("elasticity", 0.1, 1.0))
    )
    return Scene("toy", bodies, frames=frames, unknowns=unknowns, test_body="test")


class ToySimulator(Simulator):
    """Closed-form stand-in for a physics engine: a body's speed falls with its mass and its hop
    height grows with its elasticity. Deterministic, about 50 µs per call."""

    name: ClassVar[str] = "toy"

    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        scene = scene.with_params(params or {})
        t = np.arange(scene.frames) / scene.fps
        states = np.zeros((scene.frames, len(scene.bodies), 6))
        for i, b in enumerate(scene.bodies):
            speed = 0.0 if b.name == scene.test_body else 8.0 / (b.mass + 2.0)
            hop = 0.0 if b.name == scene.test_body else 1.2 * b.elasticity
            states[:, i, 0] = b.position[0] + speed * t
            states[:, i, 1] = b.position[1] + hop * np.sin(np.pi * t / max(t[-1], 1e-9))
            states[:, i, 3] = speed
        return Trajectory(scene.body_names, t, states, engine=self.name)


class ToyRenderer(Renderer):
    """Gaussian blobs on a square image of ``resolution`` pixels; channel 1 holds the ``focus``
    body (the ``mark`` layout, its only mode)."""

    name: ClassVar[str] = "toy"
    modes: ClassVar[tuple[str, ...]] = ("mark",)

    def __init__(self, resolution: int = 16, mode: str = "mark") -> None:
        super().__init__(resolution, mode)
        if not isinstance(self.resolution, int):
            raise RenderError(
                f"resolution = {resolution!r}: the toy renderer draws square images; "
                "give a whole number"
            )
        self.size = self.resolution

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        return (scene.frames if frames is None else frames, 2, self.size, self.size)

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        xmin, ymin, xmax, ymax = scene.bounds
        c = (np.arange(self.size) + 0.5) / self.size
        gx, gy = xmin + c * (xmax - xmin), ymax - c * (ymax - ymin)
        frames = np.zeros((traj.frames, 2, self.size, self.size), np.float32)
        for i, name in enumerate(traj.bodies):
            x, y = traj.states[:, i, 0], traj.states[:, i, 1]
            blob = np.exp(
                -(
                    (gy[None, :, None] - y[:, None, None]) ** 2
                    + (gx[None, None, :] - x[:, None, None]) ** 2
                )
                / 0.18
            )
            ch = 1 if name == focus else 0
            np.maximum(frames[:, ch], blob.astype(np.float32), out=frames[:, ch])
        if out is not None:
            out[...] = frames
            return out
        return frames


@dataclass
class ToyTask:
    scene: Scene
    space: ParamSpace
    simulator: ToySimulator
    renderer: ToyRenderer
    observation: Observation


def toy_task(
    params: Sequence[str] = ("mass",), bodies: Sequence[str] | None = None, *, seed: int = 0
) -> ToyTask:
    """The toy problem for ``seed``: truth from :func:`~physbench.loop.draw_problem`, observation
    simulated and rendered, with marked frames for every unknown body."""
    scene = toy_scene()
    space = ParamSpace.from_scene(scene, params, bodies)
    truth, _ = draw_problem(space, seed)
    sim, ren = ToySimulator(), ToyRenderer()
    obs = simulate_observation(scene, truth, sim, ren, marked=space.bodies)
    return ToyTask(scene, space, sim, ren, obs)


def run_toy(
    cls: type,
    options: Mapping[str, Any],
    *,
    seed: int = 0,
    iterations: int = 8,
    params: Sequence[str] = ("mass",),
    bodies: Sequence[str] | None = None,
) -> History:
    """One small :func:`~physbench.loop.refine` of ``cls(**options)`` on :func:`toy_task`."""
    t = toy_task(params, bodies, seed=seed)
    return refine(
        t.observation,
        t.scene,
        t.space,
        t.simulator,
        t.renderer,
        cls(**options),
        iterations=iterations,
        seed=seed,
    )
