"""three_circles: ``a`` and ``b`` rest on the bin's floor 0.35-0.5 m apart, and the test circle
starts up and to the left and is pushed at the upper left of ``a``; ``a`` and ``b`` have unknown
mass and elasticity."""

from __future__ import annotations

import math

import pytest

from physbench.scenes import three_circles
from physbench.scenes.bin import bin_walls

SEEDS = range(20)


@pytest.mark.parametrize("seed", SEEDS)
def test_two_circles_on_the_floor_and_the_test_circle_aimed_at_the_upper_left_of_a(
    seed: int,
) -> None:
    scene = three_circles.generate(seed)
    test, a, b = scene.bodies
    r = three_circles.RADIUS
    assert scene.body_names == ("test", "a", "b") and scene.test_body == "test"
    assert a.position[1] == b.position[1] == r  # resting on the floor
    assert 0.35 <= b.position[0] - a.position[0] - 2 * r <= 0.5  # the gap
    assert abs(a.position[0] - three_circles.XA) <= 0.1
    assert test.position[0] < a.position[0] and test.position[1] >= 1.6  # up and to the left
    (push,) = scene.forces
    assert push.body == "test" and (push.start, push.end) == (0.0, three_circles.PUSH_TIME)
    # pointed from the start at (xa - 0.7 r, 1.7 r), with 7.5-8.5 m/s after the push
    aim = (a.position[0] - 0.7 * r - test.position[0], 1.7 * r - test.position[1])
    cross = push.vector[0] * aim[1] - push.vector[1] * aim[0]
    assert cross == pytest.approx(0.0, abs=1e-6 * math.hypot(*push.vector))
    assert push.vector[0] > 0 and push.vector[1] < 0
    speed = math.hypot(*push.vector) * push.end / test.mass
    assert 7.5 <= speed <= 8.5
    assert scene.statics == bin_walls(three_circles.BOUNDS) and scene.meta == {"seed": seed}


def test_unknowns_are_mass_and_elasticity_of_a_and_b_with_nominal_mid_range() -> None:
    scene = three_circles.generate(0)
    assert [(u.key, u.low, u.high) for u in scene.unknowns] == [
        ("a.mass", 2.0, 8.0),
        ("a.elasticity", 0.4, 1.0),
        ("b.mass", 2.0, 8.0),
        ("b.elasticity", 0.4, 1.0),
    ]
    for body in scene.bodies[1:]:
        assert (body.mass, body.elasticity) == (5.0, 0.7)
