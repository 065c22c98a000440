"""The shared stepping loop, run through both built-in engines: analytic free motion, contacts,
joints, force windows and impulses, effects, typed failures, determinism.

Every test runs in both engines. Tolerances: pymunk works in float64; Box2D stores float32, so its
values carry ~1e-7 relative rounding per step (``FLOAT``). Both integrate with semi-implicit
Euler, whose positions under constant acceleration ``a`` lag the continuous solution by exactly
``a h t / 2`` (``h`` = substep); free-fall tests check that discrete solution tightly.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import pytest

from physbench.effects import LinearDrag, TableTilt, VelocityDependentRestitution
from physbench.effects.base import Effect
from physbench.errors import PhysbenchError, SimulationError
from physbench.parameter import Parameter
from physbench.scene import (
    Body,
    Box,
    Circle,
    Force,
    Joint,
    Polygon,
    Scene,
    Segment,
    StaticPolygon,
)
from physbench.scenes.bin import bin_walls
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.simulators.stepping import SteppingSimulator
from physbench.trajectory import Trajectory

G = 9.81


def _period(t: np.ndarray, x: np.ndarray) -> float:
    """Mean period from the zero crossings of ``x`` (linear interpolation between frames)."""
    i = np.where(np.sign(x[:-1]) * np.sign(x[1:]) < 0)[0]
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    assert len(tz) >= 4, "too few oscillations to measure a period"
    return float(2 * np.mean(np.diff(tz)))


@pytest.mark.parametrize("v0", [(0.0, 0.0), (3.0, 7.0)], ids=["free_fall", "projectile"])
def test_ballistic_motion_matches_analytic(
    sim: SteppingSimulator, tol: float, v0: tuple[float, float]
) -> None:
    scene = Scene(
        "ballistic",
        (Body("b", Circle(0.1), (1.0, 15.0), velocity=v0),),
        bounds=(0.0, 0.0, 20.0, 20.0),
        fps=30,
        frames=46,
        substeps=10,
    )
    tr = sim.simulate(scene)
    t, s = tr.times, tr.body("b")
    h = scene.dt / scene.substeps
    x = 1.0 + v0[0] * t
    y_exact = 15.0 + v0[1] * t - G * t**2 / 2
    y_euler = y_exact - G * h * t / 2  # semi-implicit Euler's known O(h) lag
    tol = tol
    np.testing.assert_allclose(s[:, 0], x, atol=tol)
    np.testing.assert_allclose(s[:, 1], y_euler, atol=tol)
    np.testing.assert_allclose(s[:, 3], v0[0], atol=tol)
    np.testing.assert_allclose(s[:, 4], v0[1] - G * t, atol=tol)
    assert np.abs(s[:, 1] - y_exact).max() <= G * h * t[-1] / 2 + tol
    np.testing.assert_array_equal(tr.times, np.arange(46) / 30)
    assert tr.engine == sim.name and tr.bodies == ("b",)


def test_slow_bodies_never_sleep(sim: SteppingSimulator) -> None:
    """A body slower than Box2D's sleep tolerances (1 cm/s, 2°/s) for more than 0.5 s keeps moving
    (pybox2d puts it to sleep even in a world with sleeping off, unless the body forbids it)."""
    body = Body("b", Box(0.2, 0.2), (2.0, 2.0), velocity=(0.005, 0.0), angular_velocity=0.02)
    tr = sim.simulate(Scene("creep", (body,), gravity=(0.0, 0.0), frames=61))
    s = tr.body("b")
    assert s[-1, 0] - 2.0 == pytest.approx(0.005 * tr.times[-1], abs=1e-4)  # asleep: < 0.005
    assert s[-1, 2] == pytest.approx(0.02 * tr.times[-1], abs=1e-4)


def test_angle_is_ccw_and_velocities_match_finite_differences(sim: SteppingSimulator) -> None:
    """Positive ω turns counter-clockwise (y up); reported velocities are those of the shape
    centre, also when the centre of mass is elsewhere."""
    body = Body(
        "b",
        Box(0.4, 0.2),
        (2.0, 2.0),
        velocity=(0.5, -0.2),
        angular_velocity=2.0,
        com_offset=(0.1, 0.05),
    )
    scene = Scene("spin", (body,), gravity=(0.0, 0.0), fps=60, frames=61)
    tr = sim.simulate(scene)
    t, s = tr.times, tr.body("b")
    np.testing.assert_allclose(s[:, 2], 2.0 * t, atol=1e-4)  # CCW: angle grows with +ω
    assert s[0, 3:5].tolist() == pytest.approx([0.5, -0.2], abs=1e-6)  # the centre velocity given
    # Central differences of centre positions; error bound ω² |r| dt² / 6 ≈ 3e-5.
    dt = scene.dt
    vx_fd = (s[2:, 0] - s[:-2, 0]) / (2 * dt)
    vy_fd = (s[2:, 1] - s[:-2, 1]) / (2 * dt)
    np.testing.assert_allclose(s[1:-1, 3], vx_fd, atol=5e-4)
    np.testing.assert_allclose(s[1:-1, 4], vy_fd, atol=5e-4)
    # The CoM moves in a straight line at v_centre + ω × r; the centre circles around it.
    c, sn = np.cos(s[:, 2]), np.sin(s[:, 2])
    com = np.stack([s[:, 0] + c * 0.1 - sn * 0.05, s[:, 1] + sn * 0.1 + c * 0.05], axis=1)
    v_com = np.array([0.5 - 2.0 * 0.05, -0.2 + 2.0 * 0.1])
    np.testing.assert_allclose(com, np.array([2.1, 2.05]) + np.outer(t, v_com), atol=1e-4)
    # A body-frame point on the +x edge has moved to +y after a quarter turn.
    k = round((math.pi / 4) / dt)  # ω = 2 rad/s: a quarter turn at t = π/4
    corner = (c[k] * 0.2, sn[k] * 0.2)
    assert corner[1] > 0.19 and abs(corner[0]) < 0.02


@pytest.mark.parametrize(
    ("m1", "m2", "e1", "e2"),
    [(1.0, 3.0, 1.0, 1.0), (2.0, 0.5, 1.0, 1.0), (1.0, 3.0, 0.8, 0.5)],
    ids=["elastic_light_heavy", "elastic_heavy_light", "restitution_product"],
)
def test_head_on_collision(
    sim: SteppingSimulator, tol: float, m1: float, m2: float, e1: float, e2: float
) -> None:
    u1, u2 = 2.0, -1.0
    scene = Scene(
        "collide",
        (
            Body("a", Circle(0.2), (1.0, 2.0), velocity=(u1, 0.0), mass=m1, elasticity=e1),
            Body("b", Circle(0.3), (3.0, 2.0), velocity=(u2, 0.0), mass=m2, elasticity=e2),
        ),
        gravity=(0.0, 0.0),
        frames=31,
    )
    s = sim.simulate(scene).states
    p = m1 * s[:, 0, 3:5] + m2 * s[:, 1, 3:5]
    np.testing.assert_allclose(p, p[[0]].repeat(len(p), 0), atol=tol)  # momentum
    e = e1 * e2  # physbench's mixing rule: the product
    v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2)
    v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2)
    assert s[-1, 0, 3] == pytest.approx(v1, abs=1e-4)
    assert s[-1, 1, 3] == pytest.approx(v2, abs=1e-4)
    assert np.abs(s[:, :, 4]).max() < 1e-6 and np.abs(s[:, :, 5]).max() < 1e-6  # stays 1-D
    ke = 0.5 * (m1 * (s[:, 0, 3:5] ** 2).sum(1) + m2 * (s[:, 1, 3:5] ** 2).sum(1))
    if e == 1.0:
        assert ke[-1] == pytest.approx(ke[0], rel=1e-5)  # elastic: energy kept to 1e-5
    else:
        lost = 0.5 * m1 * m2 / (m1 + m2) * (1 - e**2) * (u1 - u2) ** 2
        assert ke[0] - ke[-1] == pytest.approx(lost, rel=1e-3)


@pytest.mark.parametrize("floor_kind", ["segment", "polygon"])
def test_bounce_restitution_is_product(sim: SteppingSimulator, floor_kind: str) -> None:
    """Ball e=0.8 on floor e=0.5: rebound height ratio e² with e = 0.4 (max rule: 0.64)."""
    r, drop = 0.1, 1.0
    floor = (
        Segment((0.0, 0.0), (4.0, 0.0), elasticity=0.5)
        if floor_kind == "segment"
        else StaticPolygon(((0.0, -1.0), (4.0, -1.0), (4.0, 0.0), (0.0, 0.0)), elasticity=0.5)
    )
    scene = Scene(
        "bounce",
        (Body("ball", Circle(r), (2.0, r + drop), mass=1.0, elasticity=0.8),),
        statics=(floor,),
        bounds=(0.0, -1.0, 4.0, 3.0),
        fps=120,
        frames=121,
        substeps=5,
    )
    s = sim.simulate(scene).body("ball")
    i = int(np.argmax(s[:, 4] > 0))  # first frame moving up
    j = i + int(np.argmax(s[i:, 4] <= 0))  # the apex after it
    assert 0 < i < j
    ratio = (s[j, 1] - r) / drop
    assert ratio == pytest.approx(0.4**2, abs=0.008)


@pytest.mark.parametrize("floor_kind", ["segment", "polygon"])
def test_sliding_friction_is_product(sim: SteppingSimulator, floor_kind: str) -> None:
    """A box sliding at 4 m/s decelerates at μ g with μ = 0.5 · 0.6 (the sqrt rule gives 0.548)."""
    floor = (
        Segment((0.0, 0.0), (10.0, 0.0), friction=0.6)
        if floor_kind == "segment"
        else StaticPolygon(((0.0, -1.0), (10.0, -1.0), (10.0, 0.0), (0.0, 0.0)), friction=0.6)
    )
    scene = Scene(
        "slide",
        (
            Body(
                "box", Box(0.4, 0.2), (1.0, 0.1), velocity=(4.0, 0.0), friction=0.5, elasticity=0.0
            ),
        ),
        statics=(floor,),
        bounds=(0.0, -1.0, 10.0, 3.0),
        frames=31,
    )
    tr = sim.simulate(scene)
    s = tr.body("box")
    accel = np.polyfit(tr.times[2:25], s[2:25, 3], 1)[0]
    assert accel == pytest.approx(-0.3 * G, rel=1e-3)
    assert np.abs(s[:, 1] - 0.1).max() < 2e-3  # rests on the floor, no 1-2 cm skin
    assert np.abs(s[:, 2]).max() < 1e-3  # does not tip


def test_slope_friction_is_product(sim: SteppingSimulator) -> None:
    """A box on a 30° slope slides down at g (sin θ − μ cos θ), μ = 0.5 · 0.6."""
    th = math.radians(30.0)
    c, sn = math.cos(th), math.sin(th)
    start = (0.5 + 6 * c - 0.1 * sn, 0.5 + 6 * sn + 0.1 * c)
    scene = Scene(
        "slope",
        (Body("box", Box(0.4, 0.2), start, angle=th, friction=0.5, elasticity=0.0),),
        statics=(Segment((0.5, 0.5), (0.5 + 8 * c, 0.5 + 8 * sn), friction=0.6),),
        bounds=(0.0, 0.0, 8.0, 8.0),
        frames=31,
    )
    tr = sim.simulate(scene)
    s = tr.body("box")
    along = s[:, 3] * c + s[:, 4] * sn
    accel = np.polyfit(tr.times[3:25], along[3:25], 1)[0]
    assert accel == pytest.approx(-G * (sn - 0.3 * c), rel=1e-3)


def test_resting_contact_has_no_skin(sim: SteppingSimulator) -> None:
    """Circles, boxes and a stack rest on the floor touching it (within 2 mm) in both engines."""
    tri = Polygon(((-0.1, -0.1), (0.1, -0.1), (0.0, 0.1)))
    scene = Scene(
        "rest",
        (
            Body("circle", Circle(0.1), (0.5, 0.12)),
            Body("box", Box(0.2, 0.2), (1.5, 0.12)),
            Body("top", Box(0.2, 0.2), (1.5, 0.34)),
            Body("tri", tri, (2.5, 0.12)),
        ),
        statics=bin_walls((0.0, 0.0, 4.0, 4.0)),
        frames=61,
    )
    s = sim.simulate(scene).states[-1]
    assert s[:, 1] == pytest.approx([0.1, 0.1, 0.3, 0.1], abs=2e-3)


def test_pendulum_small_angle_period(sim: SteppingSimulator) -> None:
    """Bob of radius 1 cm on a 1 m pivot, 0.05 rad amplitude. The exact physical-pendulum period
    differs from 2π√(L/g) by the amplitude factor 1 + θ₀²/16 (1.6e-4) and √(I_pivot / m L²)
    (2.5e-5); the engines must match the corrected value to 3e-5 and the simple one to 3e-4."""
    L, th0, r = 1.0, 0.05, 0.01
    pivot = (2.0, 3.0)
    bob = Body("bob", Circle(r), (pivot[0] + L * math.sin(th0), pivot[1] - L * math.cos(th0)))
    scene = Scene("pendulum", (bob,), joints=(Joint("bob", pivot),), fps=60, frames=361)
    tr = sim.simulate(scene)
    s = tr.body("bob")
    period = _period(tr.times, s[:, 0] - pivot[0])
    simple = 2 * math.pi * math.sqrt(L / G)
    exact = simple * (1 + th0**2 / 16) * math.sqrt(1 + 0.5 * r**2 / L**2)
    assert period == pytest.approx(exact, rel=3e-5)
    assert period == pytest.approx(simple, rel=3e-4)
    assert np.abs(np.hypot(s[:, 0] - pivot[0], s[:, 1] - pivot[1]) - L).max() < 1e-4  # rod length


@pytest.mark.parametrize("moment", [None, 0.5], ids=["uniform", "explicit_moment"])
def test_com_offset_and_moment_are_honoured(sim: SteppingSimulator, moment: float | None) -> None:
    """A box pivoted at its shape centre with its CoM 0.3 m off swings as a physical pendulum,
    T = 2π√(I_pivot / (m g d)); the trajectory reports the (fixed) shape centre."""
    d, th0 = 0.3, 0.05
    box = Body(
        "b", Box(0.8, 0.8), (2.0, 2.0), angle=th0, mass=2.0, com_offset=(0.0, -d), moment=moment
    )
    scene = Scene("physical_pendulum", (box,), joints=(Joint("b", (2.0, 2.0)),), fps=60, frames=301)
    tr = sim.simulate(scene)
    s = tr.body("b")
    i_pivot = box.inertia() + box.mass * d * d
    expected = 2 * math.pi * math.sqrt(i_pivot / (box.mass * G * d)) * (1 + th0**2 / 16)
    assert _period(tr.times, s[:, 2]) == pytest.approx(expected, rel=3e-5)
    assert np.abs(s[:, 0:2] - 2.0).max() < 1e-5  # shape centre, not CoM, is reported
    assert np.abs(s[:, 3:5]).max() < 1e-4


def test_pivot_joint_between_bodies(sim: SteppingSimulator) -> None:
    """A bar pivoted to the world at one end, a ball pivoted to its other end: both anchors stay
    together while the double pendulum swings."""
    bar = Body("bar", Box(1.0, 0.05), (2.5, 3.0), mass=1.0)
    ball = Body("ball", Circle(0.05), (3.0, 3.0), mass=0.5)
    scene = Scene(
        "double",
        (bar, ball),
        joints=(Joint("bar", (2.0, 3.0)), Joint("bar", (3.0, 3.0), "ball")),
        fps=60,
        frames=121,
    )
    s = sim.simulate(scene).states
    a = s[:, 0, 2]
    end = np.stack([s[:, 0, 0] + 0.5 * np.cos(a), s[:, 0, 1] + 0.5 * np.sin(a)], axis=1)
    start = np.stack([s[:, 0, 0] - 0.5 * np.cos(a), s[:, 0, 1] - 0.5 * np.sin(a)], axis=1)
    assert np.abs(start - [2.0, 3.0]).max() < 3e-3  # Chipmunk's soft joints drift ~1 mm
    assert np.hypot(*(end - s[:, 1, 0:2]).T).max() < 3e-3
    assert s[:, 1, 1].min() < 2.2  # it really swung
    assert np.ptp(s[:, 1, 2]) < 1e-6  # a pivot lets the ball keep its own (zero) rotation


@pytest.mark.parametrize(("t0", "t1"), [(0.1, 0.2), (0.1037, 0.2511), (0.0, 0.0004), (0.95, 1.2)])
def test_force_window_and_impulse(sim: SteppingSimulator, t0: float, t1: float) -> None:
    """Δv = F (t1 − t0) / m for a force window (also when not aligned to substeps, shorter than one,
    or running past the end) and Δv = J / m for an impulse, in zero gravity."""
    m, F, J = 2.0, (3.0, -1.0), (0.0, 4.0)
    scene = Scene(
        "push",
        (Body("b", Circle(0.1), (2.0, 2.0), mass=m),),
        gravity=(0.0, 0.0),
        forces=(Force("b", F, t0, t1), Force("b", J, 0.5, kind="impulse")),
        frames=31,
    )
    tr = sim.simulate(scene)
    s = tr.body("b")
    t_end = tr.times[-1]
    acting = min(t1, t_end) - t0
    assert s[-1, 3] == pytest.approx(F[0] * acting / m, abs=1e-6)
    assert s[-1, 4] == pytest.approx((F[1] * acting + J[1]) / m, abs=1e-6)
    before = tr.times <= min(t0, 0.5)
    assert np.abs(s[before, 3:5]).max() == 0.0  # nothing acts before its start
    at = round(0.5 * scene.fps)
    assert s[at + 1, 4] - s[at, 4] == pytest.approx(
        (J[1] + F[1] * _overlap(t0, t1, 0.5, 0.5 + scene.dt)) / m, abs=1e-6
    )


def _overlap(a0: float, a1: float, b0: float, b1: float) -> float:
    return max(0.0, min(a1, b1) - max(a0, b0))


class _ConstantPush(Effect):
    """A test effect: a constant force and torque on body 0."""

    name: ClassVar[str] = "push"
    params: ClassVar[tuple[Parameter, ...]] = ()

    def setup(self, scene: Scene, values: object) -> None:
        pass

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f = np.zeros((len(states), 2))
        f[0] = (1.5, 0.0)
        tau = np.zeros(len(states))
        tau[0] = 0.2
        return f, tau


class _Broken(_ConstantPush):
    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise ZeroDivisionError("effect bug")


def test_effects_apply_force_and_torque(sim: SteppingSimulator) -> None:
    box = Body("b", Box(0.4, 0.2), (2.0, 2.0), mass=2.0, moment=0.1)
    scene = Scene("effect", (box,), gravity=(0.0, 0.0), frames=31)
    tr = sim.simulate(scene, effects=[_ConstantPush()])
    s = tr.body("b")
    assert s[-1, 3] == pytest.approx(1.5 * tr.times[-1] / 2.0, abs=1e-5)
    assert s[-1, 5] == pytest.approx(0.2 * tr.times[-1] / 0.1, rel=1e-5)
    with pytest.raises(ZeroDivisionError, match="effect bug"):  # effect bugs are not explosions
        sim.simulate(scene, effects=[_Broken()])


def _assert_names(err: SimulationError, sim: SteppingSimulator, body: str) -> None:
    assert err.engine == sim.name and err.body == body and isinstance(err.frame, int)
    assert f"[{sim.name}]" in str(err) and repr(body) in str(err)


def test_body_leaving_the_world_raises(sim: SteppingSimulator) -> None:
    scene = Scene("fall", (Body("b", Circle(0.1), (2.0, 2.0)),), frames=60)  # no floor
    with pytest.raises(SimulationError, match="left the world") as info:
        sim.simulate(scene)
    _assert_names(info.value, sim, "b")
    # y = 2 − g t²/2 passes ymin − world height = −4 at t = 1.106 s: frame 34 at 30 fps.
    assert info.value.frame == 34


def test_absurd_mass_raises(sim: SteppingSimulator) -> None:
    """A subnormal mass: pymunk's state turns NaN, Box2D (float32) cannot hold it."""
    scene = Scene(
        "absurd",
        (Body("ok", Circle(0.1), (1.0, 2.0)), Body("tiny", Circle(0.1), (2.0, 2.0), mass=1e-320)),
        forces=(Force("tiny", (1.0, 0.0), 0.0, 0.5),),
    )
    with pytest.raises(SimulationError) as info:
        sim.simulate(scene)
    _assert_names(info.value, sim, "tiny")
    assert info.value.frame <= 1


def test_huge_impulse_raises(sim: SteppingSimulator) -> None:
    """1e6 N·s on 1 kg inside a closed bin: pymunk tunnels out of the world, Box2D would clamp it
    to 2 m per step and keep it bouncing inside; both report an explosion."""
    scene = Scene(
        "kick",
        (Body("b", Circle(0.1), (2.0, 2.0)),),
        statics=bin_walls((0.0, 0.0, 4.0, 4.0), ceiling=True),
        forces=(Force("b", (1e6, 0.0), 0.1, kind="impulse"),),
    )
    with pytest.raises(SimulationError) as info:
        sim.simulate(scene)
    _assert_names(info.value, sim, "b")
    assert info.value.frame == 4  # the impulse acts at t = 0.1 s, in the interval before frame 4


def test_nan_impulse_raises(sim: SteppingSimulator) -> None:
    scene = Scene(
        "nan",
        (Body("b", Circle(0.1), (2.0, 2.0)),),
        forces=(Force("b", (1e300, 1e300), 0.2, kind="impulse"),),
    )
    with pytest.raises(SimulationError) as info:
        sim.simulate(scene)
    _assert_names(info.value, sim, "b")


def test_deterministic(sim: SteppingSimulator, busy_scene: Scene) -> None:
    scene = busy_scene
    first, second = sim.simulate(scene), type(sim)().simulate(scene)
    assert first.states.tobytes() == second.states.tobytes()
    assert np.ptp(first.states[:, :, 0], axis=0).min() > 0.01  # something happened


def test_params_are_applied(sim: SteppingSimulator, busy_scene: Scene) -> None:
    scene = busy_scene
    base = sim.simulate(scene)
    heavy = sim.simulate(scene, {"b.mass": 8.0})
    assert isinstance(heavy, Trajectory)
    assert not np.array_equal(base.states, heavy.states)
    assert np.array_equal(heavy.states, sim.simulate(scene.with_params({"b.mass": 8.0})).states)


# ------------------------------------------------------------- effects inside the loop


def slide(
    v: tuple[float, float] = (2.0, 0.5), mass: float = 1.0, frames: int = 41, fps: float = 20.0
) -> Scene:
    return Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=v, mass=mass),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=fps,
        frames=frames,
        substeps=4,
    ).validate()


def test_simulate_sets_effects_up_with_the_scene_as_simulated(sim: SteppingSimulator) -> None:
    # TableTilt's force is m·a: set up once with mass 1 but simulated with mass 3, the acceleration
    # must still be a, which needs setup() with the parameters applied inside simulate().
    scene = slide(v=(0.0, 0.0))
    tilt = TableTilt(ax=0.5)
    tilt.setup(scene, {})
    tr = sim.simulate(scene, {"ball.mass": 3.0, "table_tilt.ay": -0.25}, effects=[tilt])
    t = tr.times[-1]
    assert tr.body("ball")[-1, 3] == pytest.approx(0.5 * t, rel=1e-4)
    assert tr.body("ball")[-1, 4] == pytest.approx(-0.25 * t, rel=1e-4)
    assert tilt.values == {"ax": 0.5, "ay": -0.25}


def test_two_instances_of_an_effect_need_labels(sim: SteppingSimulator) -> None:
    scene = Scene(
        "two",
        (
            Body("a", Circle(0.05), (1, 1), velocity=(1, 0)),
            Body("b", Circle(0.05), (1, 3), velocity=(1, 0)),
        ),
        bounds=(0, 0, 6, 5),
        gravity=(0, 0),
        frames=31,
    )
    a, b = LinearDrag(bodies=["a"], label="drag_a"), LinearDrag(bodies=["b"], label="drag_b")
    tr = sim.simulate(scene, {"drag_a.c": 1.0, "drag_b.c": 0.0}, effects=[a, b])
    assert tr.body("a")[-1, 3] == pytest.approx(math.exp(-tr.times[-1]), rel=5e-3)
    assert tr.body("b")[-1, 3] == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(PhysbenchError, match="share the parameter key 'linear_drag'"):
        sim.simulate(scene, effects=[LinearDrag(), LinearDrag()])
    with pytest.raises(PhysbenchError, match="label"):
        LinearDrag(label="a.b")


def test_contact_hook_applies_velocity_dependent_restitution(sim: SteppingSimulator) -> None:
    # A ball dropped 1.25 m hits the floor at ~5 m/s: the rebound keeps e0 - k·v of the speed.
    scene = Scene(
        "drop",
        (Body("ball", Circle(0.1), (1.0, 1.35), elasticity=1.0),),
        statics=(Segment((-1, 0), (5, 0)),),
        bounds=(0, 0, 4, 4),
        fps=100.0,
        frames=71,
        substeps=10,
    )
    e0, k = 0.9, 0.08
    tr = sim.simulate(scene, effects=[VelocityDependentRestitution(e0=e0, k=k)])
    vy = tr.body("ball")[:, 4]
    i = int(np.argmax(np.diff(vy)))
    v_in, v_out = -vy[i], vy[i + 1]
    g_dt = 9.81 / scene.fps  # a frame of gravity on either side of the impact
    assert v_out / v_in == pytest.approx(e0 - k * v_in, abs=g_dt / v_in + 0.01)
    plain = sim.simulate(scene)
    assert plain.body("ball")[i + 1, 4] > v_out + 1.0  # without the effect: elastic


def test_restitution_hook_agrees_between_engines() -> None:
    # Normal speeds stay above Box2D's 1 m/s threshold, below which Box2D makes impacts inelastic.
    scene = Scene(
        "box",
        (
            Body(
                "puck", Circle(0.05), (0.5, 0.4), velocity=(4.0, 3.0), elasticity=1.0, friction=0.0
            ),
        ),
        statics=tuple(
            Segment(a, b)
            for a, b in (((0, 0), (2, 0)), ((2, 0), (2, 1)), ((2, 1), (0, 1)), ((0, 1), (0, 0)))
        ),
        bounds=(0, 0, 2, 1),
        gravity=(0.0, 0.0),
        fps=50.0,
        frames=41,
        substeps=10,
    )
    trs = [
        s().simulate(scene, effects=[VelocityDependentRestitution(e0=0.95, k=0.05)])
        for s in (PymunkSimulator, Box2DSimulator)
    ]
    vx, vy = ([abs(t.states[-1, 0, c]) for t in trs] for c in (3, 4))
    assert vx[0] == pytest.approx(vx[1], rel=1e-3) and vy[0] == pytest.approx(vy[1], rel=1e-3)
    # one side-wall impact at 4 m/s
    assert vx[0] == pytest.approx((0.95 - 0.05 * 4.0) * 4.0, rel=0.01)
    assert vy[0] < 0.85 * 3.0
