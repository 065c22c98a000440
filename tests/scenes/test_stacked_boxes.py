"""stacked_boxes: two 0.5 m boxes stand on the inset floor of a bin, ``upper`` on ``lower``; the
test circle rolls in on the floor and strikes ``lower`` at mid-height; the boxes' mass and
friction are unknown."""

from __future__ import annotations

import pytest

from physbench.scene import Box
from physbench.scenes import stacked_boxes
from physbench.scenes.bin import bin_walls

SEEDS = range(20)


@pytest.mark.parametrize("seed", SEEDS)
def test_upper_stands_on_lower_on_the_floor_and_the_test_circle_hits_lower_mid_height(
    seed: int,
) -> None:
    scene = stacked_boxes.generate(seed)
    test, lower, upper = scene.bodies
    side, floor = stacked_boxes.SIDE, stacked_boxes.INSET
    assert scene.body_names == ("test", "lower", "upper") and scene.test_body == "test"
    assert lower.shape == upper.shape == Box(side, side)
    assert lower.position[1] == floor + side / 2 and upper.position[1] == floor + 1.5 * side
    assert abs(upper.position[0] - lower.position[0]) <= 0.05  # stacked, at most 5 cm off
    assert test.position[1] == floor + stacked_boxes.RADIUS == lower.position[1]  # mid-height
    assert test.position[0] + stacked_boxes.RADIUS < lower.position[0] - side / 2
    (push,) = scene.forces
    assert push.body == "test" and push.vector[1] == 0.0 and push.vector[0] > 0
    assert scene.statics == bin_walls(stacked_boxes.BOUNDS, inset=floor)
    assert scene.meta == {"seed": seed}


def test_unknowns_are_mass_and_friction_of_both_boxes() -> None:
    scene = stacked_boxes.generate(0)
    assert [(u.key, u.low, u.high) for u in scene.unknowns] == [
        ("lower.mass", 2.0, 8.0),
        ("lower.friction", 0.2, 1.0),
        ("upper.mass", 2.0, 8.0),
        ("upper.friction", 0.2, 1.0),
    ]
    for box in scene.bodies[1:]:
        assert (box.mass, box.friction, box.elasticity) == (5.0, 0.6, 0.5)
