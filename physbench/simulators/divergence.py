"""How far two engines (or one engine from a nudged start) diverge on the same scene.

For a paper scene and seed, the unknown parameters are drawn uniformly from their ranges (seeded),
the scene is simulated in pymunk and in Box2D, and the two trajectories are compared: the
final-position difference per body, the largest difference at any frame, and whether the
qualitative outcome is the same (:func:`same_outcome`). :func:`sensitivity` compares one engine
with itself after moving the first body 1 mm: how chaotic the scene is, the yardstick for the
divergence between engines. ``benchmarks/engine_divergence.py`` prints the table in
docs/engines.md from these.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass, replace

import numpy as np

from physbench.errors import UnknownNameError
from physbench.scene import Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory

#: The paper scenes (modules of :mod:`physbench.scenes`).
SCENES = ("three_circles", "second_order", "stacked_boxes", "bouncing_balls")
#: A body that never gets this far (m) from its start has not moved.
MOVED = 0.05
#: Two bodies closer than this along x (m) at the end have no definite order.
ORDER_MARGIN = 0.1


def paper_scene(name: str, seed: int) -> Scene | None:
    """The built-in scene ``name`` for ``seed`` with its unknowns drawn from their ranges; None
    when the scene module does not exist (yet)."""
    try:
        module = importlib.import_module(f"physbench.scenes.{name}")
    except ModuleNotFoundError:
        return None
    scene: Scene = module.generate(seed)
    rng = np.random.default_rng([seed, 99])
    return scene.with_params({u.key: float(rng.uniform(u.low, u.high)) for u in scene.unknowns})


@dataclass(frozen=True)
class Outcome:
    """What happened in a simulation, qualitatively: how far each body got from its start (m)
    and where each ended along x (m)."""

    travel: dict[str, float]
    final_x: dict[str, float]

    @property
    def moved(self) -> frozenset[str]:
        return frozenset(n for n, d in self.travel.items() if d > MOVED)


def outcome(traj: Trajectory) -> Outcome:
    pos = traj.states[:, :, 0:2]
    travel = np.linalg.norm(pos - pos[0], axis=2).max(axis=0)
    return Outcome(
        travel=dict(zip(traj.bodies, travel.tolist(), strict=True)),
        final_x=dict(zip(traj.bodies, pos[-1, :, 0].tolist(), strict=True)),
    )


def same_outcome(a: Outcome, b: Outcome) -> bool:
    """No body moved (got more than :data:`MOVED` from its start) in one engine and stayed within
    half that in the other, and no two bodies more than :data:`ORDER_MARGIN` apart along x in
    both engines ended in opposite order. Values in between are too close to call."""
    for n in a.travel:
        lo, hi = sorted((a.travel[n], b.travel[n]))
        if hi > MOVED and lo < MOVED / 2:
            return False
    names = list(a.final_x)
    for i, p in enumerate(names):
        for q in names[i + 1 :]:
            da, db = a.final_x[p] - a.final_x[q], b.final_x[p] - b.final_x[q]
            if da * db < 0 and min(abs(da), abs(db)) > ORDER_MARGIN:
                return False
    return True


@dataclass(frozen=True)
class Comparison:
    """Two simulations of one scene and seed compared: per body, the distance between them at
    the end and the largest at any frame (m); whether the outcome is the same; and each engine's
    simulate time (s), when measured."""

    scene: str
    seed: int
    final_diff: np.ndarray  # (N,) m
    path_diff: np.ndarray  # (N,) max over frames, m
    same: bool
    seconds: dict[str, float]


def compare(name: str, seed: int, *, velocity_threshold: float = 0.0) -> Comparison | None:
    """pymunk (with ``velocity_threshold``) against Box2D on one scene and seed; None when the
    scene does not exist."""
    scene = paper_scene(name, seed)
    if scene is None:
        return None
    trajs, secs = {}, {}
    for sim in (PymunkSimulator(velocity_threshold=velocity_threshold), Box2DSimulator()):
        t0 = time.perf_counter()
        trajs[sim.name] = sim.simulate(scene)
        secs[sim.name] = time.perf_counter() - t0
    return _diff(name, seed, trajs["pymunk"], trajs["box2d"], secs)


def sensitivity(name: str, seed: int, engine: str, shift: float = 1e-3) -> Comparison | None:
    """One engine (``pymunk`` or ``box2d``) against itself with the first body's start moved
    ``shift`` m along x: how chaotic the scene is, the yardstick for the divergence between
    engines."""
    engines = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
    if engine not in engines:
        raise UnknownNameError("engine", engine, engines)
    scene = paper_scene(name, seed)
    if scene is None:
        return None
    sim = engines[engine]()
    b0 = scene.bodies[0]
    moved = replace(
        scene,
        bodies=(replace(b0, position=(b0.position[0] + shift, b0.position[1])), *scene.bodies[1:]),
    )
    return _diff(name, seed, sim.simulate(scene), sim.simulate(moved), {})


def _diff(name: str, seed: int, a: Trajectory, b: Trajectory, secs: dict[str, float]) -> Comparison:
    dist = np.linalg.norm(a.states[:, :, 0:2] - b.states[:, :, 0:2], axis=2)  # (T, N)
    return Comparison(
        name, seed, dist[-1], dist.max(axis=0), same_outcome(outcome(a), outcome(b)), secs
    )
