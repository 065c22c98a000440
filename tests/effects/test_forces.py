"""A constant force and a table tilt give a parabola, in both engines."""

from __future__ import annotations

import pytest

from physbench.effects import (
    ConstantForce,
    TableTilt,
)


@pytest.mark.parametrize("effect", [ConstantForce(fx=0.3, fy=-0.2), TableTilt(ax=0.15, ay=-0.1)])
def test_constant_force_and_tilt_give_a_parabola(
    effect, run_both, assert_engines_agree, assert_pose, ball_scene
):
    m = 2.0
    acc = (0.15, -0.1)  # both effects: F/m = (0.15, -0.1) for m = 2
    scene = ball_scene(seconds=2.0, mass=m)
    trajs = run_both(scene, lambda: [type(effect)(**effect.values)])
    t = trajs[0].times
    for tr in trajs:
        assert_pose(tr, scene, 0, 1.0 + 0.5 * acc[0] * t**2, 1e-5)
        assert_pose(tr, scene, 1, 1.0 + 0.5 * acc[1] * t**2, 1e-5)
    assert_engines_agree(trajs)
