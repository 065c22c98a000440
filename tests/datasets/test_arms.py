"""Chains of rigid arms: the bodies and joints of a chain, and the tracks its angles imply."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.datasets.arms import ARM_WIDTH, Arm, chain, chain_poses, chain_tracks
from physbench.scene import Scene
from physbench.simulators.pymunk_sim import PymunkSimulator

UPPER = Arm("upper", mass=0.2, com=0.1, length=0.3, inertia=1e-3)
LOWER = Arm("lower", mass=0.1, com=0.08, length=0.2, inertia=4e-4)


def test_a_hanging_arm_points_down_and_a_turned_one_follows_its_angle() -> None:
    (body,), (joint,) = chain((1.0, 2.0), [UPPER], [0.0], [0.0])
    assert body.position == pytest.approx((1.0, 1.85)) and joint.anchor == (1.0, 2.0)
    assert joint.b is None and body.shape.width == ARM_WIDTH and body.moment == UPPER.inertia
    # the centre of mass sits `com` below the pivot: the offset is from the shape centre
    assert body.com_offset == pytest.approx((0.0, 0.5 * UPPER.length - UPPER.com))
    (turned,), _ = chain((1.0, 2.0), [UPPER], [math.pi / 2], [0.0])
    assert turned.position == pytest.approx((1.15, 2.0))  # counter-clockwise from hanging down


def test_the_chain_hangs_each_arm_from_the_end_of_the_one_above_and_moves_rigidly() -> None:
    bodies, joints = chain((0.0, 0.0), [UPPER, LOWER], [0.3, -0.2], [1.0, 2.0])
    end = np.array([math.sin(0.3), -math.cos(0.3)]) * UPPER.length
    assert joints[1].a == "lower" and joints[1].b == "upper"
    assert joints[1].anchor == pytest.approx(tuple(end))
    lower_centre = end + 0.5 * LOWER.length * np.array([math.sin(-0.2), -math.cos(-0.2)])
    assert bodies[1].position == pytest.approx(tuple(lower_centre))
    # velocity of the lower centre: the upper end's velocity plus the lower arm's own rotation
    v_end = 1.0 * np.array([-end[1], end[0]])
    r = lower_centre - end
    assert bodies[1].velocity == pytest.approx(tuple(v_end + 2.0 * np.array([-r[1], r[0]])))


def test_tracks_and_poses_agree_with_the_bodies_and_a_simulation_keeps_the_chain() -> None:
    angles = np.array([[0.3, -0.2], [0.1, 0.4]])
    poses = chain_poses((0.0, 0.0), [UPPER, LOWER], angles)
    bodies, _ = chain((0.0, 0.0), [UPPER, LOWER], angles[0], [0.0, 0.0])
    np.testing.assert_allclose([p[0] for p in poses], [b.position for b in bodies])
    tracks = chain_tracks((0.0, 0.0), [UPPER, LOWER], np.array([0.0, 0.1]), angles)
    assert tracks["lower"].angle.tolist() == [-0.2, 0.4]
    assert tracks["upper"].x.tolist() == pytest.approx(poses[0][:, 0].tolist())
    bodies, joints = chain((2.0, 3.0), [UPPER, LOWER], [0.5, 0.0], [0.0, 0.0])
    scene = Scene("arms", bodies, joints=joints, frames=31, substeps=20, fps=60.0).validate()
    traj = PymunkSimulator().simulate(scene)
    pivot_to_upper = np.hypot(*(traj.body("upper")[:, :2] - (2.0, 3.0)).T)
    np.testing.assert_allclose(pivot_to_upper, 0.5 * UPPER.length, atol=2e-3)
