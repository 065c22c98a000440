"""Every force effect against its analytic solution, in both engines, and the engines against each
other; measurement and contact effects as pure functions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.effects import (
    BUILTIN_EFFECTS,
    ClockScale,
    ConstantForce,
    EffectError,
    JointCoulombFriction,
    JointQuadraticDamping,
    JointViscousDamping,
    LinearDrag,
    QuadraticDrag,
    RollingResistance,
    SensorOffset,
    TableTilt,
    VelocityDependentRestitution,
    apply_measurements,
    restitution_law,
)
from physbench.effects.base import Effect
from physbench.errors import UnknownNameError
from physbench.plugins import build_registry
from physbench.scene import Body, Box, Circle, Joint, Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory

ENGINES = [PymunkSimulator, Box2DSimulator]
G = 9.81


def run_both(scene: Scene, make_effects) -> list[Trajectory]:
    """One trajectory per engine, each with freshly set-up effects."""
    out = []
    for sim in ENGINES:
        effects = make_effects()
        for e in effects:
            e.setup(scene, {})
        out.append(sim().simulate(scene, effects=effects))
    return out


def assert_engines_agree(
    trajs: list[Trajectory], pose_tol: float = 5e-4, vel_tol: float = 1e-3
) -> None:
    """Both engines give the same poses (m, rad) and velocities, to Box2D's float32 precision."""
    a, b = trajs
    assert np.abs(a.states[:, :, :3] - b.states[:, :, :3]).max() <= pose_tol
    assert np.abs(a.states[:, :, 3:] - b.states[:, :, 3:]).max() <= vel_tol


def assert_pose(tr: Trajectory, scene: Scene, field: int, expected: np.ndarray, tol: float) -> None:
    """Pose column ``field`` (0 x, 1 y, 2 angle) of the first body matches ``expected`` within
    ``tol`` plus the engines' first-order integrator error, at most ``h·|v(t) - v(0)|``."""
    h = scene.dt / scene.substeps
    v = tr.states[:, 0, 3 + field]
    err = np.abs(tr.states[:, 0, field] - expected)
    slack = tol + h * np.abs(v - v[0])
    assert np.all(err <= slack), (
        f"[{tr.engine}] worst excess {np.max(err - slack):.3g} at frame {np.argmax(err - slack)}"
    )


def ball_scene(
    velocity=(0.0, 0.0),
    gravity=(0.0, 0.0),
    seconds=3.0,
    fps=30,
    position=(1.0, 1.0),
    bounds=(0.0, 0.0, 20.0, 20.0),
    mass=2.0,
) -> Scene:
    return Scene(
        "ball",
        (Body("ball", Circle(0.05), position, velocity=velocity, mass=mass),),
        bounds=bounds,
        gravity=gravity,
        fps=fps,
        frames=int(seconds * fps) + 1,
        substeps=10,
    ).validate()


# --------------------------------------------------------------------------- registration


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


def test_values_combine_and_bad_values_are_named():
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


# --------------------------------------------------------------------------- translation effects


def test_linear_drag_decays_velocity_exponentially():
    m, c, v0 = 2.0, 1.0, 3.0
    scene = ball_scene(velocity=(v0, 0.0), mass=m)
    trajs = run_both(scene, lambda: [LinearDrag(c=c)])
    t = trajs[0].times
    for tr in trajs:
        vx = tr.body("ball")[:, 3]
        np.testing.assert_allclose(vx, v0 * np.exp(-c / m * t), rtol=2e-3)
        assert_pose(tr, scene, 0, 1.0 + v0 * m / c * (1 - np.exp(-c / m * t)), 1e-4)
    assert_engines_agree(trajs)


def test_quadratic_drag_reaches_terminal_velocity():
    m, vt = 0.5, 4.0
    c = m * G / vt**2
    scene = ball_scene(
        gravity=(0.0, -G), seconds=3.0, position=(1.0, 38.0), bounds=(0, 0, 2, 40), mass=m
    )
    trajs = run_both(scene, lambda: [QuadraticDrag(c=c)])
    t = trajs[0].times
    for tr in trajs:
        vy = tr.body("ball")[:, 4]
        np.testing.assert_allclose(vy, -vt * np.tanh(G * t / vt), atol=5e-3 * vt)
        assert_pose(tr, scene, 1, 38.0 - vt**2 / G * np.log(np.cosh(G * t / vt)), 1e-3)
        assert abs(vy[-1] + vt) < 1e-2 * vt  # sqrt(m g / c)
    assert_engines_agree(trajs)


def test_rolling_resistance_decelerates_uniformly_and_stops():
    mu, v0 = 0.005, 0.5
    a = mu * G
    t_stop, dist = v0 / a, v0**2 / (2 * a)  # 10.2 s, 2.55 m
    scene = ball_scene(velocity=(v0, 0.0), seconds=12.0, fps=20)
    trajs = run_both(scene, lambda: [RollingResistance(mu=mu)])
    t = trajs[0].times
    moving = t < t_stop - 0.5
    for tr in trajs:
        vx, x = tr.body("ball")[:, 3], tr.body("ball")[:, 0]
        np.testing.assert_allclose(vx[moving], v0 - a * t[moving], atol=2e-3 * v0)
        assert abs(x[-1] - 1.0 - dist) < 0.01  # stop point within 1 cm
        assert abs(vx[-1]) < 1e-4  # at rest, no chatter
        assert np.all(vx > -1e-6)  # never reverses
    assert_engines_agree(trajs)


@pytest.mark.parametrize("effect", [ConstantForce(fx=0.3, fy=-0.2), TableTilt(ax=0.15, ay=-0.1)])
def test_constant_force_and_tilt_give_a_parabola(effect):
    m = 2.0
    acc = (0.15, -0.1)  # both effects: F/m = (0.15, -0.1) for m = 2
    scene = ball_scene(seconds=2.0, mass=m)
    trajs = run_both(scene, lambda: [type(effect)(**effect.values)])
    t = trajs[0].times
    for tr in trajs:
        assert_pose(tr, scene, 0, 1.0 + 0.5 * acc[0] * t**2, 1e-5)
        assert_pose(tr, scene, 1, 1.0 + 0.5 * acc[1] * t**2, 1e-5)
    assert_engines_agree(trajs)


# --------------------------------------------------------------------------- joint effects

L, W, M, THETA0 = 0.4, 0.03, 0.5, 0.2
PIVOT = (2.0, 3.0)
I_PIVOT = M * (L * L + W * W) / 12 + M * (L / 2) ** 2
MGD = M * G * L / 2


def pendulum(seconds: float = 4.0, theta0: float = THETA0) -> Scene:
    centre = (PIVOT[0] + math.sin(theta0) * L / 2, PIVOT[1] - math.cos(theta0) * L / 2)
    arm = Body("arm", Box(W, L), centre, angle=theta0, mass=M)
    return Scene(
        "pendulum",
        (arm,),
        fps=60,
        frames=int(seconds * 60) + 1,
        substeps=10,
        joints=(Joint("arm", PIVOT),),
    ).validate()


def peaks(tr: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of the angle maxima, refined by a parabola through each peak frame."""
    a, t = tr.field("angle")[:, 0], tr.times
    i = np.nonzero((a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:]))[0] + 1
    y0, y1, y2 = a[i - 1], a[i], a[i + 1]
    d = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    return t[i] + d * (t[1] - t[0]), y1 - 0.25 * (y0 - y2) * d


def test_viscous_joint_damping_decays_amplitude_exponentially():
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


def test_coulomb_joint_friction_decays_amplitude_linearly():
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
def test_coulomb_joint_friction_creeps_below_breakaway_without_chatter(sim):
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


def test_quadratic_joint_damping_loses_more_per_swing_at_large_amplitude():
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


# -------------------------------------------------------------------------- measurement and contact


def test_sensor_offset_and_clock_scale_change_only_the_measurement():
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


def test_restitution_law_and_its_hook():
    assert restitution_law(0.0, 0.9, 0.1) == pytest.approx(0.9)
    assert restitution_law(2.0, 0.9, 0.1) == pytest.approx(0.7)
    assert restitution_law(-2.0, 0.9, 0.1) == pytest.approx(0.7)  # speed, not sign
    assert restitution_law(20.0, 0.9, 0.1) == 0.0
    np.testing.assert_allclose(
        restitution_law(np.array([0.0, 1.0, 3.0]), 1.0, 0.2), [1.0, 0.8, 0.4]
    )
    e = VelocityDependentRestitution(e0=0.95, k=0.1, statics_only=True)
    scene = ball_scene()
    e.setup(scene, {})
    assert e.restitution(1.5, 0, None) == pytest.approx(0.8)
    assert e.restitution(1.5, 0, 0) is None  # body-body contacts keep the scene's restitution
    f, tau = e.forces(0.0, np.zeros((1, 6)))
    assert not f.any() and not tau.any()


def test_damping_between_bodies_stops_their_relative_spin_and_keeps_angular_momentum():
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
