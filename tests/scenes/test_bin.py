"""The bin: a floor and two walls along the bounds (and a ceiling when asked), moved inwards by
``inset``, perfectly elastic with friction 1 unless told otherwise."""

from __future__ import annotations

from physbench.scene import Segment
from physbench.scenes.bin import bin_walls


def test_floor_and_two_walls_along_the_bounds() -> None:
    assert bin_walls((0.0, 0.0, 4.0, 3.0)) == (
        Segment((0.0, 0.0), (4.0, 0.0), 0.0, 1.0, 1.0),
        Segment((0.0, 0.0), (0.0, 3.0), 0.0, 1.0, 1.0),
        Segment((4.0, 0.0), (4.0, 3.0), 0.0, 1.0, 1.0),
    )


def test_inset_ceiling_and_surface_values() -> None:
    walls = bin_walls((0.0, 1.0, 4.0, 5.0), inset=0.5, ceiling=True, elasticity=0.3, friction=2)
    assert [(s.a, s.b) for s in walls] == [
        ((0.5, 1.5), (3.5, 1.5)),
        ((0.5, 1.5), (0.5, 4.5)),
        ((3.5, 1.5), (3.5, 4.5)),
        ((0.5, 4.5), (3.5, 4.5)),
    ]
    assert {(s.radius, s.elasticity, s.friction, s.kind) for s in walls} == {
        (0.0, 0.3, 2, "segment")
    }
