"""The effect base machinery: registration, values and their checks, body selection."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.effects import (
    BUILTIN_EFFECTS,
    EffectError,
    JointViscousDamping,
    LinearDrag,
)
from physbench.effects.base import Effect
from physbench.errors import UnknownNameError
from physbench.plugins import build_registry
from physbench.scene import Body, Circle, Scene


def test_every_builtin_effect_is_registered_and_follows_the_protocol():
    names = build_registry().names("effect")
    for cls in BUILTIN_EFFECTS:
        assert cls.name in names
        assert isinstance(cls(), Effect)
        for p in cls.params:
            assert p.low <= p.default <= p.high and p.doc
    expected = {
        "linear_drag",
        "quadratic_drag",
        "rolling_resistance",
        "constant_force",
        "joint_viscous_damping",
        "joint_coulomb_friction",
        "velocity_dependent_restitution",
        "sensor_offset",
    }
    assert expected <= set(names)


def test_values_combine_and_bad_values_are_named(ball_scene):
    e = LinearDrag(c=0.5)
    e.setup(ball_scene(), {})
    assert e.values == {"c": 0.5}
    e.setup(ball_scene(), {"linear_drag.c": 0.25})  # qualified keys work too
    assert e.values == {"c": 0.25}
    with pytest.raises(EffectError, match=r"linear_drag\.c = -1\.0: must lie in \[0, 10\]"):
        LinearDrag(c=-1.0)
    with pytest.raises(EffectError, match="nan"):
        e.setup(ball_scene(), {"c": float("nan")})
    with pytest.raises(UnknownNameError, match=r"'k'.*known.*c"):
        LinearDrag(k=1.0)
    with pytest.raises(UnknownNameError, match="'nope'"):
        LinearDrag(bodies=["nope"]).setup(ball_scene(), {})
    with pytest.raises(EffectError, match="not set up"):
        LinearDrag().forces(0.0, np.zeros((1, 6)))
    with pytest.raises(EffectError, match="needs a scene with joints"):
        JointViscousDamping().setup(ball_scene(), {})


def test_body_selection_leaves_other_bodies_alone():
    scene = Scene(
        "two",
        (
            Body("a", Circle(0.05), (1, 1), velocity=(1, 0)),
            Body("b", Circle(0.05), (1, 2), velocity=(1, 0)),
        ),
        gravity=(0, 0),
        bounds=(0, 0, 10, 10),
    )
    e = LinearDrag(c=1.0, bodies=["a"])
    e.setup(scene, {})
    f, tau = e.forces(0.0, np.array([[1, 1, 0, 1, 0, 0], [1, 2, 0, 1, 0, 0]], dtype=float))
    assert f.tolist() == [[-1.0, 0.0], [0.0, 0.0]] and tau.tolist() == [0.0, 0.0]
