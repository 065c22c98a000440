"""The Box2D simulator (pybox2d, module ``Box2D``).

Box2D mixes contact materials as max(restitution) and sqrt(friction product); a contact listener
resets both to the product, physbench's convention, when a contact begins.

Box2D gives every polygon and edge a 1 cm "skin" (``b2_polygonRadius``; edge-vs-polygon contacts
hard-code 2 cm), so boxes would rest 1-2 cm above a floor where pymunk has them touching. Shapes
are built so that the contact surface is the scene's: a dynamic polygon's core is inset by its
skin (its corners are rounded by 1 cm; the skin stays, continuous collision needs it), static
polygons have no skin, and segments become thin static boxes without skin (plus end circles for a
thick segment: the capsule pymunk builds). See ``docs/engines.md``.

Divergence kept (compiled-in constants): impacts slower than ``b2_velocityThreshold`` (1 m/s) are
inelastic; a body moves at most ``b2_maxTranslation`` (2 m) and turns at most ``b2_maxRotation``
(π/2) per step, which the stepping loop reports as an explosion.
"""

from __future__ import annotations

import functools
import math
from typing import Any, ClassVar

from physbench.errors import SimulationError
from physbench.hookspecs import hookimpl
from physbench.scene import Body, Box, Circle, Scene, Segment
from physbench.simulators.stepping import EngineWorld, SteppingSimulator, initial_com_state

#: Half thickness (m) of the static box that stands in for a segment of radius 0.
SEGMENT_HALF_THICKNESS = 1e-4


@functools.cache
def _listener_class() -> Any:
    import Box2D

    class ProductMixing(Box2D.b2ContactListener):
        def BeginContact(self, contact: Any) -> None:
            fa, fb = contact.fixtureA, contact.fixtureB
            contact.restitution = fa.restitution * fb.restitution
            contact.friction = fa.friction * fb.friction

    return ProductMixing


@functools.cache
def _hooked_listener_class() -> Any:
    """Product mixing plus a restitution hook asked in ``PreSolve`` when a contact first touches
    (``oldManifold.pointCount == 0``); the contact keeps that restitution while it lasts."""

    class HookedMixing(_listener_class()):  # type: ignore[misc]
        def __init__(self, hook: Any) -> None:
            super().__init__()
            self.hook = hook

        def PreSolve(self, contact: Any, old: Any) -> None:
            if old.pointCount != 0:
                return
            fa, fb = contact.fixtureA, contact.fixtureB
            ba, bb = fa.body, fb.body
            ia, ib = ba.userData, bb.userData
            if ia is None and ib is None:
                return
            wm = contact.worldManifold
            n = wm.normal
            p = wm.points[0]
            va, vb = ba.GetLinearVelocityFromWorldPoint(p), bb.GetLinearVelocityFromWorldPoint(p)
            speed = max(0.0, -((vb[0] - va[0]) * n[0] + (vb[1] - va[1]) * n[1]))
            e = self.hook(speed, ia, ib) if ia is not None else self.hook(speed, ib, None)
            if e is not None:
                contact.restitution = e

    return HookedMixing


def _polygon(points: Any) -> Any:
    import Box2D

    shape = Box2D.b2PolygonShape(vertices=list(points))
    shape.radius = 0.0
    return shape


def _inset(points: tuple[tuple[float, float], ...], r: float) -> list[tuple[float, float]] | None:
    """The convex CCW polygon whose edges lie ``r`` inside ``points``' edges, or None if too
    small."""
    n = len(points)
    lines = []
    for i in range(n):
        (x0, y0), (x1, y1) = points[i], points[(i + 1) % n]
        ln = math.hypot(x1 - x0, y1 - y0)
        nx, ny = (y1 - y0) / ln, (x0 - x1) / ln  # outward normal
        lines.append((nx, ny, nx * x0 + ny * y0 - r))
    out = []
    for i in range(n):
        (ax, ay, ac), (bx, by, bc) = lines[i - 1], lines[i]
        det = ax * by - ay * bx
        if abs(det) < 1e-12:
            return None
        out.append(((ac * by - ay * bc) / det, (ax * bc - ac * bx) / det))
    for i in range(n):  # every edge must keep its direction, else the polygon was thinner than 2r
        (x0, y0), (x1, y1) = points[i], points[(i + 1) % n]
        (u0, v0), (u1, v1) = out[i], out[(i + 1) % n]
        if (x1 - x0) * (u1 - u0) + (y1 - y0) * (v1 - v0) <= 0:
            return None
    return out


def _dynamic_polygon(points: tuple[tuple[float, float], ...]) -> Any:
    """A dynamic polygon whose outer surface (core plus skin) is ``points``. Box2D needs the skin on
    moving polygons: without it a fast box reaches a wall without a contact and tunnels."""
    import Box2D

    r = Box2D.b2_polygonRadius
    core = _inset(points, r)
    if core is None:  # too small for the skin: a sharp polygon (continuous collision is weaker)
        return _polygon(points)
    shape = Box2D.b2PolygonShape(vertices=core)
    shape.radius = r
    return shape


def _segment_shapes(s: Segment) -> list[Any]:
    """A segment as Box2D shapes without skin: a thin box, and end circles when it is thick."""
    import Box2D

    (ax, ay), (bx, by) = s.a, s.b
    box = Box2D.b2PolygonShape()
    box.SetAsBox(
        math.hypot(bx - ax, by - ay) / 2,
        max(s.radius, SEGMENT_HALF_THICKNESS),
        ((ax + bx) / 2, (ay + by) / 2),
        math.atan2(by - ay, bx - ax),
    )
    box.radius = 0.0
    if s.radius <= 0:
        return [box]
    return [box, *(Box2D.b2CircleShape(radius=s.radius, pos=p) for p in (s.a, s.b))]


def _add_body(world: Any, b: Body, v: tuple[float, float], w: float) -> Any:
    """Create ``b`` with CoM velocity ``v`` and angular velocity ``w``."""
    import Box2D

    dx, dy = b.com_offset
    # The Box2D body origin is the shape centre; the CoM is set through the mass data.
    # allowSleep=False: pybox2d bodies fall asleep even in a world with allowSleeping off.
    body = world.CreateDynamicBody(
        position=b.position, angle=b.angle, bullet=True, allowSleep=False
    )
    if isinstance(b.shape, Circle):
        shape = Box2D.b2CircleShape(radius=b.shape.radius)
    else:
        shape = _dynamic_polygon(b.shape.vertices() if isinstance(b.shape, Box) else b.shape.points)
    body.CreateFixture(shape=shape, density=1.0, restitution=b.elasticity, friction=b.friction)
    md = Box2D.b2MassData()
    md.mass, md.center = b.mass, (dx, dy)
    md.I = b.inertia() + b.mass * (dx * dx + dy * dy)  # Box2D wants I about the body origin
    body.massData = md
    # Box2D stores float32 and silently turns a mass it cannot hold into 1 kg.
    if not (
        math.isclose(body.mass, b.mass, rel_tol=1e-5)
        and math.isclose(body.inertia, md.I, rel_tol=1e-5)
    ):
        raise SimulationError(
            f"mass {b.mass:g} kg / moment {md.I:g} kg·m² is outside Box2D's float32 range",
            engine="box2d",
            frame=0,
            body=b.name,
        )
    body.linearVelocity, body.angularVelocity = v, w
    return body


class Box2DWorld(EngineWorld):
    contact_hook = True

    def __init__(self, scene: Scene, velocity_iterations: int, position_iterations: int) -> None:
        import Box2D

        listener = _listener_class()()
        world = Box2D.b2World(gravity=scene.gravity, doSleep=False, contactListener=listener)
        self._listener = listener  # keep alive: Box2D holds only a raw pointer
        ground = world.CreateStaticBody()
        for s in scene.statics:
            for shape in _segment_shapes(s) if isinstance(s, Segment) else [_polygon(s.points)]:
                ground.CreateFixture(shape=shape, restitution=s.elasticity, friction=s.friction)
        self.bodies: list[Any] = []
        for b, (*_, vx, vy, w) in zip(scene.bodies, initial_com_state(scene), strict=True):
            try:
                self.bodies.append(_add_body(world, b, (vx, vy), w))
                self.bodies[-1].userData = len(self.bodies) - 1  # index for the contact hook
            except SimulationError:
                raise
            except Exception as exc:  # e.g. more vertices than Box2D's b2_maxPolygonVertices
                raise SimulationError(
                    f"cannot build the body: {type(exc).__name__}: {exc}",
                    engine="box2d",
                    frame=0,
                    body=b.name,
                ) from exc
        index = {b.name: body for b, body in zip(scene.bodies, self.bodies, strict=True)}
        for j in scene.joints:
            world.CreateRevoluteJoint(
                bodyA=index[j.a], bodyB=index[j.b] if j.b else ground, anchor=j.anchor
            )
        self.world = world
        self.vi, self.pi = velocity_iterations, position_iterations
        h = scene.dt / scene.substeps
        self.max_speed = Box2D.b2_maxTranslation / h
        self.max_angular_speed = Box2D.b2_maxRotation / h

    def set_restitution_hook(self, hook: Any) -> None:
        """Ask ``hook`` for the restitution of every contact when it first touches. Box2D still
        makes impacts slower than ``b2_velocityThreshold`` (1 m/s) inelastic."""
        listener = _hooked_listener_class()(hook)
        self.world.contactListener = listener
        self._listener = listener  # keep alive: Box2D holds only a raw pointer

    def step(self, h: float) -> None:
        self.world.Step(h, self.vi, self.pi)

    def read(self) -> list[float]:
        out: list[float] = []
        for b in self.bodies:
            p, v = b.worldCenter, b.linearVelocity
            out += (p[0], p[1], b.angle, v[0], v[1], b.angularVelocity)
        return out

    def apply_force(self, i: int, fx: float, fy: float) -> None:
        self.bodies[i].ApplyForceToCenter((fx, fy), True)

    def apply_torque(self, i: int, tau: float) -> None:
        self.bodies[i].ApplyTorque(tau, True)

    def apply_impulse(self, i: int, jx: float, jy: float) -> None:
        b = self.bodies[i]
        b.ApplyLinearImpulse((jx, jy), b.worldCenter, True)


class Box2DSimulator(SteppingSimulator):
    """Box2D 2.3 through pybox2d; ``velocity_iterations``/``position_iterations`` per step."""

    name: ClassVar[str] = "box2d"

    def __init__(self, velocity_iterations: int = 10, position_iterations: int = 5) -> None:
        self.velocity_iterations = velocity_iterations
        self.position_iterations = position_iterations

    def build(self, scene: Scene) -> Box2DWorld:
        return Box2DWorld(scene, self.velocity_iterations, self.position_iterations)


@hookimpl
def register_simulators() -> list[type]:
    return [Box2DSimulator]
