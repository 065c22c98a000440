"""Measurement effects: they change what the sensor reports, not the motion.

They return zero forces. The framework must call :meth:`measure` on every simulated trajectory
(after simulating, before comparing with a recording or rendering the observation);
:func:`physbench.effects.apply_measurements` does it for a list of effects.

A sensor's bias (:class:`SensorOffset`) and its clock (:class:`ClockScale`), and the camera's view
of the plane of motion: its length calibration (:class:`CalibrationScale`), the turn of its axes
(:class:`AxisRotation`), radial lens distortion (:class:`LensDistortion`) and the tilt of the plane
(:class:`PlaneTilt`). Discovery offers them as causes beside the physical effects: a calibration
2 % off looks like a change of ``g`` in free flight, a turn of the axes like a horizontal force.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect, EffectError
from physbench.parameter import Parameter
from physbench.trajectory import Trajectory


class _Measurement(Effect):
    applies_forces: ClassVar[bool] = False
    measures: ClassVar[bool] = True

    def _body_mask(self, traj: Trajectory) -> np.ndarray:
        if self.bodies is None:
            return np.ones(len(traj.bodies), dtype=bool)
        missing = [b for b in self.bodies if b not in traj.bodies]
        if missing:
            raise EffectError(
                f"{self.name}: bodies {missing} are not in the trajectory (bodies: "
                f"{list(traj.bodies)})"
            )
        return np.array([b in self.bodies for b in traj.bodies], dtype=bool)


class SensorOffset(_Measurement):
    """A constant bias added to the tracked ``x``, ``y`` and ``angle`` of each selected body
    (default: all), e.g. an encoder zero that is not the rest angle.

    A position bias has no physical limit (a camera's origin can be anywhere), so ``dx`` and
    ``dy`` widen at either end; ``dangle`` does not, as widening ten-fold would pass ±π, where
    an angle bias repeats."""

    name: ClassVar[str] = "sensor_offset"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "dx", -0.5, 0.5, unit="m", default=0.0, doc="bias of the tracked x", extensible=True
        ),
        Parameter(
            "dy", -0.5, 0.5, unit="m", default=0.0, doc="bias of the tracked y", extensible=True
        ),
        Parameter("dangle", -0.5, 0.5, unit="rad", default=0.0, doc="bias of the tracked angle"),
    )

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation: the trajectory shifted by the biases."""
        states = traj.states.copy()
        sel = self._body_mask(traj)
        states[:, sel, 0] += self.values["dx"]
        states[:, sel, 1] += self.values["dy"]
        states[:, sel, 2] += self.values["dangle"]
        return Trajectory(traj.bodies, traj.times, states, engine=traj.engine)


class ClockScale(_Measurement):
    """A recorder clock that runs at the wrong rate: a sample stamped ``t`` was taken at true time
    ``scale·t`` (e.g. a logger whose nominal sample interval is shorter than the real one).

    The measured trajectory is stamped ``t/scale`` and its velocities are per recorder second.
    Simulate at least ``scale`` times the recording's duration.
    """

    name: ClassVar[str] = "clock_scale"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("scale", 0.8, 1.25, default=1.0, doc="true seconds per recorded second"),
    )

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation: the trajectory on the recorder's clock."""
        s = self.values["scale"]
        states = traj.states.copy()
        states[:, :, 3:6] *= s
        return Trajectory(traj.bodies, traj.times / s, states, engine=traj.engine)


# --------------------------------------------------------------------------- the camera's plane


def _point(value: object, what: str) -> tuple[float, float] | None:
    """``value`` as a finite point ``(x, y)``, or None."""
    if value is None:
        return None
    try:
        x, y = (float(v) for v in value)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise EffectError(f"{what} = {value!r}: expected a point (x, y) in metres") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise EffectError(f"{what} = {value!r}: expected finite coordinates")
    return (x, y)


def _length(value: object, what: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise EffectError(f"{what} = {value!r}: expected a length > 0 in metres")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise EffectError(f"{what} = {value!r}: expected a length > 0 in metres")
    return v


class _PlaneMap(_Measurement):
    """A measurement error of a camera's view of the plane of motion: every tracked point ``p`` is
    reported at ``centre + warp(p - centre)``, velocities and angles as that map carries them.

    ``centre`` (option, m) is the point the map is about; subclasses say what it defaults to.
    """

    #: Options besides ``bodies``, ``label`` and the parameters.
    extra_options: ClassVar[tuple[str, ...]] = ("centre",)

    def __init__(self, *, centre: object = None, **kw: object) -> None:
        super().__init__(**kw)  # type: ignore[arg-type]
        self.given_centre = _point(centre, f"{self.name}: centre")

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        return (*super().option_names(), *cls.extra_options)

    def centre(self) -> np.ndarray:
        """The point the map is about (default: the world's origin)."""
        return np.array(self.given_centre or (0.0, 0.0))

    def is_neutral(self) -> bool:
        neutral = self.neutral() or {}
        return all(self.values[k] == v for k, v in neutral.items())

    def warp(self, d: np.ndarray) -> np.ndarray:
        """Points ``d`` (``(..., 2)``, relative to the centre) as reported."""
        raise NotImplementedError

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation: positions through :meth:`warp`, velocities and angular
        rates as central differences along each body's own motion (exact for linear maps), and a
        body's angle as the map turns a short segment along it."""
        if self.is_neutral():
            return traj
        sel = self._body_mask(traj)
        states = traj.states.copy()
        s = states[:, sel]
        c = self.centre()

        def f(q: np.ndarray) -> np.ndarray:
            return c + self.warp(q - c)

        p, a, v, w = s[..., 0:2], s[..., 2], s[..., 3:5], s[..., 5]
        h = _DT
        out = s.copy()
        out[..., 0:2] = f(p)
        out[..., 3:5] = (f(p + h * v) - f(p - h * v)) / (2 * h)
        ahead = self._angle(f, p + h * v, a + h * w)
        behind = self._angle(f, p - h * v, a - h * w)
        out[..., 2] = self._angle(f, p, a)
        out[..., 5] = (ahead - behind) / (2 * h)
        states[:, sel] = out
        return Trajectory(traj.bodies, traj.times, states, engine=traj.engine)

    @staticmethod
    def _angle(f: Callable[[np.ndarray], np.ndarray], p: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The reported angle of a body at ``p`` turned by ``a``: the direction of a short
        segment along it through the map, kept within half a turn of ``a`` (no wrapping)."""
        u = _SEGMENT * np.stack([np.cos(a), np.sin(a)], axis=-1)
        e = f(p + u) - f(p - u)
        turn = np.arctan2(e[..., 1], e[..., 0]) - a
        return a + (turn + np.pi) % (2 * np.pi) - np.pi


#: How far from the middle of the view (in view radii) a view-centred map is exact.
REACH = 1.5
#: Time step (s) of the central differences that carry velocities through a map, and half length
#: (m) of the segment that carries an angle: small enough that a map's curvature does not show,
#: large enough that rounding does not.
_DT = 1e-4
_SEGMENT = 1e-4


class CalibrationScale(_PlaneMap):
    """A length calibration that is off: a reported length is ``scale`` times the true one (e.g. a
    reference tape or a pixel scale 2 % short), about ``centre`` (option; default the origin of
    the coordinates). In free flight it is a change of ``g`` (and of the initial speeds); a
    reference length in the plane fixes it."""

    name: ClassVar[str] = "calibration_scale"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("scale", 0.8, 1.25, default=1.0, doc="reported length per true length"),
    )

    def warp(self, d: np.ndarray) -> np.ndarray:
        """Called by :meth:`measure`: ``scale · d``."""
        return self.values["scale"] * d


class AxisRotation(_PlaneMap):
    """Coordinate axes turned by ``angle`` against the true ones (a camera or a level a fraction
    of a degree off), about ``centre`` (option; default the origin of the coordinates): reported
    positions and velocities are turned by ``angle`` and body angles shifted by it. In a side
    view it tilts ``g``, the same as a horizontal uniform force; a plumb line or a level in view
    fixes it."""

    name: ClassVar[str] = "axis_rotation"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "angle", -0.2, 0.2, unit="rad", default=0.0, doc="turn of the reported axes (CCW)"
        ),
    )

    def warp(self, d: np.ndarray) -> np.ndarray:
        """Called by :meth:`measure`: ``d`` turned by ``angle``."""
        a = self.values["angle"]
        c, s = math.cos(a), math.sin(a)
        return np.stack([c * d[..., 0] - s * d[..., 1], s * d[..., 0] + c * d[..., 1]], axis=-1)


class _ViewMap(_PlaneMap):
    """A map about the middle of the camera's view: ``centre`` and ``radius`` (options, m) default
    to the middle and half the diagonal of the scene's bounds; discovery sets them to the extent
    of the tracked positions (what the camera framed).

    The map is exact within :data:`REACH` radii of the centre; a point further out moves as the
    point at that distance in its direction does. Such points are outside any view: only a
    simulation far from the data puts them there, and there the lens's and the perspective's fast
    growth would otherwise let a fit pull the whole trajectory towards the data."""

    extra_options: ClassVar[tuple[str, ...]] = ("centre", "radius")

    def bend(self, d: np.ndarray) -> np.ndarray:
        """The exact map of points ``d`` (``(..., 2)``, relative to the centre)."""
        raise NotImplementedError

    def warp(self, d: np.ndarray) -> np.ndarray:
        """Called by :meth:`measure`: :meth:`bend`, its shift held beyond :data:`REACH` radii."""
        r = np.sqrt((d * d).sum(axis=-1, keepdims=True))
        reach = REACH * self.radius()
        inside = d * np.minimum(1.0, reach / np.maximum(r, 1e-300))
        return d + self.bend(inside) - inside

    def __init__(self, *, radius: object = None, **kw: object) -> None:
        super().__init__(**kw)
        self.given_radius = _length(radius, f"{self.name}: radius")

    def _bounds(self) -> tuple[float, float, float, float]:
        if self.scene is None:
            raise EffectError(
                f"{self.name}: give centre and radius, or call setup(scene, values) first "
                "(they default to the scene's bounds)"
            )
        return tuple(float(b) for b in self.scene.bounds)  # type: ignore[return-value]

    def centre(self) -> np.ndarray:
        """The middle of the view (default: of the scene's bounds)."""
        if self.given_centre is not None:
            return np.array(self.given_centre)
        x0, y0, x1, y1 = self._bounds()
        return np.array([(x0 + x1) / 2, (y0 + y1) / 2])

    def radius(self) -> float:
        """Half the diagonal of the view (default: of the scene's bounds)."""
        if self.given_radius is not None:
            return self.given_radius
        x0, y0, x1, y1 = self._bounds()
        return math.hypot(x1 - x0, y1 - y0) / 2


class LensDistortion(_ViewMap):
    """Radial lens distortion left in the calibration: a point at distance ``r`` from the middle
    of the view is reported at ``r (1 + k1 (r / radius)²)`` (barrel for ``k1 < 0``, pincushion
    for ``k1 > 0``; ``k1`` is the shift at the edge of the view, ``radius``, per ``radius``). It
    bends straight paths near the edges; a straight reference line across the view or a lens
    calibration fixes it."""

    name: ClassVar[str] = "lens_distortion"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("k1", -0.2, 0.2, default=0.0, doc="radial shift at the view's edge per radius"),
    )

    def bend(self, d: np.ndarray) -> np.ndarray:
        """``d (1 + k1 |d|² / radius²)``."""
        r2 = (d * d).sum(axis=-1, keepdims=True) / self.radius() ** 2
        return d * (1.0 + self.values["k1"] * r2)


class PlaneTilt(_ViewMap):
    """The plane of motion not square to the camera: turned by ``tx`` about the view's x axis and
    ``ty`` about its y axis through the middle of the view, seen by a pinhole at ``distance``
    (option, m; default four times ``radius``: the motion spans about 28° of the view), scaled so
    that the middle keeps its size. Points on the near side are reported further apart than on the
    far side (perspective), so a steady motion seems to speed up or slow down; a second view, or a
    reference of known shape in the plane, fixes it."""

    name: ClassVar[str] = "plane_tilt"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("tx", -0.3, 0.3, unit="rad", default=0.0, doc="turn about the view's x axis"),
        Parameter("ty", -0.3, 0.3, unit="rad", default=0.0, doc="turn about the view's y axis"),
    )
    extra_options: ClassVar[tuple[str, ...]] = ("centre", "radius", "distance")

    def __init__(self, *, distance: object = None, **kw: object) -> None:
        super().__init__(**kw)
        self.given_distance = _length(distance, f"{self.name}: distance")

    def distance(self) -> float:
        """How far the pinhole is from the middle of the view (default: four times the radius)."""
        return self.given_distance if self.given_distance is not None else 4 * self.radius()

    def bend(self, d: np.ndarray) -> np.ndarray:
        """``d`` turned out of the plane, then projected."""
        tx, ty = self.values["tx"], self.values["ty"]
        dx, dy = d[..., 0], d[..., 1]
        z1 = dy * math.sin(tx)
        x = dx * math.cos(ty) + z1 * math.sin(ty)
        y = dy * math.cos(tx)
        z = -dx * math.sin(ty) + z1 * math.cos(ty)
        k = self.distance() / (self.distance() - z)
        return np.stack([x * k, y * k], axis=-1)
