"""Measurement effects change what the sensor reports, not the motion."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.effects import (
    AxisRotation,
    CalibrationScale,
    ClockScale,
    LensDistortion,
    LinearDrag,
    PlaneTilt,
    SensorOffset,
    apply_measurements,
)
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_sensor_offset_and_clock_scale_change_only_the_measurement(run_both, ball_scene):
    scene = ball_scene(velocity=(1.0, 0.0), seconds=1.0)
    off, clock = SensorOffset(dx=0.1, dangle=-0.05), ClockScale(scale=1.25)
    trajs = run_both(scene, lambda: [SensorOffset(dx=0.1, dangle=-0.05)])
    plain = PymunkSimulator().simulate(scene)
    np.testing.assert_array_equal(trajs[0].states, plain.states)  # no forces
    off.setup(scene, {})
    clock.setup(scene, {})
    seen = apply_measurements(plain, [LinearDrag(), off, clock])
    np.testing.assert_allclose(seen.times, plain.times / 1.25)
    np.testing.assert_allclose(seen.body("ball")[:, 0], plain.body("ball")[:, 0] + 0.1)
    np.testing.assert_allclose(seen.body("ball")[:, 2], plain.body("ball")[:, 2] - 0.05)
    np.testing.assert_allclose(seen.body("ball")[:, 3], plain.body("ball")[:, 3] * 1.25)
    # the measured trajectory stays self-consistent: dx/dt on the recorder clock is the velocity
    x = seen.body("ball")[:, 0]
    assert np.gradient(x, seen.times)[5] == pytest.approx(seen.body("ball")[5, 3], rel=1e-3)


def _spinning(seconds: float = 1.0):
    """A spinning ball thrown across a 4 m view (positions, angles and rates all change)."""
    from physbench.scene import Body, Box, Scene

    ball = Body("box", Box(0.2, 0.1), (0.5, 1.0), velocity=(3.0, 4.0), angular_velocity=2.0)
    scene = Scene("throw", (ball,), bounds=(0.0, 0.0, 4.0, 4.0), frames=int(30 * seconds) + 1)
    return scene, PymunkSimulator().simulate(scene.validate())


def _measured(effect, scene, traj):
    effect.setup(scene, {})
    return apply_measurements(traj, [effect])


def _consistent(seen) -> None:
    """Reported velocities and rates are the time derivatives of the reported poses."""
    t = seen.times
    for f, v in ((0, 3), (1, 4), (2, 5)):
        pose = seen.states[:, 0, f]
        rate = seen.states[:, 0, v]
        np.testing.assert_allclose(np.gradient(pose, t)[3:-3], rate[3:-3], rtol=0.02, atol=0.02)


def test_calibration_scale_stretches_lengths_about_its_centre():
    scene, plain = _spinning()
    seen = _measured(CalibrationScale(scale=1.05, centre=(1.0, 2.0)), scene, plain)
    p, q = plain.states[:, 0], seen.states[:, 0]
    np.testing.assert_allclose(q[:, 0], 1.0 + 1.05 * (p[:, 0] - 1.0))
    np.testing.assert_allclose(q[:, 1], 2.0 + 1.05 * (p[:, 1] - 2.0))
    np.testing.assert_allclose(q[:, 3:5], 1.05 * p[:, 3:5], rtol=1e-9)
    np.testing.assert_allclose(q[:, [2, 5]], p[:, [2, 5]], atol=1e-9)  # angles keep
    _consistent(seen)


def test_axis_rotation_turns_positions_velocities_and_angles():
    scene, plain = _spinning()
    a = 0.02
    seen = _measured(AxisRotation(angle=a), scene, plain)
    p, q = plain.states[:, 0], seen.states[:, 0]
    c, s = np.cos(a), np.sin(a)
    np.testing.assert_allclose(q[:, 0], c * p[:, 0] - s * p[:, 1])
    np.testing.assert_allclose(q[:, 1], s * p[:, 0] + c * p[:, 1])
    np.testing.assert_allclose(q[:, 4], s * p[:, 3] + c * p[:, 4], rtol=1e-9)
    np.testing.assert_allclose(q[:, 2], p[:, 2] + a, atol=1e-9)
    np.testing.assert_allclose(q[:, 5], p[:, 5], atol=1e-6)
    _consistent(seen)


def test_lens_distortion_shifts_points_radially_by_k1_at_the_edge_of_the_view():
    from physbench.scene import Scene

    eff = LensDistortion(k1=0.05, centre=(2.0, 2.0), radius=2.0)
    eff.setup(Scene("s", (_spinning()[0].bodies[0],)), {})
    d = np.array([[2.0, 0.0], [0.0, -1.0], [0.0, 0.0]])
    got = eff.warp(d)
    far = eff.warp(np.array([[30.0, 0.0]]))  # beyond 1.5 radii it shifts as at 1.5 radii
    np.testing.assert_allclose(far, [[30.0 + 0.05 * 3.0 * 1.5**2, 0.0]])
    np.testing.assert_allclose(got[0], [2.1, 0.0])  # at the radius: k1 * radius outwards
    np.testing.assert_allclose(got[1], [0.0, -1.0125])  # half way: a quarter of that share
    np.testing.assert_allclose(got[2], [0.0, 0.0])
    scene, plain = _spinning()
    _consistent(_measured(LensDistortion(k1=-0.1), scene, plain))


def test_plane_tilt_is_perspective_the_near_side_looks_larger():
    from physbench.scene import Scene

    eff = PlaneTilt(tx=0.2, centre=(0.0, 0.0), radius=1.0, distance=2.0)
    eff.setup(Scene("s", (_spinning()[0].bodies[0],)), {})
    up, down = eff.warp(np.array([[0.0, 0.5], [0.0, -0.5]]))
    # turned about x, the +y side comes nearer the pinhole (z > 0) and is seen larger
    assert up[1] > 0.5 * np.cos(0.2) and -down[1] < 0.5 * np.cos(0.2)
    assert up[1] > -down[1]
    np.testing.assert_allclose(eff.warp(np.zeros((1, 2))), 0.0)  # the middle stays
    scene, plain = _spinning()
    _consistent(_measured(PlaneTilt(tx=0.1, ty=-0.2), scene, plain))


def test_view_maps_default_to_the_scene_bounds_and_refuse_bad_options():
    from physbench.components import create
    from physbench.effects import EffectError
    from physbench.errors import OptionError

    scene, _ = _spinning()
    eff = create("effect", "lens_distortion", {})
    eff.setup(scene, {})
    np.testing.assert_allclose(eff.centre(), [2.0, 2.0])
    assert eff.radius() == pytest.approx(np.hypot(4.0, 4.0) / 2)
    tilt = create("effect", "plane_tilt", {"radius": 1.5})
    assert tilt.distance() == 6.0
    with pytest.raises(EffectError, match="radius"):
        LensDistortion(radius=-1.0)
    with pytest.raises(EffectError, match="centre"):
        CalibrationScale(centre=(1.0,))
    with pytest.raises(OptionError, match="distance"):
        create("effect", "lens_distortion", {"distance": 2.0})
    with pytest.raises(EffectError, match="setup"):
        LensDistortion(k1=0.1).measure(_spinning()[1])
