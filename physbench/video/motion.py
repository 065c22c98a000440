"""How the tracker expects a body to move between two frames, from what the scene says.

- A **free** body (no joint) moves under the scene's gravity and the forces and impulses the scene
  applies to it (:class:`~physbench.scene.Force`, divided by the body's mass).
- Where that path runs into **static geometry** (a floor, a rail, a ramp, a wall: the scene's
  segments and polygons), the body stops at the contact and slides along the surface: a ball
  resting on a rail stays on it and one rolling along it is predicted along it, not in free fall
  (at 3 frames/s free fall puts the prediction 0.55 m below a resting ball). The contact is found
  by moving the body's outline in small steps and pushing it out of each static it overlaps along
  the static's normal, with the support of its shape in that direction (its radius for a disc, the
  vertex furthest towards the static for a polygon at its angle).
- A **jointed** body keeps its velocity (its joint's constraint is not modelled).

Bounces are not predicted (the gate's share for a velocity change covers them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.scene import Circle, Segment

if TYPE_CHECKING:
    from physbench.scene import Body, Scene

#: Longest move of one contact step, as a share of the body's smallest half-size.
CONTACT_STEP = 0.4
#: Most contact steps per prediction.
MAX_STEPS = 64


@dataclass(frozen=True)
class Kick:
    """What known accelerations do over one interval, from rest: displacement ``dx`` (m) and
    velocity change ``dv`` (m/s)."""

    dx: np.ndarray
    dv: np.ndarray


class Motion:
    """The motion model of ``scene``'s bodies (see the module docstring)."""

    def __init__(self, scene: Scene) -> None:
        self.g = np.asarray(scene.gravity, dtype=float)
        jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b}
        self.free = {b.name: b.name not in jointed for b in scene.bodies}
        self.forces: dict[str, list[tuple[np.ndarray, float, float, str]]] = {}
        mass = {b.name: b.mass for b in scene.bodies}
        for f in scene.forces:
            if f.body in mass and mass[f.body] > 0:
                acc = np.asarray(f.vector, dtype=float) / mass[f.body]
                self.forces.setdefault(f.body, []).append((acc, f.start, f.end, f.kind))
        caps = []
        for st in scene.statics:
            if isinstance(st, Segment):
                caps.append((st.a, st.b, st.radius))
            else:
                pts = list(st.points)
                caps += [(pts[k], pts[(k + 1) % len(pts)], 0.0) for k in range(len(pts))]
        self.a = np.array([c[0] for c in caps], dtype=float).reshape(-1, 2)
        self.b = np.array([c[1] for c in caps], dtype=float).reshape(-1, 2)
        self.rho = np.array([c[2] for c in caps], dtype=float)
        self.lo = np.minimum(self.a, self.b) - self.rho[:, None]
        self.hi = np.maximum(self.a, self.b) + self.rho[:, None]
        # The statics' boxes and gravity as Python floats: the tracker asks of every body in
        # every frame, and NumPy's dispatch on arrays of two values costs more than the work.
        self._boxes = list(zip(*self.lo.T.tolist(), *self.hi.T.tolist(), strict=True))
        self._g = self.g.tolist()
        self._last: dict[str, tuple[float, float, Kick]] = {}

    # ----------------------------------------------------------------- known accelerations

    def kick(self, body: str, t0: float, dt: float) -> Kick:
        """The displacement and velocity change of ``body`` from rest over ``[t0, t0 + dt]``
        (s, scene time) from gravity and the scene's forces on it (none for a jointed body)."""
        if not self.free.get(body, False) or dt <= 0:
            return Kick(np.zeros(2), np.zeros(2))
        last = self._last.get(body)
        if last is not None and last[0] == t0 and last[1] == dt:
            return last[2]  # the tracker's prediction and its acceptance ask the same
        gx, gy = self._g
        dx = np.array([0.5 * gx * dt * dt, 0.5 * gy * dt * dt])
        dv = np.array([gx * dt, gy * dt])
        for acc, start, end, kind in self.forces.get(body, ()):
            if kind == "impulse":
                if t0 <= start < t0 + dt:  # an impulse (N s / kg = m/s) at `start`
                    dv = dv + acc
                    dx = dx + acc * (t0 + dt - start)
                continue
            a, b = max(start, t0), min(end, t0 + dt)
            if b <= a:
                continue
            on = b - a  # seconds the force acts, then coasts until t0 + dt
            dv = dv + acc * on
            dx = dx + acc * (0.5 * on * on + on * (t0 + dt - b))
        kick = Kick(dx, dv)
        self._last[body] = (t0, dt, kick)
        return kick

    # ----------------------------------------------------------------- static geometry

    def slide(
        self, body: Body, angle: float, start: np.ndarray, move: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Move ``body`` (at ``angle``) from ``start`` by ``move`` (m), stopping at static
        geometry and sliding along it: the end point and the normal (unit, away from the
        surface) of the last contact, or ``None`` without one."""
        if not self.free.get(body.name, False) or not len(self.rho):
            return start + move, None
        extent = body.shape.extent()
        end = start + move
        (x0, y0), (x1, y1) = start.tolist(), end.tolist()
        lx, ly = min(x0, x1) - extent, min(y0, y1) - extent
        hx, hy = max(x0, x1) + extent, max(y0, y1) + extent
        boxed = [ax <= hx and ay <= hy and bx >= lx and by >= ly for ax, ay, bx, by in self._boxes]
        if not any(boxed):
            return end, None
        near = np.array(boxed)
        a, b, rho = self.a[near], self.b[near], self.rho[near]
        verts = _vertices(body, angle)
        smallest = body.shape.radius if isinstance(body.shape, Circle) else _half_size(verts)
        n_steps = int(
            min(MAX_STEPS, max(1, math.ceil(np.hypot(*move) / (CONTACT_STEP * smallest))))
        )
        p, d = start.astype(float).copy(), move / n_steps
        normal = None
        for _ in range(n_steps):
            p = p + d
            for _ in range(2):  # a corner between two statics: push out of both
                q = _closest(p, a, b)
                off = p - q
                dist = np.hypot(off[:, 0], off[:, 1])
                n = off / np.maximum(dist, 1e-12)[:, None]
                support = extent if verts is None else np.max(-(verts @ n.T), axis=0)
                depth = rho + support - dist
                k = int(np.argmax(depth))
                if depth[k] <= 0:
                    break
                p = p + depth[k] * n[k]
                normal = n[k]
                into = float(d @ n[k])
                if into < 0:  # slide: drop the part of the motion into the surface
                    d = d - into * n[k]
        return p, normal


def _vertices(body: Body, angle: float) -> np.ndarray | None:
    """``body``'s polygon vertices about its centre at ``angle`` (m), or ``None`` for a disc."""
    if isinstance(body.shape, Circle):
        return None
    pts = np.asarray(body.shape.vertices(), dtype=float)
    c, s = math.cos(angle), math.sin(angle)
    return pts @ np.array([[c, s], [-s, c]])


def _half_size(verts: np.ndarray | None) -> float:
    """The smallest half-size of a polygon (its narrowest support), at least 1 mm."""
    if verts is None:
        return 1e-3
    spans = []
    for k in range(len(verts)):
        e = verts[(k + 1) % len(verts)] - verts[k]
        n = np.array([e[1], -e[0]]) / max(math.hypot(*e), 1e-12)
        proj = verts @ n
        spans.append(proj.max() - proj.min())
    return max(1e-3, 0.5 * min(spans))


def _closest(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The closest point to ``p`` on each segment ``a``-``b`` (``(S, 2)``)."""
    e = b - a
    ll = (e * e).sum(axis=1)
    t = np.clip(((p - a) * e).sum(axis=1) / np.maximum(ll, 1e-24), 0.0, 1.0)
    return a + t[:, None] * e
