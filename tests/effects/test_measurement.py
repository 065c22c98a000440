"""Measurement effects change what the sensor reports, not the motion."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.effects import (
    ClockScale,
    LinearDrag,
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
