"""The engine-neutral stepping loop both built-in simulators share.

An engine adapter (:class:`EngineWorld`) only builds the world, steps it and reads and pushes body
state; the schedule of forces and impulses, effects, recording at the frame rate, the conversion
from centre of mass to shape centre and the explosion check live here once, so both engines
behave the same by construction.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import ClassVar, Protocol

import numpy as np

from physbench.errors import SimulationError
from physbench.protocols import Effect
from physbench.scene import Scene
from physbench.trajectory import Trajectory

#: A body that leaves the world bounds by more than this many world sizes has exploded.
ESCAPE_MARGIN = 1.0


class EngineWorld(Protocol):
    """One built scene inside a concrete engine. Body order is ``scene.bodies`` order."""

    def step(self, h: float) -> None: ...

    def read(self) -> list[float]:
        """Flat CoM states ``[x, y, angle, vx, vy, omega] * N`` (velocity of the CoM)."""
        ...

    def apply_force(self, i: int, fx: float, fy: float) -> None: ...

    def apply_torque(self, i: int, tau: float) -> None: ...

    def apply_impulse(self, i: int, jx: float, jy: float) -> None: ...


def com_offsets_world(scene: Scene, angles: np.ndarray) -> np.ndarray:
    """``(..., N, 2)`` vectors from shape centre to centre of mass, rotated by ``angles (..., N)``."""
    off = np.array([b.com_offset for b in scene.bodies], dtype=float)
    c, s = np.cos(angles), np.sin(angles)
    return np.stack([c * off[:, 0] - s * off[:, 1], s * off[:, 0] + c * off[:, 1]], axis=-1)


def initial_com_state(scene: Scene) -> list[tuple[float, float, float, float, float, float]]:
    """Per body: the CoM pose and velocity implied by the scene's shape-centre state."""
    out = []
    for b in scene.bodies:
        dx, dy = b.com_offset
        c, s = math.cos(b.angle), math.sin(b.angle)
        rx, ry = c * dx - s * dy, s * dx + c * dy
        w = b.angular_velocity
        out.append((b.position[0] + rx, b.position[1] + ry, b.angle, b.velocity[0] - w * ry, b.velocity[1] + w * rx, w))
    return out


def _schedule(scene: Scene, h: float, n_sub: int) -> dict[int, list[tuple[str, int, float, float]]]:
    """Substep index -> [(kind, body index, x, y)] for every force or impulse acting then."""
    sched: dict[int, list[tuple[str, int, float, float]]] = {}
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    for f in scene.forces:
        i = index[f.body]
        if f.kind == "impulse":
            k = max(0, math.ceil(f.start / h - 1e-9))
            if k < n_sub:
                sched.setdefault(k, []).append(("impulse", i, *f.vector))
        else:
            # A substep [k h, (k+1) h) feels the force by the fraction of it inside the window,
            # so short windows act the same whatever the substep count.
            k0, k1 = int(math.floor(f.start / h)), min(n_sub, math.ceil(f.end / h))
            for k in range(max(0, k0), k1):
                frac = (min(f.end, (k + 1) * h) - max(f.start, k * h)) / h
                if frac > 1e-12:
                    sched.setdefault(k, []).append(("force", i, f.vector[0] * frac, f.vector[1] * frac))
    return sched


class SteppingSimulator:
    """Base of the built-in simulators: subclasses implement :meth:`build`."""

    name: ClassVar[str] = ""

    def build(self, scene: Scene) -> EngineWorld:
        """Called once per simulation: create the engine world for ``scene``."""
        raise NotImplementedError

    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        if params:
            scene = scene.with_params(params)
        world = self.build(scene)
        T, n_sub = scene.frames, scene.substeps
        h = scene.dt / n_sub
        sched = _schedule(scene, h, (T - 1) * n_sub)
        n = len(scene.bodies)
        rows = [world.read()]
        k = 0
        for _ in range(T - 1):
            for _ in range(n_sub):
                acts = sched.get(k)
                if acts:
                    for kind, i, x, y in acts:
                        (world.apply_impulse if kind == "impulse" else world.apply_force)(i, x, y)
                if effects:
                    state = np.asarray(world.read()).reshape(n, 6)
                    for eff in effects:
                        fxy, tau = eff.forces(k * h, state)
                        for i in range(n):
                            if fxy[i, 0] or fxy[i, 1]:
                                world.apply_force(i, float(fxy[i, 0]), float(fxy[i, 1]))
                            if tau[i]:
                                world.apply_torque(i, float(tau[i]))
                world.step(h)
                k += 1
            rows.append(world.read())
        states = np.asarray(rows, dtype=float).reshape(T, n, 6)
        self._check(scene, states)
        if any(b.com_offset != (0.0, 0.0) for b in scene.bodies):
            r = com_offsets_world(scene, states[:, :, 2])  # centre -> CoM
            w = states[:, :, 5]
            states[:, :, 0:2] -= r
            states[:, :, 3] += w * r[:, :, 1]
            states[:, :, 4] -= w * r[:, :, 0]
        return Trajectory(scene.body_names, np.arange(T) / scene.fps, states, engine=self.name)

    def _check(self, scene: Scene, states: np.ndarray) -> None:
        bad = ~np.isfinite(states).all(axis=2)
        if bad.any():
            t, i = np.argwhere(bad)[0]
            raise SimulationError("state became NaN/inf", engine=self.name, frame=int(t), body=scene.bodies[i].name)
        xmin, ymin, xmax, ymax = scene.bounds
        mx, my = ESCAPE_MARGIN * (xmax - xmin), ESCAPE_MARGIN * (ymax - ymin)
        x, y = states[:, :, 0], states[:, :, 1]
        out = (x < xmin - mx) | (x > xmax + mx) | (y < ymin - my) | (y > ymax + my)
        if out.any():
            t, i = np.argwhere(out)[0]
            raise SimulationError(
                f"body left the world {tuple(scene.bounds)} (at x={x[t, i]:.3g}, y={y[t, i]:.3g})",
                engine=self.name,
                frame=int(t),
                body=scene.bodies[i].name,
            )
