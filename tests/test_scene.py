"""The scene model: validation names the first bad key and its value, ``with_params`` applies
``body.param`` values, body and unknown lookups name what is known, and each shape's geometry (area,
moment, extent, rotated bounding box) has its closed form."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import pytest

from physbench.errors import SceneError, UnknownNameError
from physbench.scene import (
    BODY_PARAMS,
    GRAVITY,
    Body,
    Box,
    Circle,
    Force,
    Joint,
    Polygon,
    Scene,
    Segment,
    StaticPolygon,
    body_unknown,
)

A = Body("a", Circle(0.5), (1.0, 1.0), mass=2.0)
B = Body("b", Box(1.0, 0.5), (3.0, 1.0), elasticity=0.25)
GOOD = Scene(
    "s",
    (A, B),
    statics=(Segment((0.0, 0.0), (4.0, 0.0)),),
    forces=(Force("a", (1.0, 0.0), 0.0, 0.1),),
    joints=(Joint("b", (3.0, 1.0)),),
    unknowns=(body_unknown("a", "mass", 1.0, 5.0), body_unknown("b", "friction", 0.1, 1.0)),
)


def _body(i: int, **changes: Any) -> Scene:
    bodies = list(GOOD.bodies)
    bodies[i] = dataclasses.replace(bodies[i], **changes)
    return dataclasses.replace(GOOD, bodies=tuple(bodies))


def test_a_good_scene_validates_and_returns_itself() -> None:
    assert GOOD.validate() is GOOD
    assert GOOD.dt == pytest.approx(1 / 30) and GOOD.body_names == ("a", "b")


@pytest.mark.parametrize(
    ("scene", "key", "value", "reason"),
    [
        (dataclasses.replace(GOOD, name=""), "name", "", "must be a non-empty string"),
        (
            dataclasses.replace(GOOD, bounds=(0.0, 0.0, 0.0, 4.0)),
            "bounds",
            (0.0, 0.0, 0.0, 4.0),
            "bounds must be [xmin, ymin, xmax, ymax] with min < max",
        ),
        (dataclasses.replace(GOOD, fps=0.0), "fps", 0.0, "must lie in [0.1, 100000] Hz"),
        (dataclasses.replace(GOOD, fps=1e9), "fps", 1e9, "must lie in [0.1, 100000] Hz"),
        (
            dataclasses.replace(GOOD, gravity=(0.0, -1e9)),
            "gravity[1]",
            -1e9,
            "must lie in [-10000, 10000] m/s²",
        ),
        (
            dataclasses.replace(GOOD, frames=True),
            "frames",
            True,
            "must be a whole number in [1, 100000]",
        ),
        (dataclasses.replace(GOOD, gravity=(0.0, math.nan)), "gravity[1]", math.nan, None),
        (
            dataclasses.replace(GOOD, bodies=()),
            "bodies",
            [],
            "a scene needs at least one dynamic body",
        ),
        (
            _body(1, name="a"),
            "bodies[1].name",
            "a",
            "duplicate body name",
        ),
        (
            _body(0, name="x.y"),
            "bodies[0].name",
            "x.y",
            "must be a non-empty name without '.', not 'world'",
        ),
        (
            _body(0, shape=Circle(0.0)),
            "bodies[0].shape.radius",
            0.0,
            "must lie in [1e-06, 1e+06] m",
        ),
        (
            _body(1, position=(3.6, 1.0)),
            "bodies[1].position",
            (3.6, 1.0),
            "body (half size 0.5 x 0.25 m) must lie inside the world bounds (0.0, 0.0, 4.0, 4.0)",
        ),
        (_body(0, mass=0.0), "bodies[0].mass", 0.0, "mass must lie in [1e-06, 1e+06] kg"),
        (_body(0, mass=1e-320), "bodies[0].mass", 1e-320, "mass must lie in [1e-06, 1e+06] kg"),
        (_body(0, mass=1e12), "bodies[0].mass", 1e12, "mass must lie in [1e-06, 1e+06] kg"),
        (
            _body(0, velocity=(1e9, 0.0)),
            "bodies[0].velocity[0]",
            1e9,
            "must lie in [-10000, 10000] m/s",
        ),
        (
            _body(1, angular_velocity=-1e9),
            "bodies[1].angular_velocity",
            -1e9,
            "must lie in [-100000, 100000] rad/s",
        ),
        (
            _body(1, elasticity=1.5),
            "bodies[1].elasticity",
            1.5,
            "elasticity must lie in [0.0, 1.0]",
        ),
        (_body(1, moment=-1.0), "bodies[1].moment", -1.0, "moment must be > 0"),
        (
            _body(0, shape=Polygon(((0.0, 0.0), (0.0, 1.0), (1.0, 0.0)))),
            "bodies[0].shape.points",
            ((0.0, 0.0), (0.0, 1.0), (1.0, 0.0)),
            "polygon must be convex with counter-clockwise points",
        ),
        (
            dataclasses.replace(GOOD, statics=(Segment((1.0, 1.0), (1.0, 1.0)),)),
            "statics[0].b",
            (1.0, 1.0),
            "segment end points must differ",
        ),
        (
            dataclasses.replace(
                GOOD, statics=(StaticPolygon(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), friction=-1),)
            ),
            "statics[0].friction",
            -1.0,
            "friction must lie in [0.0, inf]",
        ),
        (
            dataclasses.replace(GOOD, forces=(Force("c", (1.0, 0.0), 0.0, 0.1),)),
            "forces[0].body",
            "c",
            "no such body; bodies: a, b",
        ),
        (
            dataclasses.replace(GOOD, forces=(Force("a", (1.0, 0.0), 0.2, 0.1),)),
            "forces[0].end",
            0.1,
            "a force window needs end > start",
        ),
        (
            dataclasses.replace(GOOD, joints=(Joint("b", (3.0, 1.0), b="b"),)),
            "joints[0].b",
            "b",
            "a joint needs two different bodies",
        ),
        (
            dataclasses.replace(GOOD, unknowns=(body_unknown("a", "colour", 0.0, 1.0),)),
            "unknowns[0].param",
            "colour",
            "unknown parameter; known: mass, elasticity, friction, moment",
        ),
        (
            dataclasses.replace(GOOD, unknowns=(body_unknown("a", "mass", 5.0, 1.0),)),
            "unknowns[0].range",
            [5.0, 1.0],
            "range must be [low, high] with low < high",
        ),
        (
            dataclasses.replace(GOOD, unknowns=(body_unknown("b", "elasticity", 0.5, 2.0),)),
            "unknowns[0].range[1]",
            2.0,
            "elasticity must lie in [0.0, 1.0]",
        ),
        (
            dataclasses.replace(GOOD, unknowns=(*GOOD.unknowns, body_unknown("a", "mass", 1, 2))),
            "unknowns[2].param",
            "mass",
            "parameter declared unknown twice",
        ),
        (
            dataclasses.replace(GOOD, test_body="a"),
            "unknowns[0].body",
            "a",
            "the test body's parameters are fixed by definition",
        ),
        (
            dataclasses.replace(GOOD, test_body="c"),
            "test_body",
            "c",
            "no such body; bodies: a, b",
        ),
    ],
)
def test_validation_names_the_first_bad_key_and_its_value(
    scene: Scene, key: str, value: object, reason: str | None
) -> None:
    with pytest.raises(SceneError) as err:
        scene.validate()
    assert err.value.key == key
    if isinstance(value, float) and math.isnan(value):
        assert math.isnan(err.value.value)  # type: ignore[arg-type]
        assert str(err.value) == f"{key} = nan: must be a finite number"
    else:
        assert err.value.value == value
        assert str(err.value) == f"{key} = {value!r}: {reason}"


def test_with_params_applies_body_parameters_to_a_copy() -> None:
    assert GOOD.with_params({}) is GOOD
    new = GOOD.with_params({"a.mass": 3, "b.friction": 0.75, "a.moment": 0.5})
    assert (new.bodies[0].mass, new.bodies[0].moment, new.bodies[1].friction) == (3.0, 0.5, 0.75)
    assert type(new.bodies[0].mass) is float
    assert (GOOD.bodies[0].mass, GOOD.bodies[0].moment) == (2.0, None)  # unchanged
    assert new.bodies[1].elasticity == 0.25 and new.unknowns == GOOD.unknowns


def test_with_params_names_an_unknown_parameter_or_body() -> None:
    with pytest.raises(SceneError) as err:
        GOOD.with_params({"a.colour": 1.0})
    assert (err.value.key, err.value.value) == ("a.colour", 1.0)
    assert str(err.value) == (
        "a.colour = 1.0: unknown body parameter; known: mass, elasticity, friction, moment"
    )
    with pytest.raises(UnknownNameError, match=r"^unknown body 'z'; known .*: a, b$"):
        GOOD.with_params({"z.mass": 1.0})


def test_body_index_and_unknown_find_by_name_or_list_the_known_names() -> None:
    assert GOOD.body_index("b") == 1
    assert GOOD.unknown("b.friction") is GOOD.unknowns[1]
    with pytest.raises(UnknownNameError, match=r"^unknown body 'c'; known bodies: a, b$"):
        GOOD.body_index("c")
    with pytest.raises(UnknownNameError) as err:
        GOOD.unknown("b.mass")
    assert str(err.value) == (
        "unknown parameter 'b.mass' among the unknowns of scene 's'; known parameters among the "
        "unknowns of scene 's': a.mass, b.friction"
    )


def test_body_unknown_declares_a_parameter_with_its_unit() -> None:
    u = body_unknown("a", "moment", 0.1, 2.0)
    assert (u.key, u.owner, u.name, u.low, u.high, u.unit) == (
        "a.moment",
        "a",
        "moment",
        0.1,
        2.0,
        "kg·m²",
    )
    assert body_unknown("a", "elasticity", 0.1, 1.0).unit == ""
    assert set(BODY_PARAMS) == {"mass", "elasticity", "friction", "moment"}


def test_circle_geometry() -> None:
    c = Circle(2.0)
    assert c.area() == pytest.approx(4 * math.pi) and c.moment(3.0) == 6.0
    assert c.extent() == 2.0 and c.half_extents(0.7) == (2.0, 2.0)


def test_box_geometry_and_its_rotated_bounding_box() -> None:
    b = Box(4.0, 2.0)
    assert b.vertices() == ((-2.0, -1.0), (2.0, -1.0), (2.0, 1.0), (-2.0, 1.0))
    assert b.area() == 8.0 and b.moment(3.0) == pytest.approx(3.0 * (16 + 4) / 12)
    assert b.extent() == pytest.approx(math.sqrt(5))
    assert b.half_extents(0.0) == (2.0, 1.0)
    assert b.half_extents(math.pi / 2) == pytest.approx((1.0, 2.0))
    half = 3 / math.sqrt(2)  # (2 + 1) / √2 at 45°
    assert b.half_extents(math.pi / 4) == pytest.approx((half, half))


def test_polygon_geometry_matches_the_box_it_draws() -> None:
    square = Polygon(((-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5)))
    box = Box(2.0, 1.0)
    assert square.vertices() == square.points
    assert square.area() == box.area() == 2.0
    assert square.moment(6.0) == pytest.approx(box.moment(6.0)) == pytest.approx(2.5)
    assert square.extent() == pytest.approx(box.extent())
    assert square.half_extents(0.3) == pytest.approx(box.half_extents(0.3))
    tri = Polygon(((0.0, 0.0), (3.0, 0.0), (0.0, 4.0)))
    assert tri.area() == 6.0 and tri.extent() == 4.0
    assert tri.half_extents(0.0) == (3.0, 4.0)
    assert tri.half_extents(math.pi / 2) == pytest.approx((4.0, 3.0))  # (x, y) -> (-y, x)


def test_inertia_is_the_shapes_unless_the_moment_is_set() -> None:
    assert A.inertia() == 0.5 * 2.0 * 0.25
    assert dataclasses.replace(A, moment=0.125).inertia() == 0.125


def test_with_params_sets_gravity_along_y_and_keeps_x() -> None:
    tilted = dataclasses.replace(GOOD, gravity=(0.5, -9.81))
    got = tilted.with_params({"gravity": -9.7, "a.mass": 2.0})
    assert got.gravity == (0.5, -9.7) and got.bodies[0].mass == 2.0
    assert GRAVITY.key == "gravity" and GRAVITY.extensible


def test_scaled_multiplies_every_length_about_the_origin_and_keeps_the_bounds() -> None:
    scene = dataclasses.replace(
        GOOD,
        statics=(
            Segment((0.0, 0.0), (4.0, 0.0), radius=0.1),
            StaticPolygon(((1, 1), (2, 1), (2, 2))),
        ),
        joints=(Joint("a", (1.0, 2.0)),),
    )
    half = scene.scaled(0.5)
    assert half.bounds == scene.bounds and half.gravity == (0.0, -9.81 / 2)
    assert half.bodies[0].shape == Circle(0.25) and half.bodies[0].position == (0.5, 0.5)
    assert half.bodies[1].shape == Box(0.5, 0.25) and half.bodies[1].mass == B.mass
    assert half.statics[0] == Segment((0.0, 0.0), (2.0, 0.0), radius=0.05)
    assert half.statics[1].points == ((0.5, 0.5), (1.0, 0.5), (1.0, 1.0))
    assert half.joints[0].anchor == (0.5, 1.0)
