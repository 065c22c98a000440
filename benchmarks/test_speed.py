"""Speed: raw engine stepping vs one full estimation-loop simulation (simulate + render).

``raw`` is ``sim.build(scene)`` and ``(frames - 1) * substeps`` engine steps with the scene's
pushes applied (so the bodies collide as they do in the simulation), nothing else;
``full`` is ``sim.simulate(scene)`` (stepping loop, recording, checks) plus a 64x64
``RasterRenderer`` render. The target is ``full / raw <= 2.5`` (override with
``PHYSBENCH_SPEED_TARGET``). Both are timed interleaved in the same run; the table shows medians
of many repeats and the ratio of both the medians and the fastest runs (the one checked).

    pytest benchmarks/test_speed.py          # pytest-benchmark tables + the ratio table
    python benchmarks/test_speed.py          # the ratio table only
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from physbench.render.raster import RasterRenderer
from physbench.scene import Body, Circle, Scene
from physbench.scenes.bin import bin_walls

TARGET = float(os.environ.get("PHYSBENCH_SPEED_TARGET", "2.5"))
SCENES = ("three_circles", "bouncing_balls")
ENGINES = ("pymunk", "box2d")
BALLS = 6
REPEATS = 60
CASES = [f"{s}-{e}" for s in SCENES for e in ENGINES]


def _stand_in_balls(seed: int, n: int) -> Scene:
    """Used only without ``physbench.scenes.bouncing_balls``: a test ball and n balls, no
    gravity."""
    rng = np.random.default_rng(seed)
    bounds = (0.0, 0.0, 4.0, 4.0)
    bodies = tuple(
        Body(
            f"b{i}",
            Circle(0.2),
            (0.5 + (i % 4) * 1.0, 1.0 + (i // 4) * 1.5),
            velocity=tuple(rng.uniform(-3, 3, 2)),
        )
        for i in range(n + 1)
    )
    return Scene(
        "bouncing_balls",
        bodies,
        bounds=bounds,
        gravity=(0.0, 0.0),
        statics=bin_walls(bounds, ceiling=True),
    )


def load_scene(name: str, seed: int = 0) -> Scene:
    """The scene ``name``; ``bouncing_balls`` with :data:`BALLS` balls besides the test ball."""
    if name == "three_circles":
        from physbench.scenes.three_circles import generate

        return generate(seed)
    try:
        from physbench.scenes.bouncing_balls import generate as balls
    except ImportError:
        return _stand_in_balls(seed, BALLS)
    return balls(seed, n_balls=BALLS)


def make_simulator(engine: str) -> Any:
    if engine == "pymunk":
        from physbench.simulators.pymunk_sim import PymunkSimulator

        return PymunkSimulator()
    from physbench.simulators.box2d_sim import Box2DSimulator

    return Box2DSimulator()


def push_schedule(scene: Scene) -> list[list[tuple[bool, int, float, float]]]:
    """Per substep: (is impulse, body index, x, y) for the scene's forces and impulses, so raw
    stepping moves the bodies as the simulation does (a push changes the contacts, and contacts
    dominate an engine's step cost)."""
    h = scene.dt / scene.substeps
    n_steps = (scene.frames - 1) * scene.substeps
    steps: list[list[tuple[bool, int, float, float]]] = [[] for _ in range(n_steps)]
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    for f in scene.forces:
        if f.kind == "impulse":
            k = max(0, math.ceil(f.start / h - 1e-9))
            if k < n_steps:
                steps[k].append((True, index[f.body], *f.vector))
            continue
        for k in range(max(0, math.floor(f.start / h)), min(n_steps, math.ceil(f.end / h))):
            frac = (min(f.end, (k + 1) * h) - max(f.start, k * h)) / h
            steps[k].append((False, index[f.body], f.vector[0] * frac, f.vector[1] * frac))
    return steps


@dataclass
class Workload:
    """One scene on one engine, with everything each timed job needs."""

    scene: Scene
    sim: Any
    renderer: RasterRenderer

    @classmethod
    def named(cls, name: str) -> Workload:
        """``"<scene>-<engine>"`` -> its workload."""
        scene_name, engine = name.rsplit("-", 1)
        return cls(load_scene(scene_name), make_simulator(engine), RasterRenderer())

    def __post_init__(self) -> None:
        self.pushes = push_schedule(self.scene)

    def build(self) -> None:
        self.sim.build(self.scene)

    def raw(self) -> None:
        scene = self.scene
        world = self.sim.build(scene)
        h = scene.dt / scene.substeps
        step = world.step
        for acts in self.pushes:
            for impulse, i, x, y in acts:
                (world.apply_impulse if impulse else world.apply_force)(i, x, y)
            step(h)

    def simulate(self) -> Any:
        return self.sim.simulate(self.scene)

    def full(self) -> np.ndarray:
        return self.renderer.render(self.scene, self.sim.simulate(self.scene))


def measure(case: str, repeats: int = REPEATS) -> dict[str, float]:
    """Median seconds of build, raw, simulate, render and full, timed interleaved, plus
    ``ratio`` (of the medians) and ``ratio_min`` (of the fastest runs)."""
    c = Workload.named(case)
    traj = c.simulate()
    jobs: dict[str, Callable[[], object]] = {
        "build": c.build,
        "raw": c.raw,
        "simulate": c.simulate,
        "render": lambda: c.renderer.render(c.scene, traj),
        "full": c.full,
    }
    times: dict[str, list[float]] = {k: [] for k in jobs}
    for i in range(repeats + 3):
        for key, job in jobs.items():
            t0 = time.perf_counter()
            job()
            if i >= 3:  # warm-up
                times[key].append(time.perf_counter() - t0)
    m = {k: statistics.median(v) for k, v in times.items()}
    m["ratio"] = m["full"] / m["raw"]
    m["ratio_min"] = min(times["full"]) / min(times["raw"])
    return m


def table(results: dict[str, dict[str, float]]) -> str:
    """Median times in ms: build, step (raw - build), loop overhead (simulate - raw: forces,
    reads, recording, checks), render, raw, full; then full / raw of the medians and of the
    fastest runs."""
    head = (
        f"{'case':<24}{'build':>8}{'step':>8}{'loop+rec':>10}{'render':>8}{'raw':>8}{'full':>8}"
        f"{'full/raw':>10}{'(min)':>7}"
    )
    lines = [head, "-" * len(head)]
    for case, m in results.items():
        ms = {k: v * 1e3 for k, v in m.items()}
        lines.append(
            f"{case:<24}{ms['build']:8.3f}{ms['raw'] - ms['build']:8.3f}"
            f"{ms['simulate'] - ms['raw']:10.3f}{ms['render']:8.3f}{ms['raw']:8.3f}"
            f"{ms['full']:8.3f}{m['ratio']:10.2f}{m['ratio_min']:7.2f}"
        )
    lines.append(
        f"target: full/raw <= {TARGET:g}, checked on the fastest runs (median of {REPEATS} "
        "interleaved repeats; ms)"
    )
    return "\n".join(lines)


# ------------------------------------------------------------------ pytest


@pytest.mark.parametrize("case", CASES)
def test_raw_stepping(benchmark: Any, case: str) -> None:
    c = Workload.named(case)
    benchmark.group = case
    benchmark(c.raw)


@pytest.mark.parametrize("case", CASES)
def test_simulate_and_render(benchmark: Any, case: str) -> None:
    c = Workload.named(case)
    benchmark.group = case
    frames = benchmark(c.full)
    assert frames.shape == c.renderer.shape(c.scene)


def test_full_over_raw_ratio(capsys: pytest.CaptureFixture[str]) -> None:
    """All cases timed in this one test, so the table compares like with like."""
    results = {case: measure(case) for case in CASES}
    text = table(results)
    with capsys.disabled():
        print("\n" + text)
    # Checked on the fastest runs: on a shared machine a preempted call loses a whole scheduler
    # slice (~4 ms, twice a simulation), which inflates medians but never the minimum.
    slow = [case for case, m in results.items() if m["ratio_min"] > TARGET]
    assert not slow, (
        f"simulate+render exceeds {TARGET:g}x raw stepping for {', '.join(slow)}\n{text}"
    )


if __name__ == "__main__":
    print(table({case: measure(case) for case in CASES}))
