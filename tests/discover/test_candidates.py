"""Which effects are tried, and from where (physbench/discover/candidates.py)."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.discover.candidates import (
    REFERENCES,
    camera_view,
    candidates_for,
    is_measurement,
    start_values,
)
from physbench.effects import VelocityDependentRestitution
from physbench.errors import UnknownNameError
from physbench.recording import Recording, Track
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


MEASUREMENT = ["clock_scale", "calibration_scale", "axis_rotation", "lens_distortion"]


def test_measurement_causes_are_candidates_beside_the_physical_effects():
    # without a force of known size a clock error is a change of g, and it is offered all the
    # same: discovery then names it together with the change of g it cannot be told from
    assert offered(Scene("side", (BALL,)), MEASUREMENT)[0] == MEASUREMENT
    kicked = Scene("kick", (BALL,), forces=(Force("ball", (1.0, 0.0), 0.1, 0.2),))
    assert offered(kicked, ["clock_scale"])[0] == ["clock_scale"]
    assert all(is_measurement(n) for n in [*MEASUREMENT, "sensor_offset", "plane_tilt"])
    assert not any(is_measurement(n) for n in ["constant_force", "linear_drag", "nope"])


def test_a_reference_fixes_a_measurement_cause():
    specs, skipped = candidates_for(
        Scene("side", (BALL,)), MEASUREMENT, references=("scale", "clock")
    )
    assert [s.label for s in specs] == ["axis_rotation", "lens_distortion"]
    why = dict(skipped)
    assert why["calibration_scale"] == f"fixed by a reference: {REFERENCES['scale'][1]}"
    assert why["clock_scale"] == f"fixed by a reference: {REFERENCES['clock'][1]}"


def test_the_camera_s_errors_need_positions_and_are_centred_on_the_view():
    side = Scene("side", (BALL,))
    t3, zeros = np.arange(3.0), np.zeros(3)
    angle_only = Recording({"ball": Track(t3, zeros, zeros, zeros)}, fields=("angle",))
    specs, skipped = candidates_for(side, MEASUREMENT, recordings=[angle_only])
    assert [s.label for s in specs] == ["clock_scale"]
    assert "no positions" in dict(skipped)["axis_rotation"]
    t = np.array([0.0, 1.0])
    tracked = Recording({"ball": Track(t, np.array([1.0, 3.0]), np.array([2.0, 0.0]))})
    assert camera_view([tracked]) == ((2.0, 1.0), pytest.approx(np.hypot(2.0, 2.0) / 2))
    (lens,), _ = candidates_for(side, ["lens_distortion"], recordings=[tracked])
    assert dict(lens.options)["centre"] == (2.0, 1.0)
    dropped = Recording({"ball": Track(t, np.zeros(2), np.array([2.0, 0.0]))}, fields=("y",))
    specs, skipped = candidates_for(side, MEASUREMENT, recordings=[dropped])
    assert [s.label for s in specs] == ["clock_scale", "calibration_scale"]  # a drop in y only
    assert "track one coordinate" in dict(skipped)["axis_rotation"]
    assert lens.make().radius() == pytest.approx(np.hypot(2.0, 2.0) / 2)


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
