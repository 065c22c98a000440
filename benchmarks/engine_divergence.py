"""Engine divergence: the paper scenes simulated in pymunk and Box2D with the same parameters.

For each scene and seed, the unknown parameters are drawn uniformly from their ranges (seeded), the
scene is simulated in both engines, and the two trajectories are compared:

* final-position difference per body (m): mean and max over bodies and seeds;
* trajectory difference: max over frames of the per-body distance (m);
* qualitative outcome (:func:`same_outcome`): which bodies moved, their order along x at the end.

    python benchmarks/engine_divergence.py [--seeds 10] [--scenes three_circles,...]

Prints a table (the numbers in docs/engines.md come from it). ``tests/simulators/test_simulators.py`` imports
:func:`compare` and :func:`outcome` for its paper-scene test.
"""

from __future__ import annotations

import argparse
import importlib
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from physbench.scene import Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory

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
    travel: dict[str, float]  # farthest each body got from its start (m)
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
    scene: str
    seed: int
    final_diff: np.ndarray  # (N,) m
    path_diff: np.ndarray  # (N,) max over frames, m
    same: bool
    seconds: dict[str, float]


def compare(name: str, seed: int, *, velocity_threshold: float = 0.0) -> Comparison | None:
    """pymunk (with ``velocity_threshold``) against Box2D on one scene and seed."""
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
    """One engine against itself with the first body's start moved ``shift`` m along x: how
    chaotic the scene is, the yardstick for the divergence between engines."""
    scene = paper_scene(name, seed)
    if scene is None:
        return None
    sim = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}[engine]()
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


def _row(label: str, rows: list[Comparison]) -> str:
    final = np.concatenate([c.final_diff for c in rows])
    path = np.concatenate([c.path_diff for c in rows])
    same = sum(c.same for c in rows)
    return (
        f"{label:24s} {final.mean():7.3f} {np.quantile(final, 0.9):7.3f} {final.max():7.3f} "
        f"{path.max():7.3f} {same:>5d}/{len(rows):<3d}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    runs: dict[str, Callable[[str, int], Comparison | None]] = {
        "pymunk vs box2d": compare,
        "pymunk(thr=1) vs box2d": lambda n, s: compare(n, s, velocity_threshold=1.0),
        "pymunk vs pymunk+1mm": lambda n, s: sensitivity(n, s, "pymunk"),
        "box2d vs box2d+1mm": lambda n, s: sensitivity(n, s, "box2d"),
    }
    print("final-position difference per body (m) over seeds: mean, 90th percentile, max;")
    print("path: max over frames; same: seeds with the same qualitative outcome\n")
    header = (
        f"{'scene / comparison':24s} {'mean':>7s} {'p90':>7s} {'max':>7s} {'path':>7s} {'same':>9s}"
    )
    for name in args.scenes.split(","):
        results = {
            label: [c for s in range(args.seeds) if (c := fn(name, s)) is not None]
            for label, fn in runs.items()
        }
        if not results["pymunk vs box2d"]:
            print(f"{name}: scene not available\n")
            continue
        base = results["pymunk vs box2d"]
        ms = {e: 1e3 * float(np.median([c.seconds[e] for c in base])) for e in ("pymunk", "box2d")}
        print(
            f"{name} ({len(base)} seeds; median simulate {ms['pymunk']:.1f} ms pymunk, {ms['box2d']:.1f} ms box2d)"
        )
        print(header)
        for label, rows in results.items():
            print(_row(label, rows))
        worst = max(base, key=lambda c: c.final_diff.max())
        print(f"worst seed {worst.seed}: per body {np.round(worst.final_diff, 3).tolist()}")
        print("outcome differs for seeds:", [c.seed for c in base if not c.same] or "none", "\n")


if __name__ == "__main__":
    main()
