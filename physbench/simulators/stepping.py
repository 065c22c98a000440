"""The engine-neutral stepping loop both built-in simulators share.

An engine adapter (:class:`EngineWorld`) only builds the world, steps it and reads and pushes body
state; the schedule of forces and impulses, effects, recording at the frame rate, the conversion
from centre of mass to shape centre and the explosion check live here once, so both engines
behave the same by construction.

Effects: ``simulate(scene, params, effects=[...])`` routes every ``params`` key ``"<key>.<param>"``
whose prefix is an effect's key (its label, else its name) to that effect, applies the rest to the
scene's bodies, and calls each effect's ``setup(scene_as_simulated, values)`` before building, so
every engine prepares effects the same way. Effects that declare ``changes_contacts`` are installed
as the engine's contact hook (:meth:`EngineWorld.set_restitution_hook`); effects with
``applies_forces = False`` are not called every substep.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.errors import PhysbenchError, SimulationError
from physbench.scene import Scene
from physbench.simulators.base import Simulator
from physbench.trajectory import Trajectory

#: A body that leaves the world bounds by more than this many world sizes has exploded.
ESCAPE_MARGIN = 1.0
#: A body at this fraction of an engine's speed limit has been clamped by the engine.
SPEED_LIMIT_FRACTION = 0.99


RestitutionHook = Callable[[float, int, "int | None"], "float | None"]


class EngineWorld:
    """One built scene inside a concrete engine (what :meth:`SteppingSimulator.build` returns).
    Body order is ``scene.bodies`` order. Subclasses implement the stepping and state methods."""

    #: Largest speed (m/s) and angular speed (rad/s) the engine lets a body reach at this step
    #: size (``math.inf``: it never clamps). A body at the limit has exploded.
    max_speed: float = math.inf
    max_angular_speed: float = math.inf
    #: Whether :meth:`set_restitution_hook` is implemented (needed by contact effects).
    contact_hook: ClassVar[bool] = False

    def step(self, h: float) -> None:
        """Advance the world by ``h`` seconds. Called ``scene.substeps`` times per frame."""
        raise NotImplementedError

    def read(self) -> list[float]:
        """Flat CoM states ``[x, y, angle, vx, vy, omega] * N`` (velocity of the CoM)."""
        raise NotImplementedError

    def apply_force(self, i: int, fx: float, fy: float) -> None:
        """Apply a force (N) at body ``i``'s centre of mass for the next step."""
        raise NotImplementedError

    def apply_torque(self, i: int, tau: float) -> None:
        """Apply a torque (N·m) to body ``i`` for the next step."""
        raise NotImplementedError

    def apply_impulse(self, i: int, jx: float, jy: float) -> None:
        """Change body ``i``'s momentum by ``(jx, jy)`` N·s now."""
        raise NotImplementedError

    def set_restitution_hook(self, hook: RestitutionHook) -> None:
        """Called once after building, when an effect changes contacts: ``hook(normal_speed, a,
        b)`` is to be called once when a contact starts (a, b body indices, b None for static
        geometry); the restitution it returns replaces the contact's for its duration. Engines
        that set :attr:`contact_hook` implement it."""
        raise NotImplementedError


def split_params(
    params: Mapping[str, float] | None, effects: Sequence[Effect]
) -> tuple[dict[str, float], list[dict[str, float]]]:
    """``params`` split into body parameters and, per effect, its values by bare parameter name.

    A key belongs to an effect when its prefix (before the last ``.``) is the effect's key.
    Raises :class:`~physbench.errors.PhysbenchError` when two effects share a key.
    """
    values: list[dict[str, float]] = [{} for _ in effects]
    if not effects:
        return dict(params or {}), values
    keys: dict[str, int] = {}
    for i, eff in enumerate(effects):
        k = eff.key
        if k in keys:
            raise PhysbenchError(
                f"two effects share the parameter key {k!r} ({effects[keys[k]]!r} and {eff!r}); "
                f"give one a distinct label, e.g. label='{k}_2'"
            )
        keys[k] = i
    body: dict[str, float] = {}
    for key, value in (params or {}).items():
        prefix, _, name = key.rpartition(".")
        if prefix in keys:
            values[keys[prefix]][name] = value
        else:
            body[key] = value
    return body, values


def first_restitution(effects: Sequence[Effect]) -> RestitutionHook | None:
    """One hook asking each effect that ``changes_contacts`` in turn (the first answer that is not
    ``None`` wins), or ``None`` when no effect does."""
    hooks = [e.restitution for e in effects if e.changes_contacts]
    if not hooks:
        return None
    if len(hooks) == 1:
        return hooks[0]

    def hook(speed: float, a: int, b: int | None) -> float | None:
        for h in hooks:
            e = h(speed, a, b)
            if e is not None:
                return e
        return None

    return hook


def com_offsets_world(scene: Scene, angles: np.ndarray) -> np.ndarray:
    """``(..., N, 2)`` vectors from shape centre to centre of mass, rotated by ``angles (...,
    N)``."""
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
        out.append(
            (
                b.position[0] + rx,
                b.position[1] + ry,
                b.angle,
                b.velocity[0] - w * ry,
                b.velocity[1] + w * rx,
                w,
            )
        )
    return out


Action = tuple[bool, int, float, float]  # (is impulse, body index, x, y)


def _schedule(scene: Scene, h: float, n_sub: int) -> dict[int, list[Action]]:
    """Substep index -> actions applied just before that substep."""
    sched: dict[int, list[Action]] = {}
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    for f in scene.forces:
        i = index[f.body]
        if f.kind == "impulse":
            k = max(0, math.ceil(f.start / h - 1e-9))
            if k < n_sub:
                sched.setdefault(k, []).append((True, i, *f.vector))
        else:
            # A substep [k h, (k+1) h) feels the force by the fraction of it inside the window,
            # so Δv = F (end - start) / m exactly, whatever the substep count.
            k0, k1 = math.floor(f.start / h), min(n_sub, math.ceil(f.end / h))
            for k in range(max(0, k0), k1):
                frac = (min(f.end, (k + 1) * h) - max(f.start, k * h)) / h
                if frac > 1e-12:
                    sched.setdefault(k, []).append(
                        (False, i, f.vector[0] * frac, f.vector[1] * frac)
                    )
    return sched


class _EffectFailed(Exception):
    """Carries an effect's own exception through the engine-error handler unchanged."""


class SteppingSimulator(Simulator):
    """A :class:`~physbench.simulators.base.Simulator` for any engine that can step a world:
    subclasses implement :meth:`build`."""

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
        values: list[dict[str, float]] = []
        if effects:
            params, values = split_params(params, effects)
        if params:
            scene = scene.with_params(params)
        for eff, vals in zip(effects, values, strict=True):
            eff.setup(scene, vals)  # errors in effect values are the caller's, raised unchanged
        try:
            world = self.build(scene)
        except SimulationError:
            raise
        except Exception as exc:  # engines reject absurd values with assorted exception types
            raise SimulationError(
                f"engine cannot build the scene: {type(exc).__name__}: {exc}",
                engine=self.name,
                frame=0,
            ) from exc
        if effects:
            hook = first_restitution(effects)
            if hook is not None:
                if not world.contact_hook:
                    names = [e.name for e in effects if e.changes_contacts]
                    raise SimulationError(
                        f"effects {names} change contacts, but this engine has no contact hook "
                        "(EngineWorld.set_restitution_hook)",
                        engine=self.name,
                        frame=0,
                    )
                world.set_restitution_hook(hook)
            effects = [e for e in effects if e.applies_forces]
        T, n_sub = scene.frames, scene.substeps
        h = scene.dt / n_sub
        sched = _schedule(scene, h, (T - 1) * n_sub)
        vmax = world.max_speed
        if math.isfinite(vmax):
            self._check_actions(scene, sched, vmax, h, n_sub)
        busy = {k // n_sub for k in sched}  # frames (0-based intervals) with forces or impulses
        n = len(scene.bodies)
        step, read = world.step, world.read
        rows = [read()]
        frame, culprit = 0, None
        try:
            for frame in range(1, T):
                if not effects and frame - 1 not in busy:
                    for _ in range(n_sub):
                        step(h)
                else:
                    for k in range((frame - 1) * n_sub, frame * n_sub):
                        for impulse, culprit, x, y in sched.get(k, ()):
                            (world.apply_impulse if impulse else world.apply_force)(culprit, x, y)
                        culprit = None
                        if effects:
                            self._apply_effects(world, effects, k * h, n)
                        step(h)
                row = read()
                rows.append(row)
                if not math.isfinite(
                    sum(row)
                ):  # stop early: NaN only spreads (and can stall engines)
                    break
        except _EffectFailed as exc:
            raise exc.__cause__ from None  # type: ignore[misc]
        except Exception as exc:
            body = scene.bodies[culprit].name if culprit is not None else None
            raise SimulationError(
                f"engine failed: {type(exc).__name__}: {exc}",
                engine=self.name,
                frame=frame,
                body=body,
            ) from exc
        states = np.asarray(rows, dtype=float).reshape(len(rows), n, 6)
        self._check(scene, states, world)
        if len(rows) < T:  # the sum overflowed although every value is finite: still an explosion
            raise SimulationError("state overflowed", engine=self.name, frame=len(rows) - 1)
        if any(b.com_offset != (0.0, 0.0) for b in scene.bodies):
            r = com_offsets_world(scene, states[:, :, 2])  # centre -> CoM
            w = states[:, :, 5]
            states[:, :, 0:2] -= r
            states[:, :, 3] += w * r[:, :, 1]
            states[:, :, 4] -= w * r[:, :, 0]
        return Trajectory(scene.body_names, np.arange(T) / scene.fps, states, engine=self.name)

    def _check_actions(
        self, scene: Scene, sched: dict[int, list[Action]], vmax: float, h: float, n_sub: int
    ) -> None:
        """Raise for a force or impulse that alone would push a body past the engine's speed limit
        within one step (the engine would clamp it silently, possibly between two frames)."""
        for k, acts in sched.items():
            for impulse, i, x, y in acts:
                body = scene.bodies[i]
                dv = math.hypot(x, y) / body.mass * (1.0 if impulse else h)
                if dv >= SPEED_LIMIT_FRACTION * vmax:
                    raise SimulationError(
                        f"{'impulse' if impulse else 'force'} changes the speed by {dv:.3g} m/s "
                        "in one step; "
                        f"the engine clamps speeds above {vmax:.3g} m/s at this step size",
                        engine=self.name,
                        frame=k // n_sub + 1,
                        body=body.name,
                    )

    @staticmethod
    def _apply_effects(world: EngineWorld, effects: Sequence[Effect], t: float, n: int) -> None:
        state = np.asarray(world.read()).reshape(n, 6)
        try:
            fxy, tau = effects[0].forces(t, state)
            for eff in effects[1:]:
                f2, t2 = eff.forces(t, state)
                fxy, tau = fxy + f2, tau + t2
        except Exception as exc:
            raise _EffectFailed from exc
        forces, torques = (
            np.asarray(fxy, dtype=float).tolist(),
            np.asarray(tau, dtype=float).tolist(),
        )
        for i in range(n):
            fx, fy = forces[i]
            if fx or fy:
                world.apply_force(i, fx, fy)
            if torques[i]:
                world.apply_torque(i, torques[i])

    def _check(self, scene: Scene, states: np.ndarray, world: EngineWorld) -> None:
        """Raise for the earliest frame where a body is NaN, far outside the world, or at the
        engine's speed limit."""
        xmin, ymin, xmax, ymax = scene.bounds
        mx, my = ESCAPE_MARGIN * (xmax - xmin), ESCAPE_MARGIN * (ymax - ymin)
        x, y = states[:, :, 0], states[:, :, 1]
        nan = ~np.isfinite(states).all(axis=2)
        out = (x < xmin - mx) | (x > xmax + mx) | (y < ymin - my) | (y > ymax + my)
        fast = np.zeros_like(out)
        vmax, wmax = world.max_speed, world.max_angular_speed
        if math.isfinite(vmax):
            with np.errstate(invalid="ignore", over="ignore"):
                fast |= np.hypot(states[:, :, 3], states[:, :, 4]) >= SPEED_LIMIT_FRACTION * vmax
        if math.isfinite(wmax):
            with np.errstate(invalid="ignore"):
                fast |= np.abs(states[:, :, 5]) >= SPEED_LIMIT_FRACTION * wmax
        bad = nan | out | fast
        if not bad.any():
            return
        t, i = np.unravel_index(int(np.argmax(bad)), bad.shape)  # earliest frame, then first body
        if nan[t, i]:
            why = "state became NaN/inf"
        elif out[t, i]:
            why = f"body left the world {tuple(scene.bounds)} (at x={x[t, i]:.3g}, y={y[t, i]:.3g})"
        else:
            why = (
                f"speed reached the engine's limit ({vmax:.3g} m/s, {wmax:.3g} rad/s at this step "
                "size; "
                f"v={math.hypot(states[t, i, 3], states[t, i, 4]):.3g} m/s, "
                f"ω={states[t, i, 5]:.3g} rad/s): "
                "the engine clamped it; more substeps raise the limit"
            )
        raise SimulationError(why, engine=self.name, frame=int(t), body=scene.bodies[i].name)
