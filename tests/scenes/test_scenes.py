"""What holds for every built-in scene: registered, valid, simulable in both engines, exact TOML
round trip, seeded, and observable (what one scene module promises: tests/scenes/test_<scene>.py).

Observability (a design requirement of the paper scenes, cf. the paper's Fig. 4), for seeds 0-9
with true parameters drawn from the scene's ranges (``ParamSpace.sample``), in both engines:

1. every body with an unknown parameter moves clearly: its centre's largest distance from where it
   started is at least ``MIN_DISPLACEMENT`` (0.3 m, about 5 pixels of the 64-pixel image of a 4 m
   world);
2. moving any one unknown 10 % off its true value (down and up; up is skipped where it would be
   physically invalid, e.g. elasticity > 1) changes the rendered video by at least
   ``MIN_PIXEL_CHANGE`` (20) in the sum over frames, channels and pixels of ``|Δframe|``: the
   64 x 64 raster renderer, default ``"mark"`` mode, focus on the changed body. A prototype bin gave
   0-4 for an unidentifiable mass and 30-400 for identifiable ones; 20 lies between.

Run ``python tests/scenes/test_scenes.py`` to print the measured minima for docs/scenes.md.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from physbench.errors import SimulationError
from physbench.render.raster import RasterRenderer
from physbench.scene import BODY_PARAMS, Scene
from physbench.scene_toml import dumps_scene, loads_scene
from physbench.scenes import (
    ball_drop,
    bouncing_balls,
    pendulum,
    second_order,
    stacked_boxes,
    three_circles,
)
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.unknowns import ParamSpace

SEEDS = range(10)
MIN_DISPLACEMENT = 0.3  # m
MIN_PIXEL_CHANGE = 20.0  # summed |Δframe| at 64 x 64
RESOLUTION = 64
ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}

#: (case id, generator, keyword arguments) of the paper scenes checked for observability.
PAPER: list[tuple[str, Callable[..., Scene], dict[str, Any]]] = [
    ("three_circles", three_circles.generate, {}),
    ("second_order", second_order.generate, {}),
    ("stacked_boxes", stacked_boxes.generate, {}),
    ("bouncing_balls", bouncing_balls.generate, {}),
    ("bouncing_balls[n=2]", bouncing_balls.generate, {"n_balls": 2}),
    ("bouncing_balls[n=6]", bouncing_balls.generate, {"n_balls": 6}),
]
#: Every built-in generator with the variants worth building.
ALL = [
    *PAPER,
    ("pendulum", pendulum.generate, {}),
    ("pendulum[benard]", pendulum.generate, {"rig": "benard"}),
    ("ball_drop", ball_drop.generate, {}),
    ("ball_drop[whiffle]", ball_drop.generate, {"ball": "whiffle_ball_1"}),
]
CASES = {cid: (gen, kw) for cid, gen, kw in ALL}
PAPER_IDS = [cid for cid, _, _ in PAPER]
ALL_IDS = list(CASES)


def make(cid: str, seed: int) -> Scene:
    gen, kw = CASES[cid]
    return gen(seed, **kw)


def truth(scene: Scene, seed: int) -> dict[str, float]:
    """The seed's true parameters: one uniform draw inside the scene's ranges."""
    return ParamSpace.from_scene(scene).sample(np.random.default_rng(seed))


def perturbed(key: str, value: float) -> list[float]:
    """``value`` 10 % down and 10 % up, keeping only physically valid values."""
    lo, hi = BODY_PARAMS[key.rpartition(".")[2]]
    return [v for v in (0.9 * value, 1.1 * value) if lo < v <= hi]


@functools.cache
def observability(cid: str, engine: str) -> dict[str, Any]:
    """``(seed, value)`` lists: max displacement of each unknown body, min pixel change of each
    unknown (bodies and unknowns vary with the seed in ``bouncing_balls``)."""
    sim = ENGINES[engine]()
    renderer = RasterRenderer(resolution=RESOLUTION)
    disp: dict[str, list[tuple[int, float]]] = {}
    pix: dict[str, list[tuple[int, float]]] = {}
    for seed in SEEDS:
        scene = make(cid, seed)
        space = ParamSpace.from_scene(scene)
        p = truth(scene, seed)
        base = sim.simulate(scene, p)
        for body in space.bodies:
            xy = base.body(body)[:, :2]
            disp.setdefault(body, []).append(
                (seed, float(np.linalg.norm(xy - xy[0], axis=1).max()))
            )
        for u in space.unknowns:
            ref = renderer.render(scene, base, focus=u.owner)
            changes = []
            for v in perturbed(u.key, p[u.key]):
                frames = renderer.render(scene, sim.simulate(scene, {**p, u.key: v}), focus=u.owner)
                changes.append(float(np.abs(frames - ref).sum()))
            pix.setdefault(u.key, []).append((seed, min(changes)))
    return {"disp": disp, "pix": pix}


# ------------------------------------------------------------------ every scene


def test_registered() -> None:
    from physbench.plugins import get_registry

    names = set(get_registry().names("scene"))
    for name in (
        "three_circles",
        "second_order",
        "stacked_boxes",
        "bouncing_balls",
        "pendulum",
        "ball_drop",
    ):
        assert name in names
        gen = get_registry().get("scene", name)
        assert gen.name == name and gen.description
        assert gen(0).name == name


@pytest.mark.parametrize("cid", ALL_IDS)
def test_valid_roundtrip_seeded(cid: str) -> None:
    scenes = [make(cid, seed) for seed in SEEDS]
    for seed, scene in zip(SEEDS, scenes, strict=True):
        scene.validate()
        assert loads_scene(dumps_scene(scene)) == scene
        assert make(cid, seed) == scene  # same seed, same scene
        assert scene.unknowns and not any(u.owner == scene.test_body for u in scene.unknowns)
        for u in scene.unknowns:  # nominal values lie inside the declared ranges
            b = scene.bodies[scene.body_index(u.owner)]
            value = b.inertia() if u.name == "moment" else getattr(b, u.name)
            assert u.low <= value <= u.high, u.key
    assert len({dumps_scene(s) for s in scenes}) == len(scenes)  # different seeds, different scenes


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("cid", ALL_IDS)
def test_simulates_without_explosion(cid: str, engine: str) -> None:
    sim = ENGINES[engine]()
    seeds = SEEDS if cid in PAPER_IDS else range(3)  # the real-data scenes are long; 3 seeds do
    for seed in seeds:
        scene = make(cid, seed)
        for params in ({}, truth(scene, seed)):
            try:
                traj = sim.simulate(scene, params)
            except SimulationError as exc:  # pragma: no cover - the failure message
                pytest.fail(f"{cid} seed {seed} {params}: {exc}")
            assert traj.states.shape == (scene.frames, len(scene.bodies), 6)
            assert np.isfinite(traj.states).all()


# ------------------------------------------------------------------ observability


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("cid", PAPER_IDS)
def test_unknown_bodies_move_clearly(cid: str, engine: str) -> None:
    disp = observability(cid, engine)["disp"]
    bad = [
        (body, seed, round(d, 3))
        for body, ds in disp.items()
        for seed, d in ds
        if d < MIN_DISPLACEMENT
    ]
    assert not bad, (
        f"{cid}/{engine}: (body, seed, displacement m) below {MIN_DISPLACEMENT} m: {bad}"
    )


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("cid", PAPER_IDS)
def test_ten_percent_changes_the_video(cid: str, engine: str) -> None:
    pix = observability(cid, engine)["pix"]
    bad = [
        (key, seed, round(c, 1))
        for key, cs in pix.items()
        for seed, c in cs
        if c < MIN_PIXEL_CHANGE
    ]
    assert not bad, f"{cid}/{engine}: (unknown, seed, pixel change) below {MIN_PIXEL_CHANGE}: {bad}"


if __name__ == "__main__":  # print the measured minima (docs/scenes.md)
    for cid in PAPER_IDS:
        for engine in ENGINES:
            res = observability(cid, engine)
            moves = ", ".join(f"{b} {min(d for _, d in ds):.2f}" for b, ds in res["disp"].items())
            pixels = ", ".join(f"{k} {min(c for _, c in cs):.0f}" for k, cs in res["pix"].items())
            print(f"{cid} | {engine} | {moves} | {pixels}")
