"""The model discovery fits: the base scene, plus effects, plus nuisance parameters, simulated per
run and compared with the data as a residual vector.

Parameters (:class:`FitParameter`) are of three kinds, all in one ``{key: value}`` dict:

``body``
    the scene's declared unknowns (``ball.mass``), shared by all runs;
``effect``
    an effect's parameters under its key (``linear_drag.c``), shared by all runs;
``nuisance``
    one run's uncertain initial state (``ball.vy0``; ``<run>/ball.vy0`` with several runs) or the
    vector of one of its scheduled forces or impulses (``force0.fx``). Jointed bodies get only an
    initial angle and rate; the chain's positions, velocities and joint anchors follow from them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.discover.data import DiscoverError, Part, Run, Split
from physbench.discover.residuals import Layout
from physbench.effects import apply_measurements
from physbench.effects.measurement import ClockScale
from physbench.errors import SimulationError
from physbench.parameter import Parameter
from physbench.recording import POSE_FIELDS, Recording, Track
from physbench.scene import Scene
from physbench.trajectory import Trajectory

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.render.base import Renderer
    from physbench.simulators.base import Simulator

NUISANCE = ("x0", "y0", "angle0", "vx0", "vy0", "omega0")
#: Typical size of a change of each nuisance (optimiser scaling and finite-difference unit).
_NUISANCE_SCALE = {"x0": 0.01, "y0": 0.01, "angle0": 0.01, "vx0": 0.05, "vy0": 0.05, "omega0": 0.05}
_NUISANCE_UNIT = {
    "x0": "m",
    "y0": "m",
    "angle0": "rad",
    "vx0": "m/s",
    "vy0": "m/s",
    "omega0": "rad/s",
}


@dataclass(frozen=True)
class FitParameter(Parameter):
    """A :class:`~physbench.parameter.Parameter` that discovery fits. ``owner`` is the body
    (``body`` and ``nuisance`` kinds), the effect's key (``effect``) or ``force<i>`` (a scheduled
    force's vector); ``default`` is where the fit starts. Adds ``kind``, ``scale`` (the typical
    size of a change: the optimiser's and the finite differences' unit), ``run`` (the run a
    nuisance parameter belongs to) and ``prefix`` (``"<run>/"`` before a nuisance key when there
    are several runs)."""

    default: float = 0.0
    kind: str = "body"
    scale: float = 1.0
    run: int | None = None
    prefix: str = ""

    @property
    def key(self) -> str:
        """``"<prefix><owner>.<name>"``: ``ball.mass``, ``linear_drag.c``, ``run2/ball.vy0``."""
        return f"{self.prefix}{self.owner}.{self.name}"

    @classmethod
    def of(
        cls,
        p: Parameter,
        *,
        kind: str,
        default: float,
        scale: float,
        run: int | None = None,
        prefix: str = "",
    ) -> FitParameter:
        """``p`` (name, range, owner, unit, doc) as a parameter to fit from ``default``."""
        return cls(
            p.name,
            p.low,
            p.high,
            owner=p.owner,
            unit=p.unit,
            default=default,
            doc=p.doc,
            extensible=p.extensible,
            kind=kind,
            scale=scale,
            run=run,
            prefix=prefix,
        )


# --------------------------------------------------------------------------- initial state


def chain_parents(scene: Scene) -> dict[str, tuple[str | None, int]] | None:
    """Jointed body -> (parent body or None for the world, joint index), when every jointed body
    hangs from exactly one joint as its ``a`` side and the chains end at the world; else None."""
    out: dict[str, tuple[str | None, int]] = {}
    for i, j in enumerate(scene.joints):
        if j.a in out:
            return None
        out[j.a] = (j.b, i)
    for body in out:
        seen, b = set(), body
        while b is not None:
            if b in seen or b not in out:
                return None
            seen.add(b)
            b = out[b][0]
    return out


def _rot(v: np.ndarray, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _cross(w: float, r: np.ndarray) -> np.ndarray:
    return np.array([-w * r[1], w * r[0]])


def apply_initial(
    scene: Scene,
    state: Mapping[str, Mapping[str, float]],
    forces: Mapping[int, Mapping[str, float]],
) -> Scene:
    """``scene`` with initial-state changes ``{body: {"vx0": ...}}`` (absolute values) and force
    vector changes ``{force index: {"fx": ..., "fy": ...}}`` applied."""
    if not state and not forces:
        return scene
    bodies = {b.name: b for b in scene.bodies}
    joints = list(scene.joints)
    parents = chain_parents(scene) or {}
    for name, ch in state.items():
        if name in parents:
            continue
        b = bodies[name]
        bodies[name] = replace(
            b,
            position=(ch.get("x0", b.position[0]), ch.get("y0", b.position[1])),
            velocity=(ch.get("vx0", b.velocity[0]), ch.get("vy0", b.velocity[1])),
            angle=ch.get("angle0", b.angle),
            angular_velocity=ch.get("omega0", b.angular_velocity),
        )
    if any(name in parents for name in state):
        new: dict[str, tuple[np.ndarray, float, np.ndarray, float]] = {}
        old = {b.name: b for b in scene.bodies}
        pending = list(parents)
        while pending:
            for name in list(pending):
                parent, ji = parents[name]
                if parent is not None and parent not in new:
                    continue
                pending.remove(name)
                b, ch = old[name], state.get(name, {})
                a0 = np.asarray(scene.joints[ji].anchor, dtype=float)
                if parent is None:
                    anchor, v_anchor = a0, np.zeros(2)
                else:
                    pb = old[parent]
                    cp, ap, vp, wp = new[parent]
                    anchor = cp + _rot(a0 - np.asarray(pb.position), ap - pb.angle)
                    v_anchor = vp + _cross(wp, anchor - cp)
                angle = ch.get("angle0", b.angle)
                omega = ch.get("omega0", b.angular_velocity)
                centre = anchor + _rot(np.asarray(b.position, dtype=float) - a0, angle - b.angle)
                vel = v_anchor + _cross(omega, centre - anchor)
                new[name] = (centre, angle, vel, omega)
                joints[ji] = replace(scene.joints[ji], anchor=(float(anchor[0]), float(anchor[1])))
                bodies[name] = replace(
                    b,
                    position=(float(centre[0]), float(centre[1])),
                    angle=float(angle),
                    velocity=(float(vel[0]), float(vel[1])),
                    angular_velocity=float(omega),
                )
    fs = list(scene.forces)
    for i, ch in forces.items():
        f = fs[i]
        fs[i] = replace(f, vector=(ch.get("fx", f.vector[0]), ch.get("fy", f.vector[1])))
    return replace(
        scene,
        bodies=tuple(bodies[b.name] for b in scene.bodies),
        joints=tuple(joints),
        forces=tuple(fs),
    )


def nuisance_params(
    run: Run, index: int, prefix: str, names: Sequence[str] | str = "auto"
) -> list[FitParameter]:
    """The nuisance parameters of one run. ``"auto"``: angle and rate of every jointed body (when
    the joints form chains hanging from the world); position and velocity (plus angle and rate
    when the data hold angles) of every free body moving at t = 0; the vector of every scheduled
    impulse. ``"none"``: nothing. Or a list of ``body.x0``-style names (``force<i>.fx`` for
    forces)."""
    scene = run.scene
    parents = chain_parents(scene)
    jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b is not None}
    has_angle = run.recording is None or any(
        tr.angle is not None for tr in run.recording.tracks.values()
    )
    wanted: list[tuple[str, str]] = []
    if names == "none":
        return []
    if names == "auto":
        for b in scene.bodies:
            if b.name in jointed:
                if parents is not None and b.name in parents:
                    wanted += [(b.name, "angle0"), (b.name, "omega0")]
                continue
            if math.hypot(*b.velocity) > 0 or b.angular_velocity != 0:
                wanted += [(b.name, "x0"), (b.name, "y0"), (b.name, "vx0"), (b.name, "vy0")]
                if has_angle and b.angular_velocity != 0:
                    wanted += [(b.name, "angle0"), (b.name, "omega0")]
        for i, f in enumerate(scene.forces):
            if f.kind == "impulse":
                wanted += [(f"force{i}", "fx"), (f"force{i}", "fy")]
    else:
        for item in names:
            target, _, name = str(item).rpartition(".")
            if target.startswith("force") and target[5:].isdigit() and name in ("fx", "fy"):
                if int(target[5:]) >= len(scene.forces):
                    raise DiscoverError(
                        f"nuisance {item!r}: scene {scene.name!r} has {len(scene.forces)} "
                        f"forces (force0..force{len(scene.forces) - 1})"
                    )
            elif target not in scene.body_names or name not in NUISANCE:
                raise DiscoverError(
                    f"nuisance {item!r}: expected BODY.NAME with a body of scene {scene.name!r} "
                    f"({', '.join(scene.body_names)}) and NAME one of {', '.join(NUISANCE)}, "
                    "or force<i>.fx/fy"
                )
            elif target in jointed and name not in ("angle0", "omega0"):
                raise DiscoverError(
                    f"nuisance {item!r}: a jointed body's initial state is its angle0 and omega0"
                )
            elif target in jointed and (parents is None or target not in parents):
                raise DiscoverError(
                    f"nuisance {item!r}: the joints of scene {scene.name!r} do not form chains "
                    "from the world"
                )
            wanted.append((target, name))
    out = []
    xmin, ymin, xmax, ymax = scene.bounds
    size = max(xmax - xmin, ymax - ymin)
    for target, name in wanted:
        if target.startswith("force") and target[5:].isdigit():
            f = scene.forces[int(target[5:])]
            v = f.vector[0 if name == "fx" else 1]
            half = max(0.5 * math.hypot(*f.vector), 1e-3)
            start, low, high, scale = v, v - half, v + half, max(0.02 * math.hypot(*f.vector), 1e-4)
        else:
            b = scene.bodies[scene.body_index(target)]
            start = {
                "x0": b.position[0],
                "y0": b.position[1],
                "angle0": b.angle,
                "vx0": b.velocity[0],
                "vy0": b.velocity[1],
                "omega0": b.angular_velocity,
            }[name]
            scale = _NUISANCE_SCALE[name]
            if name in ("x0", "y0"):
                hx, hy = b.shape.half_extents(b.angle)
                lo_b, hi_b = (xmin + hx, xmax - hx) if name == "x0" else (ymin + hy, ymax - hy)
                low, high = max(lo_b, start - 0.1 * size), min(hi_b, start + 0.1 * size)
            elif name == "angle0":
                low, high = start - 0.5, start + 0.5
            else:
                half = max(2.0, abs(start)) if name != "omega0" else max(3.0, abs(start))
                low, high = start - half, start + half
        out.append(
            FitParameter(
                name,
                float(low),
                float(high),
                owner=target,
                unit=_NUISANCE_UNIT.get(name, ""),
                default=float(start),
                kind="nuisance",
                scale=float(scale),
                run=index,
                prefix=prefix,
            )
        )
    return out


def body_params(scene: Scene) -> list[FitParameter]:
    """The scene's declared unknowns, starting from the scene's values (clipped into range)."""
    out = []
    for u in scene.unknowns:
        b = scene.bodies[scene.body_index(u.owner)]
        v = getattr(b, u.name)  # a body field, named by the validated unknown
        if v is None:  # moment from the shape
            v = b.inertia()
        start = float(min(max(v, u.low), u.high))
        out.append(FitParameter.of(u, kind="body", default=start, scale=0.02 * (u.high - u.low)))
    return out


def effect_params(effect: Effect, starts: Mapping[str, float] | None = None) -> list[FitParameter]:
    """All parameters of ``effect`` under its key, starting at ``starts`` or its current values."""
    out = []
    for p in effect.parameters():
        v = (starts or {}).get(p.name, effect.values.get(p.name, p.default))
        assert v is not None  # every effect parameter has a default
        out.append(
            FitParameter.of(p, kind="effect", default=float(v), scale=0.01 * (p.high - p.low))
        )
    return out


# --------------------------------------------------------------------------- simulation


def resample(traj: Trajectory, times: np.ndarray) -> Trajectory:
    """Poses of ``traj`` at ``times`` (Hermite interpolation with its velocities); velocities are
    left at the nearest earlier frame's."""
    if traj.times.shape == times.shape and np.allclose(traj.times, times, rtol=0, atol=1e-12):
        return traj
    rec = Recording(
        {
            b: Track(times, np.zeros_like(times), np.zeros_like(times), np.zeros_like(times))
            for b in traj.bodies
        }
    )
    got = rec.sample(traj)
    k = np.clip(np.searchsorted(traj.times, times, side="right") - 1, 0, traj.frames - 1)
    states = traj.states[k].copy()
    for i, b in enumerate(traj.bodies):
        tr = got.tracks[b]
        states[:, i, 0], states[:, i, 1], states[:, i, 2] = tr.x, tr.y, tr.angle
    return Trajectory(traj.bodies, times, states, engine=traj.engine)


@dataclass(eq=False)
class Problem:
    """The data side: runs, their split, the simulator and (for frames) the renderer, and the
    residual layout of every part."""

    runs: Sequence[Run]
    split: Split
    simulator: Simulator
    renderer: Renderer | None = None
    layouts: dict[tuple[str, int], Layout] = field(default_factory=dict)
    simulations: int = 0
    _truncated: dict[tuple[str, int, float], tuple[Part, np.ndarray]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for role, parts in (
            ("fit", self.split.fit),
            ("lead", self.split.lead),
            ("held", self.split.held),
        ):
            for p in parts:
                run = self.runs[p.run]
                if p.recording is not None:
                    self.layouts[(role, p.run)] = Layout.of_recording(p.recording, run.scene)
                else:
                    assert run.frames is not None and p.frames is not None
                    self.layouts[(role, p.run)] = Layout.of_frames(
                        p.frames, run.frames.shape, run.scene.fps
                    )
        if any(r.frames is not None for r in self.runs) and self.renderer is None:
            raise DiscoverError("runs with frames need a renderer for the image loss")

    def truncated(self, role: str, part: Part, horizon: float) -> tuple[Part, np.ndarray]:
        """``part`` cut to the first ``horizon`` share of its time span, and its residual
        weights."""
        layout = self.layouts[(role, part.run)]
        if horizon >= 1.0:
            return part, layout.weight
        key = (role, part.run, horizon)
        hit = self._truncated.get(key)
        if hit is not None:
            return hit
        t0 = float(layout.t.min())
        cut = t0 + horizon * (part.t_end - t0)
        if part.recording is not None:
            from physbench.discover.data import sub_recording

            rec = sub_recording(part.recording, -math.inf, cut)
            if rec is None:
                out = (part, layout.weight)
            else:
                sub = Part(part.run, recording=rec, t_end=rec.t_end)
                out = (sub, Layout.of_recording(rec, self.runs[part.run].scene).weight)
        else:
            assert part.frames is not None
            fps = self.runs[part.run].scene.fps
            keep = part.frames[part.frames / fps <= cut + 1e-9]
            if keep.size == 0:
                keep = part.frames[:1]
            out = (Part(part.run, frames=keep, t_end=float(keep[-1]) / fps), np.ones(1))
        self._truncated[key] = out
        return out

    def parts(self, role: str) -> tuple[Part, ...]:
        return {"fit": self.split.fit, "lead": self.split.lead, "held": self.split.held}[role]

    def series(self, role: str, runs: Sequence[int] | None = None) -> np.ndarray:
        """A label per entry of the full-horizon residuals of ``role`` (as
        :meth:`Model.residuals` concatenates them) naming its series: one run's body and field
        in time order, or one frame of an image part. The fit's intervals estimate the
        correlation in time within each series."""
        out, base = [], 0
        for p in self.parts(role):
            if runs is not None and p.run not in runs:
                continue
            lay = self.layouts[(role, p.run)]
            if lay.field[0] < 0:
                key = np.rint(lay.t * self.runs[p.run].scene.fps).astype(np.int64)
            else:
                key = lay.body.astype(np.int64) * len(POSE_FIELDS) + lay.field
            _, inverse = np.unique(key, return_inverse=True)
            out.append(base + inverse)
            base += int(inverse.max()) + 1 if inverse.size else 0
        return np.concatenate(out) if out else np.zeros(0, dtype=np.int64)

    @property
    def unit(self) -> str:
        units = {lay.unit for lay in self.layouts.values()}
        return units.pop() if len(units) == 1 else "mixed units"


class Model:
    """Effects plus parameters over a :class:`Problem`. ``values`` holds every parameter's current
    value; :meth:`residuals` simulates the parts of one role with some values overridden."""

    def __init__(
        self, problem: Problem, effects: Sequence[Effect], params: Sequence[FitParameter]
    ) -> None:
        self.problem = problem
        self.effects = list(effects)
        self.params = list(params)
        keys = [p.key for p in self.params]
        if len(set(keys)) != len(keys):
            dup = sorted({k for k in keys if keys.count(k) > 1})
            raise DiscoverError(
                f"parameter keys {dup} appear twice; give effects of one kind distinct labels"
            )
        self.values: dict[str, float] = {p.key: p.default for p in self.params}
        self._cache: dict[tuple[Any, ...], np.ndarray] = {}

    def param(self, key: str) -> FitParameter:
        for p in self.params:
            if p.key == key:
                return p
        from physbench.errors import UnknownNameError

        raise UnknownNameError("model parameter", key, [p.key for p in self.params])

    def extended(self, effect: Effect, starts: Mapping[str, float] | None = None) -> Model:
        """This model plus ``effect`` (its parameters starting at ``starts``), values carried
        over."""
        m = Model(
            self.problem, [*self.effects, effect], [*self.params, *effect_params(effect, starts)]
        )
        m.values.update(self.values)
        return m

    def widen(self, key: str, factor: float = 10.0) -> FitParameter:
        """Widen the range of the effect parameter ``key`` ``factor`` times (its nonzero ends, in
        the model and in the effect, so that the effect accepts the new values); returns the
        widened parameter. Called when a fit ends at the end of an extensible range."""
        old = self.param(key)
        wide = old.widened(factor)
        new = replace(old, low=wide.low, high=wide.high)
        for e in self.effects:
            if e.key == old.owner:
                e.widen(old.name, new.low, new.high)
        self.params = [new if p.key == key else p for p in self.params]
        return new

    def _time_scale(self, values: Mapping[str, float]) -> float:
        """How much longer than the data the simulation must run (clock effects)."""
        s = 1.0
        for e in self.effects:
            if isinstance(e, ClockScale):
                s = max(s, float(values.get(f"{e.key}.scale", e.values.get("scale", 1.0))))
        return s

    def run_scene(self, run: int, values: Mapping[str, float]) -> tuple[Scene, dict[str, float]]:
        """The run's scene with its nuisance applied, and the body + effect parameters to
        simulate."""
        state: dict[str, dict[str, float]] = {}
        forces: dict[int, dict[str, float]] = {}
        sim: dict[str, float] = {}
        for p in self.params:
            v = values[p.key]
            if p.kind == "nuisance":
                if p.run != run:
                    continue
                if p.owner.startswith("force") and p.owner[5:].isdigit():
                    forces.setdefault(int(p.owner[5:]), {})[p.name] = v
                else:
                    state.setdefault(p.owner, {})[p.name] = v
            else:
                sim[p.key] = v
        return apply_initial(self.problem.runs[run].scene, state, forces), sim

    def simulate(
        self, run: int, values: Mapping[str, float], t_end: float | None = None
    ) -> tuple[Trajectory, Trajectory]:
        """The run simulated up to ``t_end`` (default: its end) on the data's clock: the engine's
        trajectory and the measured one (after the measurement effects)."""
        r = self.problem.runs[run]
        scene, sim = self.run_scene(run, values)
        t = r.t_end if t_end is None else t_end
        scale = self._time_scale(values)
        frames = max(2, math.ceil(t * scale * scene.fps - 1e-9) + 1)
        scene = replace(scene, frames=frames)
        self.problem.simulations += 1
        traj = self.problem.simulator.simulate(scene, sim, effects=self.effects)
        return traj, apply_measurements(traj, self.effects)  # measurement values were set in setup

    def part_residuals(
        self, role: str, part: Part, values: Mapping[str, float], horizon: float = 1.0
    ) -> np.ndarray:
        """Weighted residuals (simulated minus observed) of one part, or of its first ``horizon``
        share of time."""
        run = self.problem.runs[part.run]
        part, weight = self.problem.truncated(role, part, horizon)
        _, measured = self.simulate(part.run, values, part.t_end)
        if part.recording is not None:
            return part.recording.residuals(measured) * weight
        assert (
            run.frames is not None and part.frames is not None and self.problem.renderer is not None
        )
        times = np.arange(int(part.frames[-1]) + 1) / run.scene.fps
        seen = resample(measured, times)
        scene = replace(run.scene, frames=times.size)
        img = self.problem.renderer.render(scene, seen)
        return (img[part.frames] - run.frames[part.frames]).astype(float).ravel()

    def residuals(
        self,
        role: str,
        values: Mapping[str, float] | None = None,
        runs: Sequence[int] | None = None,
        horizon: float = 1.0,
    ) -> np.ndarray:
        """Concatenated residuals of the parts of ``role`` (``fit``, ``lead``, ``held``), for the
        runs ``runs`` (default all of that role), at ``values`` (default the current ones), over
        the first ``horizon`` share of each part. Raises
        :class:`~physbench.errors.SimulationError` when a simulation explodes."""
        vals = dict(self.values)
        if values:
            vals.update(values)
        key = (role, None if runs is None else tuple(runs), horizon, tuple(sorted(vals.items())))
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        parts = [p for p in self.problem.parts(role) if runs is None or p.run in runs]
        out = (
            np.concatenate([self.part_residuals(role, p, vals, horizon) for p in parts])
            if parts
            else np.zeros(0)
        )
        if len(self._cache) > 16:
            self._cache.clear()
        self._cache[key] = out
        return out

    def free_keys(self) -> list[str]:
        """Keys fitted in the main fit: shared parameters and the nuisance of training runs."""
        train = set(self.problem.split.train_runs)
        return [p.key for p in self.params if p.kind != "nuisance" or p.run in train]

    def without(self, key: str) -> Model:
        """This model without the effect of ``key`` (and its parameters), at the current values of
        the others."""
        effects = [e for e in self.effects if e.key != key]
        params = [p for p in self.params if not (p.kind == "effect" and p.owner == key)]
        out = Model(self.problem, effects, params)
        out.values.update({k: v for k, v in self.values.items() if k in out.values})
        return out

    def copy(self) -> Model:
        m = Model(self.problem, self.effects, self.params)
        m.values = dict(self.values)
        return m


def safe_residuals(
    model: Model,
    role: str,
    values: Mapping[str, float] | None = None,
    runs: Sequence[int] | None = None,
) -> np.ndarray | None:
    """:meth:`Model.residuals`, or None when the simulation explodes."""
    try:
        return model.residuals(role, values, runs)
    except SimulationError:
        return None


__all__ = [
    "NUISANCE",
    "FitParameter",
    "Model",
    "Problem",
    "apply_initial",
    "body_params",
    "chain_parents",
    "effect_params",
    "nuisance_params",
    "resample",
    "safe_residuals",
]
