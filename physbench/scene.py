"""The engine-neutral scene model: a scene is data that every simulator builds the same way.

Units are SI (m, kg, s, rad); y points up, gravity is usually ``(0, -9.81)``; angles are
counter-clockwise. A body's ``position`` is the centre of its shape; ``com_offset`` moves the centre
of mass away from it (in the body frame). Contacts combine the two surfaces' elasticity and friction
by multiplying them, in every engine.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

from physbench.errors import SceneError
from physbench.limits import FPS, MAX_COORDINATE, MAX_FRAMES, MAX_SPIN
from physbench.parameter import Parameter

Vec = tuple[float, float]

#: Physical parameters a body has, with the closed range each must lie in.
BODY_PARAMS: dict[str, tuple[float, float]] = {
    "mass": (0.0, math.inf),  # exclusive lower bound; a scene's masses lie in MASS
    "elasticity": (0.0, 1.0),
    "friction": (0.0, math.inf),
    "moment": (0.0, math.inf),  # exclusive lower bound; None means "from shape and mass"
}

# Limits a scene must keep, so that a typo fails when the scene is loaded rather than deep inside
# an engine or the rasteriser (pixel coordinates that overflow, areas that underflow to 0, an
# allocation per substep). Those that recordings share live in physbench.limits: MAX_COORDINATE,
# FPS, MAX_SPIN, MAX_FRAMES.
#: m: the smallest radius, width and height (and square root of a polygon's area); a smaller shape
#: has an area and a moment that underflow.
MIN_SIZE = 1e-6
#: m/s: the largest initial speed along an axis (ten times a rifle bullet's).
MAX_SPEED = 1e4
#: m/s²: the largest gravity along an axis (a thousand g).
MAX_GRAVITY = 1e4
#: kg: the masses accepted, a milligram to a thousand tonnes: outside them the engines' contact
#: solvers lose precision (pymunk turns a subnormal mass into NaN).
MASS = (1e-6, 1e6)
#: Physics steps per recorded frame; more only costs time (1e4 steps per frame at 30 fps is a
#: 3 microsecond step).
MAX_SUBSTEPS = 10_000


@dataclass(frozen=True)
class Circle:
    radius: float
    kind: Literal["circle"] = "circle"

    def area(self) -> float:
        return math.pi * self.radius**2

    def moment(self, mass: float) -> float:
        return 0.5 * mass * self.radius**2

    def extent(self) -> float:
        """Radius of the smallest circle around the shape centre that holds the shape."""
        return self.radius

    def half_extents(self, angle: float) -> Vec:
        """Half width and half height of the axis-aligned box around the shape at ``angle``."""
        return (self.radius, self.radius)


@dataclass(frozen=True)
class Box:
    width: float
    height: float
    kind: Literal["box"] = "box"

    def vertices(self) -> tuple[Vec, ...]:
        w, h = self.width / 2, self.height / 2
        return ((-w, -h), (w, -h), (w, h), (-w, h))

    def area(self) -> float:
        return self.width * self.height

    def moment(self, mass: float) -> float:
        return mass * (self.width**2 + self.height**2) / 12.0

    def extent(self) -> float:
        return math.hypot(self.width, self.height) / 2

    def half_extents(self, angle: float) -> Vec:
        c, s = math.cos(angle), math.sin(angle)
        pts = self.vertices()
        return (max(abs(c * x - s * y) for x, y in pts), max(abs(s * x + c * y) for x, y in pts))


@dataclass(frozen=True)
class Polygon:
    """A convex polygon, vertices counter-clockwise around the shape centre (body frame)."""

    points: tuple[Vec, ...]
    kind: Literal["polygon"] = "polygon"

    def vertices(self) -> tuple[Vec, ...]:
        return self.points

    def area(self) -> float:
        return abs(_signed_area(self.points))

    def moment(self, mass: float) -> float:
        # Polygon moment about the origin of its vertex frame (uniform density).
        num = den = 0.0
        pts = self.points
        for i in range(len(pts)):
            (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % len(pts)]
            cross = abs(x0 * y1 - x1 * y0)
            num += cross * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1)
            den += cross
        return mass * num / (6.0 * den)

    def extent(self) -> float:
        return max(math.hypot(x, y) for x, y in self.points)

    def half_extents(self, angle: float) -> Vec:
        c, s = math.cos(angle), math.sin(angle)
        pts = self.vertices()
        return (max(abs(c * x - s * y) for x, y in pts), max(abs(s * x + c * y) for x, y in pts))


Shape = Circle | Box | Polygon
SHAPE_KINDS = ("circle", "box", "polygon")


@dataclass(frozen=True)
class Body:
    """A dynamic body. Its parameters are the ones an estimator may be asked to identify."""

    name: str
    shape: Shape
    position: Vec
    angle: float = 0.0
    velocity: Vec = (0.0, 0.0)
    angular_velocity: float = 0.0
    mass: float = 1.0
    elasticity: float = 0.5
    friction: float = 0.5
    moment: float | None = None
    com_offset: Vec = (0.0, 0.0)

    def inertia(self) -> float:
        """Moment of inertia about the centre of mass (uniform density unless ``moment`` is set)."""
        return self.moment if self.moment is not None else self.shape.moment(self.mass)


@dataclass(frozen=True)
class Segment:
    """Static line segment (a wall, a floor), optionally thickened by ``radius``."""

    a: Vec
    b: Vec
    radius: float = 0.0
    elasticity: float = 1.0
    friction: float = 1.0
    kind: Literal["segment"] = "segment"


@dataclass(frozen=True)
class StaticPolygon:
    """Static convex polygon in world coordinates, counter-clockwise."""

    points: tuple[Vec, ...]
    elasticity: float = 1.0
    friction: float = 1.0
    kind: Literal["polygon"] = "polygon"


Static = Segment | StaticPolygon


@dataclass(frozen=True)
class Force:
    """A force (N) applied at a body's centre of mass from ``start`` to ``end`` (s), or an
    impulse (N·s) applied once at ``start``."""

    body: str
    vector: Vec
    start: float = 0.0
    end: float = 0.0
    kind: Literal["force", "impulse"] = "force"


@dataclass(frozen=True)
class Joint:
    """A pivot: ``a`` and ``b`` (``None`` = the world) share the point ``anchor`` (world
    coordinates at t=0) and may rotate about it."""

    a: str
    anchor: Vec
    b: str | None = None
    kind: Literal["pivot"] = "pivot"


#: Unit of each body parameter, for the :class:`~physbench.unknowns.Parameter` of an unknown.
BODY_UNITS: dict[str, str] = {"mass": "kg", "elasticity": "", "friction": "", "moment": "kg·m²"}


#: The scene's gravity along y as an unknown (``--params gravity``): scenes are y-up, so this is
#: minus g. The default range spans Earth's g with room for a wrong scale or clock (a ball toss
#: filmed with a tape off by a few per cent); it is a typical span, not a limit, so a run may set
#: another (``gravity=-2:2`` for a tilted table seen from above). The x component stays as the
#: scene says: a horizontal pull is the same as a rotated camera, which is discovery's question.
GRAVITY = Parameter(
    "gravity",
    -12.0,
    -8.0,
    unit="m/s²",
    doc="gravity along y (minus g in a y-up scene)",
    extensible=True,
)


def body_unknown(body: str, param: str, low: float, high: float) -> Parameter:
    """The declaration that ``body.param`` is unknown and lies somewhere in ``[low, high]``."""
    unit = BODY_UNITS.get(param, "") if isinstance(param, str) else ""  # validated later
    return Parameter(param, low, high, owner=body, unit=unit)


@dataclass(frozen=True)
class Scene:
    """A complete, engine-neutral description of one experiment."""

    name: str
    bodies: tuple[Body, ...]
    bounds: tuple[float, float, float, float] = (0.0, 0.0, 4.0, 4.0)  # xmin, ymin, xmax, ymax
    gravity: Vec = (0.0, -9.81)
    fps: float = 30.0
    frames: int = 30
    substeps: int = 10
    statics: tuple[Static, ...] = ()
    forces: tuple[Force, ...] = ()
    joints: tuple[Joint, ...] = ()
    unknowns: tuple[Parameter, ...] = ()
    test_body: str | None = None
    description: str = ""
    meta: Mapping[str, object] = field(default_factory=dict, compare=True)

    @property
    def dt(self) -> float:
        """Seconds between two recorded frames."""
        return 1.0 / self.fps

    @property
    def body_names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bodies)

    def body_index(self, name: str) -> int:
        for i, b in enumerate(self.bodies):
            if b.name == name:
                return i
        from physbench.errors import UnknownNameError

        raise UnknownNameError("body", name, self.body_names)

    def unknown(self, key: str) -> Parameter:
        for u in self.unknowns:
            if u.key == key:
                return u
        from physbench.errors import UnknownNameError

        raise UnknownNameError(
            "parameter",
            key,
            [u.key for u in self.unknowns],
            where=f"among the unknowns of scene {self.name!r}",
        )

    def with_params(self, params: Mapping[str, float]) -> Scene:
        """A copy with ``{"body.param": value}`` (and ``{"gravity": gy}``, :data:`GRAVITY`)
        applied. Called once per simulation."""
        if not params:
            return self
        changes: dict[str, dict[str, float]] = {}
        world: dict[str, object] = {}
        for key, value in params.items():
            if key == GRAVITY.key:
                world["gravity"] = (self.gravity[0], float(value))
                continue
            body, _, param = key.rpartition(".")
            if param not in BODY_PARAMS:
                raise SceneError(
                    f"unknown body parameter; known: {', '.join(BODY_PARAMS)}", key=key, value=value
                )
            changes.setdefault(body, {})[param] = float(value)
        names = set(self.body_names)
        for body in changes:
            if body not in names:
                from physbench.errors import UnknownNameError

                raise UnknownNameError("body", body, names)
        bodies = tuple(
            replace(b, **changes[b.name]) if b.name in changes else b for b in self.bodies
        )
        return replace(self, bodies=bodies, **world)  # type: ignore[arg-type]

    def scaled(self, factor: float) -> Scene:
        """A copy with every length multiplied by ``factor`` about the origin (positions,
        velocities, gravity, shapes, statics, anchors) and the bounds kept: the scene as a
        calibration off by ``1 / factor`` shows it in the same frame. Called for every point a run
        simulates with a ``camera.scale`` (:func:`physbench.unknowns.simulate_seen`)."""
        f = float(factor)

        def v(p: Vec) -> Vec:
            return (f * p[0], f * p[1])

        def shape(sh: Shape) -> Shape:
            if isinstance(sh, Circle):
                return Circle(f * sh.radius)
            if isinstance(sh, Box):
                return Box(f * sh.width, f * sh.height)
            return Polygon(tuple(v(p) for p in sh.points))

        def static(st: Static) -> Static:
            if isinstance(st, Segment):
                return replace(st, a=v(st.a), b=v(st.b), radius=f * st.radius)
            return replace(st, points=tuple(v(p) for p in st.points))

        bodies = tuple(
            replace(
                b,
                shape=shape(b.shape),
                position=v(b.position),
                velocity=v(b.velocity),
                com_offset=v(b.com_offset),
            )
            for b in self.bodies
        )
        return replace(
            self,
            bodies=bodies,
            statics=tuple(static(st) for st in self.statics),
            joints=tuple(replace(j, anchor=v(j.anchor)) for j in self.joints),
            gravity=v(self.gravity),
        )

    def validate(self) -> Scene:
        """Check every value; raise :class:`SceneError` naming the first bad key. Returns self."""
        validate_scene(self)
        return self


# --------------------------------------------------------------------------- validation


def _signed_area(points: tuple[Vec, ...]) -> float:
    s = 0.0
    for i in range(len(points)):
        (x0, y0), (x1, y1) = points[i], points[(i + 1) % len(points)]
        s += x0 * y1 - x1 * y0
    return s / 2


def _is_convex_ccw(points: tuple[Vec, ...]) -> bool:
    n = len(points)
    if n < 3 or _signed_area(points) <= 0:
        return False
    for i in range(n):
        (x0, y0), (x1, y1), (x2, y2) = points[i], points[(i + 1) % n], points[(i + 2) % n]
        if (x1 - x0) * (y2 - y1) - (y1 - y0) * (x2 - x1) < -1e-12:
            return False
    return True


def _finite(key: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise SceneError("must be a finite number", key=key, value=value)
    return float(value)


def _vec(key: str, value: object) -> Vec:
    if not isinstance(value, tuple | list) or len(value) != 2:
        raise SceneError("must be a pair of numbers [x, y]", key=key, value=value)
    return (_finite(f"{key}[0]", value[0]), _finite(f"{key}[1]", value[1]))


def _coordinate(key: str, value: object) -> float:
    v = _finite(key, value)
    if abs(v) > MAX_COORDINATE:
        raise SceneError(
            f"must lie in [-{MAX_COORDINATE:g}, {MAX_COORDINATE:g}] m", key=key, value=value
        )
    return v


def _within(key: str, value: object, low: float, high: float, unit: str) -> float:
    v = _finite(key, value)
    if not low <= v <= high:
        raise SceneError(f"must lie in [{low:g}, {high:g}] {unit}", key=key, value=value)
    return v


def _bounded_vec(key: str, value: object, most: float, unit: str) -> Vec:
    x, y = _vec(key, value)
    return (
        _within(f"{key}[0]", x, -most, most, unit),
        _within(f"{key}[1]", y, -most, most, unit),
    )


def _point(key: str, value: object) -> Vec:
    x, y = _vec(key, value)
    return (_coordinate(f"{key}[0]", x), _coordinate(f"{key}[1]", y))


def _size(key: str, value: object) -> float:
    v = _finite(key, value)
    if not MIN_SIZE <= v <= MAX_COORDINATE:
        raise SceneError(f"must lie in [{MIN_SIZE:g}, {MAX_COORDINATE:g}] m", key=key, value=value)
    return v


def _name(key: str, value: object, seen: set[str], *, world: bool = False) -> str:
    """``value`` when it names one of the bodies ``seen`` (or, with ``world``, is ``None``)."""
    if (world and value is None) or (isinstance(value, str) and value in seen):
        return value  # type: ignore[return-value]
    extra = " (or 'world' for b)" if world else ""
    raise SceneError(
        f"no such body; bodies: {', '.join(sorted(seen))}{extra}", key=key, value=value
    )


def _check_param(key: str, param: str, value: float) -> None:
    lo, hi = BODY_PARAMS[param]
    value = _finite(key, value)
    if param == "mass":
        if not MASS[0] <= value <= MASS[1]:
            raise SceneError(
                f"mass must lie in [{MASS[0]:g}, {MASS[1]:g}] kg", key=key, value=value
            )
    elif param == "moment":
        if value <= 0:
            raise SceneError(f"{param} must be > 0", key=key, value=value)
    elif not lo <= value <= hi:
        raise SceneError(f"{param} must lie in [{lo}, {hi}]", key=key, value=value)


def check_body_param(key: str, param: str, value: float) -> None:
    """Raise :class:`SceneError` naming ``key`` when ``value`` is not a value body parameter
    ``param`` can take (a mass in :data:`MASS`, an elasticity in [0, 1], ...)."""
    _check_param(key, param, value)


def validate_scene(scene: Scene) -> None:
    """Check every value of ``scene``; raise :class:`SceneError` naming the first bad key."""
    bounds = _check_world(scene)
    names = _check_bodies(scene, bounds)
    _check_statics(scene.statics)
    _check_forces(scene.forces, names)
    _check_joints(scene.joints, names)
    _check_unknowns(scene, names)
    if scene.test_body is not None:
        _name("test_body", scene.test_body, names)


def _check_world(scene: Scene) -> tuple[float, float, float, float]:
    """Check the scene's name, bounds, gravity, clock and that it has a body; returns the
    bounds."""
    if not scene.name or not isinstance(scene.name, str):
        raise SceneError("must be a non-empty string", key="name", value=scene.name)
    if not isinstance(scene.bounds, tuple | list) or len(scene.bounds) != 4:
        raise SceneError("must be [xmin, ymin, xmax, ymax]", key="bounds", value=scene.bounds)
    xmin, ymin, xmax, ymax = (_coordinate(f"bounds[{i}]", v) for i, v in enumerate(scene.bounds))
    if not (xmin < xmax and ymin < ymax):
        raise SceneError(
            "bounds must be [xmin, ymin, xmax, ymax] with min < max",
            key="bounds",
            value=scene.bounds,
        )
    _bounded_vec("gravity", scene.gravity, MAX_GRAVITY, "m/s²")
    _within("fps", scene.fps, *FPS, "Hz")
    for key, most in (("frames", MAX_FRAMES), ("substeps", MAX_SUBSTEPS)):
        v = getattr(scene, key)
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= most:
            raise SceneError(f"must be a whole number in [1, {most}]", key=key, value=v)
    if not scene.bodies:
        raise SceneError("a scene needs at least one dynamic body", key="bodies", value=[])
    return xmin, ymin, xmax, ymax


def _check_bodies(scene: Scene, bounds: tuple[float, float, float, float]) -> set[str]:
    """Check each body (names unique); returns their names."""
    seen: set[str] = set()
    for i, b in enumerate(scene.bodies):
        k = f"bodies[{i}]"
        if not isinstance(b.name, str) or not b.name or "." in b.name or b.name == "world":
            raise SceneError(
                "must be a non-empty name without '.', not 'world'", key=f"{k}.name", value=b.name
            )
        if b.name in seen:
            raise SceneError("duplicate body name", key=f"{k}.name", value=b.name)
        seen.add(b.name)
        _check_body(k, b, scene, bounds)
    return seen


def _check_body(k: str, b: Body, scene: Scene, bounds: tuple[float, float, float, float]) -> None:
    """Check body ``b`` (at key ``k``): its shape, that it lies inside the world (``bounds``: the
    scene's, as numbers), its motion and its parameters."""
    xmin, ymin, xmax, ymax = bounds
    _check_shape(f"{k}.shape", b.shape)
    x, y = _point(f"{k}.position", b.position)
    hx, hy = b.shape.half_extents(_finite(f"{k}.angle", b.angle))
    eps = 1e-9
    if not (xmin + hx - eps <= x <= xmax - hx + eps and ymin + hy - eps <= y <= ymax - hy + eps):
        raise SceneError(
            f"body (half size {hx:g} x {hy:g} m) must lie inside the world bounds "
            f"{tuple(scene.bounds)}",
            key=f"{k}.position",
            value=b.position,
        )
    _finite(f"{k}.angle", b.angle)
    _bounded_vec(f"{k}.velocity", b.velocity, MAX_SPEED, "m/s")
    _within(f"{k}.angular_velocity", b.angular_velocity, -MAX_SPIN, MAX_SPIN, "rad/s")
    _point(f"{k}.com_offset", b.com_offset)
    for p in ("mass", "elasticity", "friction"):
        _check_param(f"{k}.{p}", p, getattr(b, p))
    if b.moment is not None:
        _check_param(f"{k}.moment", "moment", b.moment)


def _check_statics(statics: Sequence[Static]) -> None:
    """Check each static segment or polygon and its contact parameters."""
    for i, s in enumerate(statics):
        k = f"statics[{i}]"
        if isinstance(s, Segment):
            a, bb = _point(f"{k}.a", s.a), _point(f"{k}.b", s.b)
            if a == bb:
                raise SceneError("segment end points must differ", key=f"{k}.b", value=s.b)
            if not 0 <= _finite(f"{k}.radius", s.radius) <= MAX_COORDINATE:
                raise SceneError(
                    f"must lie in [0, {MAX_COORDINATE:g}] m", key=f"{k}.radius", value=s.radius
                )
        elif isinstance(s, StaticPolygon):
            _check_points(f"{k}.points", s.points)
        else:
            raise SceneError("unknown static kind; known: segment, polygon", key=k, value=s)
        _check_param(f"{k}.elasticity", "elasticity", s.elasticity)
        _check_param(f"{k}.friction", "friction", s.friction)


def _check_forces(forces: Sequence[Force], names: set[str]) -> None:
    """Check each applied force or impulse: its body, kind, vector and time window."""
    for i, f in enumerate(forces):
        k = f"forces[{i}]"
        _name(f"{k}.body", f.body, names)
        if f.kind not in ("force", "impulse"):
            raise SceneError(
                "unknown force kind; known: force, impulse", key=f"{k}.kind", value=f.kind
            )
        _vec(f"{k}.vector", f.vector)
        start, end = _finite(f"{k}.start", f.start), _finite(f"{k}.end", f.end)
        if start < 0:
            raise SceneError("must be >= 0", key=f"{k}.start", value=f.start)
        if f.kind == "force" and end <= start:
            raise SceneError("a force window needs end > start", key=f"{k}.end", value=f.end)


def _check_joints(joints: Sequence[Joint], names: set[str]) -> None:
    """Check each pivot: its kind, two different bodies (or a body and the world), its anchor."""
    for i, j in enumerate(joints):
        k = f"joints[{i}]"
        if j.kind != "pivot":
            raise SceneError("unknown joint kind; known: pivot", key=f"{k}.kind", value=j.kind)
        _name(f"{k}.a", j.a, names)
        _name(f"{k}.b", j.b, names, world=True)
        if j.a == j.b:
            raise SceneError("a joint needs two different bodies", key=f"{k}.b", value=j.b)
        _point(f"{k}.anchor", j.anchor)


def _check_unknowns(scene: Scene, names: set[str]) -> None:
    """Check each unknown body parameter: its body (not the test body), name and range, each
    declared once."""
    keys: set[str] = set()
    for i, u in enumerate(scene.unknowns):
        k = f"unknowns[{i}]"
        _name(f"{k}.body", u.owner, names)
        if not isinstance(u.name, str) or u.name not in BODY_PARAMS:
            raise SceneError(
                f"unknown parameter; known: {', '.join(BODY_PARAMS)}",
                key=f"{k}.param",
                value=u.name,
            )
        lo, hi = _finite(f"{k}.range[0]", u.low), _finite(f"{k}.range[1]", u.high)
        if not lo < hi:
            raise SceneError(
                "range must be [low, high] with low < high", key=f"{k}.range", value=[u.low, u.high]
            )
        _check_param(f"{k}.range[0]", u.name, lo)
        _check_param(f"{k}.range[1]", u.name, hi)
        if u.key in keys:
            raise SceneError("parameter declared unknown twice", key=f"{k}.param", value=u.name)
        keys.add(u.key)
        if u.owner == scene.test_body:
            raise SceneError(
                "the test body's parameters are fixed by definition", key=f"{k}.body", value=u.owner
            )


def _check_shape(key: str, shape: object) -> None:
    if isinstance(shape, Circle):
        _size(f"{key}.radius", shape.radius)
    elif isinstance(shape, Box):
        for d in ("width", "height"):
            _size(f"{key}.{d}", getattr(shape, d))
    elif isinstance(shape, Polygon):
        _check_points(f"{key}.points", shape.points)
    else:
        raise SceneError(f"unknown shape; known: {', '.join(SHAPE_KINDS)}", key=key, value=shape)


def _check_points(key: str, points: object) -> None:
    if not isinstance(points, tuple | list) or len(points) < 3:
        raise SceneError("a polygon needs at least 3 points", key=key, value=points)
    pts = tuple(_point(f"{key}[{i}]", p) for i, p in enumerate(points))
    if not _is_convex_ccw(pts):
        raise SceneError(
            "polygon must be convex with counter-clockwise points", key=key, value=points
        )
    if _signed_area(pts) < MIN_SIZE**2:
        raise SceneError(f"polygon area must be >= {MIN_SIZE**2:g} m^2", key=key, value=points)
