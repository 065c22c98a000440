"""The Box2D adapter: its documented divergences (velocity threshold, continuous collision) and
limits (polygon vertices)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from physbench.errors import SimulationError
from physbench.scene import (
    Body,
    Box,
    Circle,
    Polygon,
    Scene,
    Segment,
)
from physbench.scenes.bin import bin_walls
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_box2d_velocity_threshold_is_documented_divergence() -> None:
    """Box2D treats impacts below 1 m/s as inelastic (compiled-in ``b2_velocityThreshold``); pymunk
    bounces at any speed unless asked to mimic it. docs/engines.md describes this."""
    drop = 0.03  # impact at 0.77 m/s
    scene = Scene(
        "slow_bounce",
        (Body("ball", Circle(0.1), (2.0, 0.1 + drop), elasticity=1.0),),
        statics=(Segment((0.0, 0.0), (4.0, 0.0), elasticity=1.0),),
        fps=120,
        frames=40,
        substeps=5,
    )
    engines = {"pymunk": PymunkSimulator(), "box2d": Box2DSimulator()}
    rise = {name: sim.simulate(scene).body("ball")[:, 4].max() for name, sim in engines.items()}
    assert rise["pymunk"] > 0.6  # bounced back at ~e · 0.77 m/s
    assert rise["box2d"] < 0.01  # stuck to the floor
    mimic = PymunkSimulator(velocity_threshold=1.0)
    assert mimic.simulate(scene).body("ball")[:, 4].max() < 0.01
    fast = replace(scene, bodies=(replace(scene.bodies[0], position=(2.0, 0.4)),))  # 2.4 m/s
    assert mimic.simulate(fast).body("ball")[:, 4].max() > 2.0  # faster impacts still bounce


def test_fast_bodies_and_ccd() -> None:
    """Box2D (bullets, continuous collision) keeps a 40 m/s box inside the bin; pymunk has no
    continuous collision and lets it tunnel through the wall — reported as an explosion."""
    scene = Scene(
        "fast",
        (Body("b", Box(0.1, 0.1), (2.0, 2.0), velocity=(40.0, 0.0), elasticity=1.0),),
        gravity=(0.0, 0.0),
        statics=bin_walls((0.0, 0.0, 4.0, 4.0)),
        frames=11,
    )
    s = Box2DSimulator().simulate(scene).body("b")
    assert s[-1, 3] == pytest.approx(-40.0, rel=1e-4) and 0 < s[-1, 0] < 4
    with pytest.raises(SimulationError, match="left the world"):
        PymunkSimulator().simulate(scene)


def test_box2d_polygon_vertex_limit_raises() -> None:
    pts = tuple(
        (0.2 * math.cos(2 * math.pi * i / 20), 0.2 * math.sin(2 * math.pi * i / 20))
        for i in range(20)
    )
    scene = Scene("many", (Body("poly", Polygon(pts), (2.0, 2.0)),))
    assert PymunkSimulator().simulate(scene).frames == 30
    with pytest.raises(SimulationError, match="b2_maxPolygonVertices") as info:
        Box2DSimulator().simulate(scene)
    assert info.value.body == "poly" and info.value.frame == 0
