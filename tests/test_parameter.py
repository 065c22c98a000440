"""Parameter: one description of a named, bounded, unit-carrying quantity."""

from __future__ import annotations

import math

from physbench.effects import LinearDrag
from physbench.parameter import Parameter
from physbench.scene import body_unknown


def test_keys_owners_ranges_and_descriptions() -> None:
    c = Parameter("c", 0.0, 10.0, unit="N·s/m", default=0.0, doc="drag per unit speed")
    assert c.key == "c" and c.width == 10.0 and c.describe() == "[0, 10] N·s/m"
    drag = c.owned_by("drag_a")
    assert drag.key == "drag_a.c" and drag.unit == c.unit and c.owner == ""
    assert c.contains(10.0) and not c.contains(10.1) and c.contains(10.1, tol=0.2)
    assert not c.contains(math.nan)


def test_unknowns_and_effect_parameters_are_the_same_type() -> None:
    mass = body_unknown("ball", "mass", 0.5, 2.0)
    assert isinstance(mass, Parameter) and mass.key == "ball.mass" and mass.unit == "kg"
    assert body_unknown("ball", "elasticity", 0.1, 1.0).unit == ""
    (c,) = LinearDrag(label="drag_a").parameters()
    assert isinstance(c, Parameter) and c.key == "drag_a.c" and c.default == 0.0
