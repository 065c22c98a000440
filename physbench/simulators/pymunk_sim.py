"""The pymunk (Chipmunk2D) simulator.

Chipmunk steps positions *before* velocities (x += h v_old; v += h a), Box2D after (v += h a;
x += h v_new): left alone, a falling body in pymunk would sit g·h·t above Box2D's (3 cm after 1 s
at 300 Hz). The two orders are the same sequence of operations shifted by half a step, so this
adapter reports Chipmunk's state the Box2D way: the position reported is the one Chipmunk will
integrate to at the start of the next step, ``x + h v``. Both engines then collide at, and report,
the same positions (see ``docs/engines.md``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any, ClassVar

from physbench.hookspecs import hookimpl
from physbench.scene import Box, Circle, Scene, Segment
from physbench.simulators.stepping import EngineWorld, SteppingSimulator, initial_com_state

#: Allowed overlap between shapes (m); Box2D's linear slop is the same 5 mm.
COLLISION_SLOP = 0.005


class PymunkWorld(EngineWorld):
    contact_hook = True
    max_speed = math.inf  # Chipmunk never clamps motion
    max_angular_speed = math.inf

    def __init__(self, scene: Scene, iterations: int, velocity_threshold: float = 0.0) -> None:
        import pymunk

        h = self.h = scene.dt / scene.substeps
        space = pymunk.Space()
        space.gravity = scene.gravity
        space.iterations = iterations
        space.collision_slop = COLLISION_SLOP
        static = space.static_body
        shapes: list[Any] = []
        for s in scene.statics:
            if isinstance(s, Segment):
                sh = pymunk.Segment(static, s.a, s.b, s.radius)
            else:
                sh = pymunk.Poly(static, list(s.points))
            sh.elasticity, sh.friction = s.elasticity, s.friction
            shapes.append(sh)
        self.bodies: list[Any] = []
        com = initial_com_state(scene)
        for b, (x, y, a, vx, vy, w) in zip(scene.bodies, com, strict=True):
            body = pymunk.Body(b.mass, b.inertia())  # mass set on the body: shapes carry none
            # Half a step back, so that the first position update lands on the scene's pose.
            body.position, body.angle = (x - h * vx, y - h * vy), a - h * w
            body.velocity, body.angular_velocity = (vx, vy), w
            dx, dy = b.com_offset
            if isinstance(b.shape, Circle):
                sh = pymunk.Circle(body, b.shape.radius, (-dx, -dy))
            else:
                verts = b.shape.vertices() if isinstance(b.shape, Box) else b.shape.points
                sh = pymunk.Poly(body, [(px - dx, py - dy) for px, py in verts])
            sh.elasticity, sh.friction = b.elasticity, b.friction
            self.bodies.append(body)
            shapes.extend([body, sh])
        space.add(*shapes)
        index = {b.name: i for i, b in enumerate(scene.bodies)}
        for j in scene.joints:
            # Anchors in body coordinates from the scene's pose (the bodies sit half a step back).
            ia, ib = index[j.a], (index[j.b] if j.b else None)
            joint = pymunk.PivotJoint(
                self.bodies[ia],
                self.bodies[ib] if ib is not None else static,
                _local(com[ia], j.anchor),
                _local(com[ib], j.anchor) if ib is not None else j.anchor,
            )
            joint.collide_bodies = False  # as Box2D's default for joined bodies
            space.add(joint)
        if velocity_threshold > 0:
            space.on_collision(begin=_inelastic_below(velocity_threshold))
        self.velocity_threshold = velocity_threshold
        self.space = space
        self._batch = _BatchReader.for_world(self)

    def step(self, h: float) -> None:
        self.space.step(h)

    def read(self) -> list[float]:
        out = self._batch.read() if self._batch is not None else self.read_bodies()
        h = self.h
        for i in range(0, len(out), 6):
            out[i] += h * out[i + 3]
            out[i + 1] += h * out[i + 4]
            out[i + 2] += h * out[i + 5]
        return out

    def read_bodies(self) -> list[float]:
        """Chipmunk's own state ``[x, y, angle, vx, vy, omega] * N``, one body at a time."""
        out: list[float] = []
        for b in self.bodies:
            (px, py), (vx, vy) = b.position, b.velocity
            out += (px, py, b.angle, vx, vy, b.angular_velocity)
        return out

    def apply_force(self, i: int, fx: float, fy: float) -> None:
        b = self.bodies[i]
        b.apply_force_at_world_point((fx, fy), b.position)

    def apply_torque(self, i: int, tau: float) -> None:
        self.bodies[i].torque += tau

    def set_restitution_hook(self, hook: Callable[[float, int, int | None], float | None]) -> None:
        """Ask ``hook`` for the restitution of every contact when it starts (Chipmunk resets a
        contact's restitution to the product every step, so it is re-applied each step until the
        shapes separate)."""
        index = {b: i for i, b in enumerate(self.bodies)}
        chosen: dict[tuple[int, int], float | None] = {}
        threshold = self.velocity_threshold

        def pair(arbiter: Any) -> tuple[int, int]:
            a, b = arbiter.shapes
            return (id(a), id(b)) if id(a) < id(b) else (id(b), id(a))

        def pre_solve(arbiter: Any, space: Any, data: Any) -> None:
            key = pair(arbiter)
            if arbiter.is_first_contact:
                e = None
                points = arbiter.contact_point_set.points
                a, b = arbiter.bodies
                ia, ib = index.get(a), index.get(b)
                if points and (ia is not None or ib is not None):
                    p = points[0].point_a
                    speed = max(
                        0.0,
                        -(b.velocity_at_world_point(p) - a.velocity_at_world_point(p)).dot(
                            arbiter.normal
                        ),
                    )
                    e = hook(speed, ia, ib) if ia is not None else hook(speed, ib, None)  # type: ignore[arg-type]
                    if e is not None and speed < threshold:
                        e = 0.0  # as the begin handler of velocity_threshold would
                chosen[key] = e
            e = chosen.get(key)
            if e is not None:
                arbiter.restitution = e

        def separate(arbiter: Any, space: Any, data: Any) -> None:
            chosen.pop(pair(arbiter), None)

        self.space.on_collision(pre_solve=pre_solve, separate=separate)

    def apply_impulse(self, i: int, jx: float, jy: float) -> None:
        # The velocity change must not move the already-reported position x + h v.
        b, h = self.bodies[i], self.h
        dvx, dvy = jx / b.mass, jy / b.mass
        b.velocity = (b.velocity.x + dvx, b.velocity.y + dvy)
        b.position = (b.position.x - h * dvx, b.position.y - h * dvy)


class _BatchReader:
    """Reads every body in one call through ``pymunk.batch`` (4x faster than per-body properties
    at 5 bodies). The module is marked experimental, so it is used only when it reads back exactly
    what the per-body properties give, in body order."""

    def __init__(self, space: Any, n: int) -> None:
        import pymunk.batch as batch

        self.space, self.get, self.buf = space, batch.get_space_bodies, batch.Buffer()
        self.n = 6 * n  # the space's static body follows the dynamic ones
        f = batch.BodyFields
        self.fields = f.POSITION | f.ANGLE | f.VELOCITY | f.ANGULAR_VELOCITY

    def read(self) -> list[float]:
        self.buf.clear()
        self.get(self.space, self.fields, self.buf)
        return memoryview(self.buf.float_buf()).cast("d")[: self.n].tolist()

    @classmethod
    def for_world(cls, world: PymunkWorld) -> _BatchReader | None:
        if not _batch_layout_ok():
            return None
        reader = cls(world.space, len(world.bodies))
        return reader if reader.read() == world.read_bodies() else None


@functools.cache
def _batch_layout_ok() -> bool:
    """Whether ``pymunk.batch`` returns ``x, y, angle, vx, vy, omega`` per body in insertion order
    (checked once on bodies whose every field differs)."""
    try:
        import pymunk

        space = pymunk.Space()
        for k in (1.0, 2.0):
            b = pymunk.Body(1.0, 1.0)
            b.position, b.angle, b.velocity, b.angular_velocity = (
                (k, k + 0.1),
                k + 0.2,
                (k + 0.3, k + 0.4),
                k + 0.5,
            )
            space.add(b, pymunk.Circle(b, 0.1))
        expected = [v for k in (1.0, 2.0) for v in (k, k + 0.1, k + 0.2, k + 0.3, k + 0.4, k + 0.5)]
        return _BatchReader(space, 2).read() == expected
    except Exception:
        return False


def _inelastic_below(threshold: float) -> Callable[[Any, Any, Any], None]:
    """A ``begin`` handler that makes a contact inelastic when its bodies first meet slower than
    ``threshold`` m/s along the normal, as Box2D's ``b2_velocityThreshold`` does."""

    def begin(arbiter: Any, space: Any, data: Any) -> None:
        points = arbiter.contact_point_set.points
        if not points:
            return
        a, b = arbiter.bodies
        p = points[0].point_a
        if (b.velocity_at_world_point(p) - a.velocity_at_world_point(p)).dot(
            arbiter.normal
        ) > -threshold:
            arbiter.restitution = 0.0

    return begin


def _local(pose: tuple[float, ...], point: tuple[float, float]) -> tuple[float, float]:
    """``point`` (world) in the frame of a body whose CoM pose is ``(x, y, angle, ...)``."""
    x, y, a = pose[0], pose[1], pose[2]
    c, s = math.cos(a), math.sin(a)
    dx, dy = point[0] - x, point[1] - y
    return (c * dx + s * dy, -s * dx + c * dy)


class PymunkSimulator(SteppingSimulator):
    """Chipmunk2D through pymunk: iterative impulse solver, ``iterations`` per step.

    ``velocity_threshold`` (m/s, default 0: off) makes contacts that begin slower than it
    inelastic, mimicking Box2D's compiled-in 1 m/s; it costs a Python call per new contact.
    """

    name: ClassVar[str] = "pymunk"

    def __init__(self, iterations: int = 10, velocity_threshold: float = 0.0) -> None:
        self.iterations = iterations
        self.velocity_threshold = velocity_threshold

    def build(self, scene: Scene) -> PymunkWorld:
        return PymunkWorld(scene, self.iterations, self.velocity_threshold)


@hookimpl
def register_simulators() -> list[type]:
    return [PymunkSimulator]
