"""The simulator kit: checks of a :class:`~physbench.simulators.base.Simulator` against physics
with closed-form answers, on small probe scenes (1 s at 30 fps, 10 substeps; a few ms each in the
built-in engines).

Tolerances allow a first-order integrator: a body under constant acceleration ``a`` may lag the
exact solution by ``h·|a|·t`` (``h`` the substep; semi-implicit Euler lags by half that), plus
1e-4 for single-precision engines. Kit setting: ``subprocess`` (``False`` leaves out the
other-process check).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.errors import SimulationError
from physbench.parameter import Parameter
from physbench.scene import Body, Box, Circle, Force, Scene, Segment
from physbench.simulators.base import Simulator
from physbench.testing.kit import (
    Check,
    ConformanceError,
    Subject,
    construct,
    import_path,
    label,
    load,
    require_contract,
    run_checks,
    run_in_child,
)
from physbench.trajectory import STATE_FIELDS, Trajectory

#: Absolute slack on positions (m) and velocities (m/s) for engines that compute in float32.
ATOL = 1e-4


# --------------------------------------------------------------------------- probe scenes


def contact_scene() -> Scene:
    """A box tumbling onto a floor and two balls colliding above it: contacts, friction and
    rotation, for the determinism checks."""
    bodies = (
        Body("box", Box(0.4, 0.3), (2.0, 1.2), angle=0.3, angular_velocity=1.0, mass=2.0),
        Body("left", Circle(0.2), (0.6, 2.5), velocity=(3.0, 0.5), elasticity=0.8),
        Body("right", Circle(0.2), (3.4, 2.5), velocity=(-3.0, 0.5), mass=1.5, elasticity=0.8),
    )
    floor = Segment((0.0, 0.2), (4.0, 0.2), elasticity=0.9, friction=0.8)
    return Scene("kit_contacts", bodies, frames=31, statics=(floor,)).validate()


def free_fall_scene() -> Scene:
    """A ball and a spinning box thrown upwards, far apart: nothing but gravity acts."""
    bodies = (
        Body("ball", Circle(0.1), (0.5, 3.5), velocity=(1.0, 2.0), angular_velocity=1.0),
        Body(
            "box",
            Box(0.2, 0.1),
            (2.5, 3.8),
            velocity=(-0.5, 1.0),
            angular_velocity=-2.0,
            mass=3.0,
        ),
    )
    return Scene("kit_free_fall", bodies, frames=31).validate()


def collision_scene() -> Scene:
    """A 1 kg and a 3 kg ball meeting head on at 2 m/s each, no gravity, elasticity 1: after the
    impact the light one moves at -4 m/s and the heavy one stops."""
    bodies = (
        Body("light", Circle(0.2), (1.2, 2.0), velocity=(2.0, 0.0), mass=1.0, elasticity=1.0),
        Body("heavy", Circle(0.2), (2.8, 2.0), velocity=(-2.0, 0.0), mass=3.0, elasticity=1.0),
    )
    return Scene("kit_collision", bodies, gravity=(0.0, 0.0), frames=31).validate()


def push_scene() -> Scene:
    """A 1 N force along x on ``pushed`` for the whole second, no gravity; ``still`` rests."""
    bodies = (
        Body("pushed", Circle(0.1), (0.5, 2.0)),
        Body("still", Circle(0.1), (3.0, 3.0)),
    )
    push = Force("pushed", (1.0, 0.0), 0.0, 1.0)
    return Scene("kit_push", bodies, gravity=(0.0, 0.0), frames=31, forces=(push,)).validate()


def explosion_scene() -> Scene:
    """An impulse of 1e9 N·s on a 1 kg ball at t = 0.1 s: no engine can report that sanely."""
    bodies = (Body("ball", Circle(0.1), (2.0, 2.0)),)
    kick = Force("ball", (1e9, 0.0), 0.1, kind="impulse")
    return Scene("kit_explosion", bodies, frames=31, forces=(kick,)).validate()


class KitPush(Effect):
    """The kit's own effect: a force ``f`` (N) along x on every body."""

    name: ClassVar[str] = "kit_push"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("f", -10.0, 10.0, unit="N", default=0.0, doc="force along x"),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f, tau = self.zeros(states.shape[0])
        f[:, 0] = self.values["f"]
        return f, tau


# --------------------------------------------------------------------------- helpers


def _build(cls: type, options: Mapping[str, Any]) -> Simulator:
    sim: Simulator = construct(cls, options, Simulator)
    return sim


def _simulate(
    cls: type,
    sim: Simulator,
    scene: Scene,
    params: Mapping[str, float] | None = None,
    effects: Sequence[Effect] = (),
) -> Trajectory:
    """``sim.simulate(...)``, any exception or a malformed result turned into a finding."""
    try:
        traj = sim.simulate(scene, params, effects=effects)
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: simulating the probe scene {scene.name!r} raised "
            f"{type(exc).__name__}: {exc}"
        ) from exc
    if not isinstance(traj, Trajectory):
        raise ConformanceError(
            f"{label(cls)}: simulate() returned {type(traj).__name__}, expected a "
            "physbench.trajectory.Trajectory"
        )
    expected = (scene.frames, len(scene.bodies), len(STATE_FIELDS))
    if tuple(traj.bodies) != scene.body_names or traj.states.shape != expected:
        raise ConformanceError(
            f"{label(cls)}: on the probe scene {scene.name!r} simulate() returned bodies "
            f"{list(traj.bodies)} and states {traj.states.shape}; expected bodies "
            f"{list(scene.body_names)} and states {expected} (frames, bodies, "
            f"{', '.join(STATE_FIELDS)})"
        )
    return traj


def _worst(
    traj: Trajectory, field: int, expected: np.ndarray, slack: np.ndarray
) -> tuple[int, int, float] | None:
    """(frame, body, value) where ``states[..., field]`` is furthest beyond ``expected ±
    slack``, or None when every value is within."""
    excess = np.abs(traj.states[:, :, field] - expected) - slack
    if not (excess > 0).any() and np.isfinite(excess).all():
        return None
    excess = np.where(np.isfinite(excess), excess, np.inf)
    t, i = np.unravel_index(int(np.argmax(excess)), excess.shape)
    return int(t), int(i), float(traj.states[t, i, field])


# --------------------------------------------------------------------------- checks


def check_protocol(cls: type[Simulator], **options: Any) -> None:
    """``name`` is a non-empty string; ``cls(**options)`` builds a
    :class:`~physbench.simulators.base.Simulator` whose ``simulate`` returns one frame per scene
    frame, one row per body in scene order, times ``k / fps``, and the scene's initial state in
    frame 0."""
    require_contract(cls, Simulator)
    scene = contact_scene()
    traj = _simulate(cls, _build(cls, options), scene)
    times = np.arange(scene.frames) / scene.fps
    if traj.times.shape != times.shape or not np.allclose(traj.times, times, rtol=0, atol=1e-9):
        raise ConformanceError(
            f"{label(cls)}: trajectory times {traj.times[:3].tolist()}... are not frame k at "
            f"k / fps = {times[:3].tolist()}..."
        )
    initial = np.array(
        [(*b.position, b.angle, *b.velocity, b.angular_velocity) for b in scene.bodies]
    )
    diff = np.abs(traj.states[0] - initial)
    if not (diff <= ATOL).all():
        i, f = np.unravel_index(
            int(np.argmax(np.where(np.isfinite(diff), diff, np.inf))), diff.shape
        )
        raise ConformanceError(
            f"{label(cls)}: frame 0 must be the scene's initial state; body "
            f"{scene.bodies[i].name!r} has {STATE_FIELDS[f]} = {float(traj.states[0, i, f])!r}, "
            f"the scene says {float(initial[i, f])!r}"
        )


def _first_difference(a: np.ndarray, b: np.ndarray, scene: Scene) -> str:
    t, i, f = np.argwhere(~((a == b) | (np.isnan(a) & np.isnan(b))))[0]
    return (
        f"frame {t}, body {scene.bodies[i].name!r}, {STATE_FIELDS[f]}: {float(a[t, i, f])!r} vs "
        f"{float(b[t, i, f])!r}"
    )


def check_deterministic(cls: type[Simulator], **options: Any) -> None:
    """The same scene gives the identical trajectory twice from one instance and once from a
    fresh one (a scene with contacts, friction and rotation)."""
    scene = contact_scene()
    sim = _build(cls, options)
    a = _simulate(cls, sim, scene).states
    for again, what in ((sim, "the same instance"), (_build(cls, options), "a fresh instance")):
        b = _simulate(cls, again, scene).states
        if not np.array_equal(a, b, equal_nan=True):
            raise ConformanceError(
                f"{label(cls)}: simulating {scene.name!r} again with {what} differs at "
                f"{_first_difference(a, b, scene)}"
            )


def check_deterministic_in_subprocess(cls: type[Simulator], **options: Any) -> None:
    """A fresh Python process (another hash seed) gives the identical trajectory. Options must be
    JSON values; the class must be importable at module level."""
    spec = {"cls": import_path(cls), "options": options}
    theirs = np.array(run_in_child(cls, "physbench.testing.simulators:_child_states", spec))
    scene = contact_scene()
    ours = _simulate(cls, _build(cls, options), scene).states
    if theirs.shape != ours.shape or not np.array_equal(ours, theirs, equal_nan=True):
        where = (
            _first_difference(ours, theirs, scene)
            if theirs.shape == ours.shape
            else f"shape {theirs.shape} vs {ours.shape}"
        )
        raise ConformanceError(
            f"{label(cls)}: simulating {scene.name!r} in another process differs at {where}; "
            "a simulation must not depend on hash order, the time or global state"
        )


def _child_states(spec: Mapping[str, Any]) -> list[Any]:
    cls = load(spec["cls"])
    states: list[Any] = _build(cls, spec["options"]).simulate(contact_scene()).states.tolist()
    return states


def check_free_fall(cls: type[Simulator], **options: Any) -> None:
    """Bodies thrown in gravity follow ``x0 + v0 t + g t²/2`` and ``v0 + g t``, and turn at their
    constant angular velocity."""
    scene = free_fall_scene()
    traj = _simulate(cls, _build(cls, options), scene)
    h = scene.dt / scene.substeps
    t = traj.times[:, None]
    gx, gy = scene.gravity
    g = math.hypot(gx, gy)
    p0 = np.array([b.position for b in scene.bodies])
    v0 = np.array([b.velocity for b in scene.bodies])
    w0 = np.array([b.angular_velocity for b in scene.bodies])
    a0 = np.array([b.angle for b in scene.bodies])
    expected = {
        0: (p0[:, 0] + v0[:, 0] * t + gx * t * t / 2, ATOL + h * g * t),
        1: (p0[:, 1] + v0[:, 1] * t + gy * t * t / 2, ATOL + h * g * t),
        2: (a0 + w0 * t, ATOL + 0 * t),
        3: (v0[:, 0] + gx * t, 10 * ATOL + h * g + 0 * t),
        4: (v0[:, 1] + gy * t, 10 * ATOL + h * g + 0 * t),
        5: (w0 + 0 * t, 10 * ATOL + 0 * t),
    }
    for field, (want, slack) in expected.items():
        bad = _worst(traj, field, want, slack)
        if bad is not None:
            k, i, got = bad
            raise ConformanceError(
                f"{label(cls)}: free fall: body {scene.bodies[i].name!r} at frame {k} "
                f"(t = {traj.times[k]:.3g} s) has {STATE_FIELDS[field]} = {got:.6g}, expected "
                f"{want[k, i]:.6g} ± {slack[k, 0]:.2g} (gravity {scene.gravity} m/s², frame "
                f"k at k / fps, {scene.substeps} substeps per frame)"
            )


def check_collision(cls: type[Simulator], **options: Any) -> None:
    """Two free balls (1 kg and 3 kg, elasticity 1, no gravity) meet head on: total momentum is
    conserved at every frame, and after the impact their velocities are the elastic ones (-4 and
    0 m/s) within 2% of the approach speed."""
    scene = collision_scene()
    traj = _simulate(cls, _build(cls, options), scene)
    m = np.array([b.mass for b in scene.bodies])
    p = (traj.states[:, :, 3:5] * m[None, :, None]).sum(axis=1)
    scale = float(sum(b.mass * math.hypot(*b.velocity) for b in scene.bodies))
    drift = np.abs(p - p[0]).max(axis=1)
    if not (drift <= 1e-4 * scale).all():
        k = int(np.argmax(np.where(np.isfinite(drift), drift, np.inf)))
        raise ConformanceError(
            f"{label(cls)}: momentum is not conserved in a collision of two free bodies: at "
            f"frame {k} it is {p[k].tolist()} kg·m/s, at frame 0 {p[0].tolist()}"
        )
    (u1, _), (u2, _) = (b.velocity for b in scene.bodies)
    m1, m2 = m
    want = np.array(
        [((m1 - m2) * u1 + 2 * m2 * u2) / (m1 + m2), ((m2 - m1) * u2 + 2 * m1 * u1) / (m1 + m2)]
    )
    got = traj.states[-1, :, 3]
    if not (np.abs(got - want) <= 0.02 * abs(u1 - u2)).all():
        raise ConformanceError(
            f"{label(cls)}: after an elastic head-on collision (masses {m.tolist()} kg, "
            f"velocities {u1} and {u2} m/s, elasticity 1 x 1) the velocities are "
            f"{got.tolist()} m/s, expected {want.tolist()}"
        )


def check_explosion_raises(cls: type[Simulator], **options: Any) -> None:
    """An absurd scene (an impulse of 1e9 N·s on a 1 kg ball) raises
    :class:`~physbench.errors.SimulationError`, not another exception, NaN or a body light-years
    away."""
    scene = explosion_scene()
    sim = _build(cls, options)
    try:
        traj = sim.simulate(scene)
    except SimulationError:
        return
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: an exploding simulation ({scene.name!r}: impulse 1e9 N·s on 1 kg) "
            f"raised {type(exc).__name__}: {exc}; raise physbench.errors.SimulationError"
        ) from exc
    with np.errstate(invalid="ignore"):
        far = float(np.nanmax(np.abs(np.asarray(traj.states, dtype=float)[:, :, :2])))
    raise ConformanceError(
        f"{label(cls)}: an exploding simulation ({scene.name!r}: impulse 1e9 N·s on 1 kg) "
        f"returned a trajectory (largest |position| {far:.3g} m, NaN: "
        f"{bool(np.isnan(traj.states).any())}) instead of raising "
        "physbench.errors.SimulationError"
    )


def check_applies_params(cls: type[Simulator], **options: Any) -> None:
    """``simulate(scene, {"pushed.mass": 4.0})`` simulates the body with that mass: a 1 N push
    moves it ``t²/8`` m instead of ``t²/2``; other bodies are untouched."""
    scene = push_scene()
    sim = _build(cls, options)
    h = scene.dt / scene.substeps
    force = scene.forces[0].vector[0]
    for params in ({}, {"pushed.mass": 4.0}):
        traj = _simulate(cls, sim, scene, params)
        mass = params.get("pushed.mass", scene.bodies[0].mass)
        a = force / mass
        t = traj.times
        x0 = scene.bodies[0].position[0]
        checks = (
            ("pushed", 0, x0 + a * t * t / 2, ATOL + h * a * t),
            ("pushed", 3, a * t, 10 * ATOL + h * a + 0 * t),
            ("still", 0, scene.bodies[1].position[0] + 0 * t, ATOL + 0 * t),
        )
        for body, field, want, slack in checks:
            got = traj.body(body)[:, field]
            bad = np.abs(got - want) > slack
            if bad.any() or not np.isfinite(got).all():
                k = int(np.argmax(bad | ~np.isfinite(got)))
                raise ConformanceError(
                    f"{label(cls)}: with params {params} body {body!r} has "
                    f"{STATE_FIELDS[field]} = {got[k]:.6g} at t = {t[k]:.3g} s, expected "
                    f"{want[k]:.6g} (a {force} N push on {mass} kg); simulate() must apply "
                    "'body.param' values to the scene before building it"
                )


def check_applies_effects(cls: type[Simulator], **options: Any) -> None:
    """``simulate(scene, {"kit_push.f": 3.0}, effects=[KitPush()])`` calls the effect's ``setup``
    with its values and applies its force every substep: 3 N on a 1 kg body."""
    scene = replace(push_scene(), forces=())  # the same bodies, without the scene's own force
    sim = _build(cls, options)
    h = scene.dt / scene.substeps
    traj = _simulate(cls, sim, scene, {"kit_push.f": 3.0}, [KitPush()])
    t = traj.times[:, None]
    m = np.array([b.mass for b in scene.bodies])
    a = 3.0 / m
    bad = _worst(traj, 3, a * t, 10 * ATOL + h * a + 0 * t)
    if bad is not None:
        k, i, got = bad
        raise ConformanceError(
            f"{label(cls)}: with effects=[KitPush()] and params {{'kit_push.f': 3.0}}, body "
            f"{scene.bodies[i].name!r} has vx = {got:.6g} m/s at t = {traj.times[k]:.3g} s, "
            f"expected {a[i] * traj.times[k]:.6g}; simulate() must call each effect's "
            "setup(scene, values) with the '<key>.<param>' values of params and apply its "
            "forces every substep"
        )


#: Kit settings the simulator checks take.
SETTINGS = frozenset({"subprocess"})
#: Every simulator check, in the order they run.
CHECKS = (
    check_protocol,
    check_deterministic,
    check_free_fall,
    check_collision,
    check_applies_params,
    check_applies_effects,
    check_explosion_raises,
    check_deterministic_in_subprocess,
)


def yield_checks(subject: Subject) -> Iterator[Any]:
    """The simulator checks: all, less the other-process check when the kit setting
    ``subprocess`` is false."""
    for check in CHECKS:
        if check is check_deterministic_in_subprocess and not subject.kit.get("subprocess", True):
            continue
        yield check


def check_simulator(cls: type[Simulator], /, *, subprocess: bool = True, **options: Any) -> None:
    """Every simulator check on ``cls(**options)``; raises one :class:`ConformanceError` listing
    every failure."""
    subject = Subject(cls, options, {"subprocess": subprocess})
    checks = [Check(f) for f in yield_checks(subject)]
    run_checks(subject, checks, stop_after=check_protocol.__name__)
