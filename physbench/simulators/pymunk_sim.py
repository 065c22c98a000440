"""The pymunk (Chipmunk2D) simulator."""

from __future__ import annotations

from typing import Any, ClassVar

from physbench.hookspecs import hookimpl
from physbench.scene import Box, Circle, Scene, Segment
from physbench.simulators.stepping import SteppingSimulator, initial_com_state

#: Allowed overlap between shapes (m); Box2D's linear slop is the same 5 mm.
COLLISION_SLOP = 0.005


class PymunkWorld:
    def __init__(self, scene: Scene, iterations: int) -> None:
        import pymunk

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
        for b, (x, y, a, vx, vy, w) in zip(scene.bodies, initial_com_state(scene), strict=True):
            body = pymunk.Body(b.mass, b.inertia())
            body.position, body.angle, body.velocity, body.angular_velocity = (x, y), a, (vx, vy), w
            dx, dy = b.com_offset
            if isinstance(b.shape, Circle):
                sh = pymunk.Circle(body, b.shape.radius, (-dx, -dy))
            else:
                verts = b.shape.vertices() if isinstance(b.shape, Box) else b.shape.points
                sh = pymunk.Poly(body, [(px - dx, py - dy) for px, py in verts])
            sh.elasticity, sh.friction = b.elasticity, b.friction
            # pymunk would recompute mass from shapes only when density is set; we set it on the body.
            self.bodies.append(body)
            shapes.extend([body, sh])
        space.add(*shapes)
        index = {b.name: body for b, body in zip(scene.bodies, self.bodies, strict=True)}
        for j in scene.joints:
            joint = pymunk.PivotJoint(index[j.a], index[j.b] if j.b else static, j.anchor)
            joint.collide_bodies = False  # as Box2D's default for joined bodies
            space.add(joint)
        self.space = space

    def step(self, h: float) -> None:
        self.space.step(h)

    def read(self) -> list[float]:
        out: list[float] = []
        for b in self.bodies:
            p, v = b.position, b.velocity
            out += (p.x, p.y, b.angle, v.x, v.y, b.angular_velocity)
        return out

    def apply_force(self, i: int, fx: float, fy: float) -> None:
        b = self.bodies[i]
        b.apply_force_at_world_point((fx, fy), b.position)

    def apply_torque(self, i: int, tau: float) -> None:
        self.bodies[i].torque += tau

    def apply_impulse(self, i: int, jx: float, jy: float) -> None:
        b = self.bodies[i]
        b.apply_impulse_at_world_point((jx, jy), b.position)


class PymunkSimulator(SteppingSimulator):
    """Chipmunk2D through pymunk: iterative impulse solver, ``iterations`` per step."""

    name: ClassVar[str] = "pymunk"

    def __init__(self, iterations: int = 10) -> None:
        self.iterations = iterations

    def build(self, scene: Scene) -> PymunkWorld:
        return PymunkWorld(scene, self.iterations)


@hookimpl
def register_simulators() -> list[type]:
    return [PymunkSimulator]
