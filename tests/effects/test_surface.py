"""Rolling resistance: uniform deceleration to rest, in both engines."""

from __future__ import annotations

import numpy as np

from physbench.effects import (
    RollingResistance,
)

G = 9.81


def test_rolling_resistance_decelerates_uniformly_and_stops(
    run_both, assert_engines_agree, ball_scene
):
    mu, v0 = 0.005, 0.5
    a = mu * G
    t_stop, dist = v0 / a, v0**2 / (2 * a)  # 10.2 s, 2.55 m
    scene = ball_scene(velocity=(v0, 0.0), seconds=12.0, fps=20)
    trajs = run_both(scene, lambda: [RollingResistance(mu=mu)])
    t = trajs[0].times
    moving = t < t_stop - 0.5
    for tr in trajs:
        vx, x = tr.body("ball")[:, 3], tr.body("ball")[:, 0]
        np.testing.assert_allclose(vx[moving], v0 - a * t[moving], atol=2e-3 * v0)
        assert abs(x[-1] - 1.0 - dist) < 0.01  # stop point within 1 cm
        assert abs(vx[-1]) < 1e-4  # at rest, no chatter
        assert np.all(vx > -1e-6)  # never reverses
    assert_engines_agree(trajs)
