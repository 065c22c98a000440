"""Linear and quadratic drag against their analytic solutions, in both engines."""

from __future__ import annotations

import numpy as np

from physbench.effects import (
    LinearDrag,
    QuadraticDrag,
)

G = 9.81


def test_linear_drag_decays_velocity_exponentially(
    run_both, assert_engines_agree, assert_pose, ball_scene
):
    m, c, v0 = 2.0, 1.0, 3.0
    scene = ball_scene(velocity=(v0, 0.0), mass=m)
    trajs = run_both(scene, lambda: [LinearDrag(c=c)])
    t = trajs[0].times
    for tr in trajs:
        vx = tr.body("ball")[:, 3]
        np.testing.assert_allclose(vx, v0 * np.exp(-c / m * t), rtol=2e-3)
        assert_pose(tr, scene, 0, 1.0 + v0 * m / c * (1 - np.exp(-c / m * t)), 1e-4)
    assert_engines_agree(trajs)


def test_quadratic_drag_reaches_terminal_velocity(
    run_both, assert_engines_agree, assert_pose, ball_scene
):
    m, vt = 0.5, 4.0
    c = m * G / vt**2
    scene = ball_scene(
        gravity=(0.0, -G), seconds=3.0, position=(1.0, 38.0), bounds=(0, 0, 2, 40), mass=m
    )
    trajs = run_both(scene, lambda: [QuadraticDrag(c=c)])
    t = trajs[0].times
    for tr in trajs:
        vy = tr.body("ball")[:, 4]
        np.testing.assert_allclose(vy, -vt * np.tanh(G * t / vt), atol=5e-3 * vt)
        assert_pose(tr, scene, 1, 38.0 - vt**2 / G * np.log(np.cosh(G * t / vt)), 1e-3)
        assert abs(vy[-1] + vt) < 1e-2 * vt  # sqrt(m g / c)
    assert_engines_agree(trajs)
