"""ball_drop: the data's units (15 fps, drops from 45.5-49.5 m), each ball's mass and radius
from the data set's table, free fall in the engine, and an unknown ball refused."""

from __future__ import annotations

import math

import pytest

from physbench.scenes import ball_drop
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_matches_data_units() -> None:
    scene = ball_drop.generate(0, ball="baseball")
    mass, radius = ball_drop.ball_properties("baseball")
    assert scene.fps == 15.0 and scene.frames / scene.fps >= 3.6  # the longest drop lasts 3.6 s
    assert math.isclose(mass, 5 * 0.0283495) and math.isclose(radius, 0.2225 / (2 * math.pi))
    assert 45.5 <= scene.bodies[0].position[1] <= 49.5
    traj = PymunkSimulator().simulate(scene)
    y = traj.body("ball")[:, 1]
    t = 30 / scene.fps  # free fall; semi-implicit Euler falls (n+1)/n too far after n substeps
    assert math.isclose(y[0] - y[30], 0.5 * 9.81 * t**2, rel_tol=5e-3)


def test_the_unknown_mass_spans_half_to_twice_the_weighed_mass() -> None:
    scene = ball_drop.generate(2, ball="tennis_ball", height=30.0, velocity=1.5)
    mass, radius = ball_drop.ball_properties("tennis_ball")
    (u,) = scene.unknowns
    assert (u.key, u.low, u.high) == ("ball.mass", 0.5 * mass, 2.0 * mass)
    ball = scene.bodies[0]
    assert (ball.mass, ball.shape.radius) == (mass, radius)
    assert ball.position == (0.0, 30.0) and ball.velocity == (0.0, 1.5)
    assert scene.meta == {"seed": 2, "ball": "tennis_ball"}
    with pytest.raises(ValueError, match="ball = 'volleyball': expected one of baseball, "):
        ball_drop.generate(0, ball="volleyball")
