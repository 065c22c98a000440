"""The Box2D simulator (pybox2d, module ``Box2D``).

Box2D mixes contact materials as max(restitution) and sqrt(friction product); a contact listener
resets both to the product, physbench's convention, when a contact begins.
Known divergence kept (documented in README): Box2D treats impacts slower than 1 m/s as
inelastic (``b2_velocityThreshold``, compiled in).
"""

from __future__ import annotations

from typing import Any, ClassVar

from physbench.hookspecs import hookimpl
from physbench.scene import Box, Circle, Scene, Segment
from physbench.simulators.stepping import SteppingSimulator, initial_com_state


def _listener_class() -> Any:
    import Box2D

    class ProductMixing(Box2D.b2ContactListener):
        def BeginContact(self, contact: Any) -> None:
            fa, fb = contact.fixtureA, contact.fixtureB
            contact.restitution = fa.restitution * fb.restitution
            contact.friction = fa.friction * fb.friction

    return ProductMixing


class Box2DWorld:
    def __init__(self, scene: Scene, velocity_iterations: int, position_iterations: int) -> None:
        import Box2D

        listener = _listener_class()()
        world = Box2D.b2World(gravity=scene.gravity, doSleep=False, contactListener=listener)
        self._listener = listener  # keep alive: Box2D holds only a raw pointer
        ground = world.CreateStaticBody()
        for s in scene.statics:
            if isinstance(s, Segment):
                shape = Box2D.b2EdgeShape(vertices=[s.a, s.b])
                if s.radius > 0:
                    shape.radius = s.radius
            else:
                shape = Box2D.b2PolygonShape(vertices=list(s.points))
            ground.CreateFixture(shape=shape, restitution=s.elasticity, friction=s.friction)
        self.bodies: list[Any] = []
        for b, (x, y, a, vx, vy, w) in zip(scene.bodies, initial_com_state(scene), strict=True):
            dx, dy = b.com_offset
            # Box2D bodies have their origin at the shape centre; the CoM is set through mass data.
            ox, oy = b.position
            body = world.CreateDynamicBody(position=(ox, oy), angle=a, bullet=True)
            if isinstance(b.shape, Circle):
                shape = Box2D.b2CircleShape(radius=b.shape.radius)
            else:
                verts = b.shape.vertices() if isinstance(b.shape, Box) else b.shape.points
                shape = Box2D.b2PolygonShape(vertices=list(verts))
            body.CreateFixture(shape=shape, density=1.0, restitution=b.elasticity, friction=b.friction)
            md = Box2D.b2MassData()
            md.mass, md.center = b.mass, (dx, dy)
            md.I = b.inertia() + b.mass * (dx * dx + dy * dy)  # Box2D wants I about the body origin
            body.massData = md
            body.linearVelocity, body.angularVelocity = (vx, vy), w
            self.bodies.append(body)
        index = {b.name: body for b, body in zip(scene.bodies, self.bodies, strict=True)}
        for j in scene.joints:
            world.CreateRevoluteJoint(bodyA=index[j.a], bodyB=index[j.b] if j.b else ground, anchor=j.anchor)
        self.world = world
        self.vi, self.pi = velocity_iterations, position_iterations

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
