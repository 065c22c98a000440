"""Which effects are tried, and from where (physbench/discover/candidates.py)."""

from __future__ import annotations

import pytest

from physbench.discover.candidates import candidates_for, start_values
from physbench.effects import VelocityDependentRestitution
from physbench.errors import UnknownNameError
from physbench.scene import Body, Box, Circle, Force, Joint, Scene, Segment

BALL = Body("ball", Circle(0.05), (1.0, 1.0), velocity=(1.0, 0.0), elasticity=0.8)
FLOOR = Segment((0.0, 0.0), (4.0, 0.0), elasticity=0.5)


def offered(scene: Scene, names: list[str]) -> tuple[list[str], dict[str, str]]:
    specs, skipped = candidates_for(scene, names)
    return [s.label for s in specs], dict(skipped)


def test_rolling_resistance_needs_a_surface():
    side = Scene("side", (BALL,))
    names, why = offered(side, ["rolling_resistance"])
    assert names == [] and "no surface to roll on" in why["rolling_resistance"]
    assert offered(Scene("top", (BALL,), gravity=(0.0, 0.0)), ["rolling_resistance"])[0]
    assert offered(Scene("floor", (BALL,), statics=(FLOOR,)), ["rolling_resistance"])[0]


def test_a_uniform_acceleration_is_offered_once_on_bodies_of_one_mass():
    both = ["constant_force", "table_tilt"]
    top = Scene("top", (BALL,), gravity=(0.0, 0.0))
    assert offered(top, both)[0] == ["table_tilt"]
    assert offered(Scene("side", (BALL,)), both)[0] == ["constant_force"]
    heavy = Body("heavy", Circle(0.05), (2.0, 1.0), mass=3.0)
    assert offered(Scene("two", (BALL, heavy), gravity=(0.0, 0.0)), both)[0] == both


def test_a_clock_error_needs_a_force_of_known_size():
    names, why = offered(Scene("side", (BALL,)), ["clock_scale"])
    assert names == [] and "no force of known size" in why["clock_scale"]
    kicked = Scene("kick", (BALL,), forces=(Force("ball", (1.0, 0.0), 0.1, 0.2),))
    assert offered(kicked, ["clock_scale"])[0] == ["clock_scale"]


def test_translational_losses_act_on_free_bodies_only():
    arm = Body("arm", Box(0.04, 0.4), (1.0, 1.3))
    pendulum = Scene("p", (arm,), joints=(Joint("arm", (1.0, 1.5)),))
    names, why = offered(pendulum, ["linear_drag"])
    assert names == [] and "no free bodies" in why["linear_drag"]
    mixed = Scene("m", (arm, BALL), joints=(Joint("arm", (1.0, 1.5)),))
    (spec,), _ = candidates_for(mixed, ["linear_drag"])
    assert dict(spec.options) == {"bodies": ["ball"]}


def test_a_contact_law_needs_something_to_hit():
    names, why = offered(Scene("alone", (BALL,)), ["velocity_dependent_restitution"])
    assert names == [] and why["velocity_dependent_restitution"] == "nothing to collide with"
    assert offered(Scene("floor", (BALL,), statics=(FLOOR,)), ["velocity_dependent_restitution"])[0]


def test_unknown_effects_are_named():
    with pytest.raises(UnknownNameError, match="nope"):
        candidates_for(Scene("s", (BALL,)), ["nope"])


def test_restitution_starts_at_the_scene_s_typical_restitution():
    other = Body("other", Circle(0.05), (2.0, 1.0), elasticity=1.0)
    scene = Scene("s", (BALL, other), statics=(FLOOR,))
    # ball-floor 0.4, other-floor 0.5, ball-other 0.8
    assert start_values(VelocityDependentRestitution(), scene) == {"e0": 0.5, "k": 0.0}
    walls_only = VelocityDependentRestitution(statics_only=True)
    assert start_values(walls_only, scene) == {"e0": pytest.approx(0.45), "k": 0.0}
    assert start_values(VelocityDependentRestitution(), Scene("s", (BALL,))) == {
        "e0": 0.9,
        "k": 0.0,
    }
