"""Joint losses against the analytic pendulum, in both engines; joints between bodies."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.effects import (
    JointCoulombFriction,
    JointQuadraticDamping,
    JointViscousDamping,
)
from physbench.scene import Body, Box, Joint, Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

G = 9.81
L, W, M, THETA0 = 0.4, 0.03, 0.5, 0.2  # the pendulum fixture's arm
I_PIVOT = M * (L * L + W * W) / 12 + M * (L / 2) ** 2

MGD = M * G * L / 2

ENGINES = [PymunkSimulator, Box2DSimulator]


def test_viscous_joint_damping_decays_amplitude_exponentially(
    run_both, assert_engines_agree, pendulum, peaks
):
    c = 0.02
    scene = pendulum()
    trajs = run_both(scene, lambda: [JointViscousDamping(c=c)])
    for tr in trajs:
        tp, ap = peaks(tr)
        assert len(ap) >= 3
        rate = -np.polyfit(tp, np.log(ap), 1)[0]
        assert rate == pytest.approx(c / (2 * I_PIVOT), rel=0.02)
    assert_engines_agree(trajs)
    np.testing.assert_allclose(peaks(trajs[0])[1], peaks(trajs[1])[1], atol=1e-3)


def test_coulomb_joint_friction_decays_amplitude_linearly(
    run_both, assert_engines_agree, pendulum, peaks
):
    tau = 0.005
    scene = pendulum()
    trajs = run_both(scene, lambda: [JointCoulombFriction(tau=tau)])
    for tr in trajs:
        _, ap = peaks(tr)
        assert len(ap) >= 3
        per_cycle = -np.diff(ap)
        np.testing.assert_allclose(
            per_cycle, 4 * tau / MGD, rtol=0.03
        )  # loses 2·tau/(m g d) per half swing
    assert_engines_agree(trajs)
    np.testing.assert_allclose(peaks(trajs[0])[1], peaks(trajs[1])[1], atol=1e-3)


@pytest.mark.parametrize("sim", ENGINES)
def test_coulomb_joint_friction_creeps_below_breakaway_without_chatter(sim, pendulum):
    # Gravity's torque (0.49·tau) is below the friction: the regularised joint creeps slowly and
    # monotonically towards the bottom instead of sticking or chattering.
    tau, theta0, eps = 0.01, 0.005, 0.02
    scene = pendulum(seconds=2.0, theta0=theta0)
    effect = JointCoulombFriction(tau=tau, eps=eps)
    effect.setup(scene, {})
    tr = sim().simulate(scene, effects=[effect])
    w, a = tr.field("omega")[1:, 0], tr.field("angle")[:, 0]
    assert np.all(w <= 1e-9)  # never swings back
    assert np.abs(w).max() < 1.1 * eps * MGD * theta0 / tau  # creep rate ≈ eps·load/tau
    # near rest the joint is a viscous one, c = tau/eps: an overdamped linear oscillator
    c = tau / eps
    s1, s2 = ((-c + sgn * math.sqrt(c * c - 4 * I_PIVOT * MGD)) / (2 * I_PIVOT) for sgn in (1, -1))
    t = tr.times
    np.testing.assert_allclose(
        a, theta0 * (s2 * np.exp(s1 * t) - s1 * np.exp(s2 * t)) / (s2 - s1), atol=0.03 * theta0
    )  # sign is not exactly linear at |w| ~ eps


def test_quadratic_joint_damping_loses_more_per_swing_at_large_amplitude(
    run_both, assert_engines_agree, pendulum, peaks
):
    scene = pendulum()
    trajs = run_both(scene, lambda: [JointQuadraticDamping(c=0.002)])
    for tr in trajs:
        _, ap = peaks(tr)
        rel = -np.diff(ap) / ap[:-1]
        assert np.all(np.diff(rel) < 0)  # the relative loss shrinks with the amplitude
    assert_engines_agree(trajs)
    np.testing.assert_allclose(peaks(trajs[0])[1], peaks(trajs[1])[1], atol=1e-3)


def test_joint_between_bodies_gets_equal_and_opposite_torques():
    scene = Scene(
        "double",
        (Body("a", Box(0.03, 0.4), (1, 0.8)), Body("b", Box(0.03, 0.4), (1, 0.4))),
        bounds=(0, 0, 2, 2),
        joints=(Joint("a", (1, 1.0)), Joint("b", (1, 0.6), "a")),
    )
    e = JointViscousDamping(c=0.1, joints=[1])
    e.setup(scene, {})
    _, tau = e.forces(0.0, np.array([[0, 0, 0, 0, 0, 2.0], [0, 0, 0, 0, 0, 0.5]]))
    assert tau.tolist() == pytest.approx([-0.15, 0.15])


def test_damping_between_bodies_stops_their_relative_spin_and_keeps_angular_momentum(
    run_both, assert_engines_agree
):
    # Two rods pinned end to end in free space, spinning in opposite directions: internal damping
    # must bring them to a common rate without creating net angular momentum (which stays 0).
    rods = (
        Body("a", Box(0.03, 0.4), (1.0, 1.2), angular_velocity=1.0),
        Body("b", Box(0.03, 0.4), (1.0, 0.8), angular_velocity=-1.0),
    )
    scene = Scene(
        "rods",
        rods,
        bounds=(0, 0, 2, 2),
        gravity=(0, 0),
        fps=60,
        frames=121,
        substeps=10,
        joints=(Joint("b", (1.0, 1.0), "a"),),
    ).validate()
    trajs = run_both(scene, lambda: [JointViscousDamping(c=0.02)])
    inertia = rods[0].inertia()
    for tr in trajs:
        s = tr.states
        rel = s[:, 0, 5] - s[:, 1, 5]
        assert abs(rel[-1]) < 0.05 * abs(rel[0])
        spin = inertia * s[:, :, 5].sum(axis=1) + (
            s[:, :, 0] * s[:, :, 4] - s[:, :, 1] * s[:, :, 3]
        ).sum(axis=1)  # m = 1
        assert np.abs(spin).max() < 1e-3 * inertia
    assert_engines_agree(trajs, pose_tol=2e-3, vel_tol=1e-2)
