"""second_order: all three circles rest on the bin's floor; the test circle is pushed sideways
into ``a``, which lies 0.35-0.5 m from ``b``, so ``b`` is only set moving through ``a``."""

from __future__ import annotations

import pytest

from physbench.scenes import second_order
from physbench.scenes.bin import bin_walls

SEEDS = range(20)


@pytest.mark.parametrize("seed", SEEDS)
def test_three_circles_on_the_floor_and_a_sideways_push_into_a(seed: int) -> None:
    scene = second_order.generate(seed)
    test, a, b = scene.bodies
    r = second_order.RADIUS
    assert scene.body_names == ("test", "a", "b") and scene.test_body == "test"
    assert test.position[1] == a.position[1] == b.position[1] == r  # all on the floor
    assert test.position[0] + 2 * r < a.position[0]  # not touching a before the push
    assert 0.35 <= b.position[0] - a.position[0] - 2 * r <= 0.5  # the gap
    (push,) = scene.forces
    assert push.body == "test" and push.vector[1] == 0.0  # sideways, to the right
    assert 7 - 0.5 <= push.vector[0] * push.end / test.mass <= 7 + 0.5
    assert scene.statics == bin_walls(second_order.BOUNDS) and scene.meta == {"seed": seed}


def test_unknowns_are_mass_and_elasticity_of_a_and_b() -> None:
    scene = second_order.generate(0)
    assert [(u.key, u.low, u.high) for u in scene.unknowns] == [
        ("a.mass", 2.0, 8.0),
        ("a.elasticity", 0.4, 1.0),
        ("b.mass", 2.0, 8.0),
        ("b.elasticity", 0.4, 1.0),
    ]
    for body in scene.bodies[1:]:
        assert (body.mass, body.elasticity) == (5.0, 0.7)
