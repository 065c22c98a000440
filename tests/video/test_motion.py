"""The tracker's motion model from the scene: gravity and forces for a free body, sliding along
static geometry instead of falling through it."""

from __future__ import annotations

import numpy as np

from physbench.scene import Body, Box, Circle, Force, Joint, Scene, Segment, StaticPolygon
from physbench.video.motion import Motion


def _scene(*bodies: Body, **kw) -> Scene:
    return Scene("s", bodies, bounds=(-5.0, -5.0, 5.0, 5.0), **kw)


def test_a_ball_on_a_rail_is_predicted_along_it_not_in_free_fall() -> None:
    ball = Body("ball", Circle(0.05), (0.0, 0.15))
    rail = Segment((-2.0, 0.1), (2.0, 0.1))
    motion = Motion(_scene(ball, statics=(rail,)))
    # A third of a second: free fall would be 0.545 m down, through the rail.
    kick = motion.kick("ball", 0.0, 1 / 3)
    np.testing.assert_allclose(kick.dx, [0.0, -9.81 / 18])
    end, normal = motion.slide(ball, 0.0, np.array([0.0, 0.15]), np.array([0.2, 0.0]) + kick.dx)
    np.testing.assert_allclose(end, [0.2, 0.15], atol=1e-9)  # rolled along, resting on it
    np.testing.assert_allclose(normal, [0.0, 1.0], atol=1e-9)
    # Down a ramp it slides along the ramp; a box rests on its side, not its corner.
    ramp = StaticPolygon(((-2.0, 0.0), (2.0, 0.0), (2.0, 1.0)))
    box = Body("box", Box(0.4, 0.2), (0.0, 0.6), angle=np.arctan2(1.0, 4.0))
    motion = Motion(_scene(box, statics=(ramp,)))
    end, normal = motion.slide(box, box.angle, np.array([0.0, 0.6]), np.array([0.0, -0.3]))
    slope = np.array([4.0, 1.0]) / np.hypot(4.0, 1.0)
    np.testing.assert_allclose(normal, [-slope[1], slope[0]], atol=1e-9)
    surface = np.array([0.0, 0.5])  # the ramp's top face at x = 0
    np.testing.assert_allclose((end - surface) @ normal, 0.1, atol=1e-6)  # half the box's height
    assert end[0] < 0  # and down the slope, not straight down


def test_forces_and_impulses_of_the_scene_are_known_accelerations() -> None:
    ball = Body("ball", Circle(0.05), (0.0, 0.0), mass=2.0)
    arm = Body("arm", Box(0.04, 0.5), (1.0, 0.0))
    push = Force("ball", (4.0, 0.0), 0.0, 0.1)  # 2 m/s² for 0.1 s
    kick = Force("ball", (0.0, 1.0), 0.3, kind="impulse")  # 0.5 m/s up at 0.3 s
    motion = Motion(
        _scene(
            ball, arm, gravity=(0.0, 0.0), forces=(push, kick), joints=(Joint("arm", (1.0, 0.25)),)
        )
    )
    k = motion.kick("ball", 0.05, 0.1)  # the push acts for the first 0.05 s, then it coasts
    np.testing.assert_allclose(k.dv, [0.1, 0.0])
    np.testing.assert_allclose(k.dx, [2.0 * (0.05**2 / 2 + 0.05 * 0.05), 0.0])
    k = motion.kick("ball", 0.25, 0.1)
    np.testing.assert_allclose(k.dv, [0.0, 0.5])
    np.testing.assert_allclose(k.dx, [0.0, 0.5 * 0.05])
    assert not motion.kick("arm", 0.0, 0.1).dx.any()  # a jointed body keeps its velocity
