r"""ParamSpace: the unknowns of a run (:class:`~physbench.parameter.Parameter`\ s), their ranges
and normalisation, and where each unknown acts when a point is simulated.

Values travel as ``{"key": value}`` dicts (:data:`Params`); estimators that want vectors use
:meth:`ParamSpace.to_unit` / :meth:`ParamSpace.from_unit` (each range mapped to [0, 1]).

An unknown is a body parameter the scene declares unknown (``a.mass``, named by its bare name
``mass`` in ``--params``) or, in a run, a scene-level parameter named by its key
(:func:`scene_parameters`): the scene's ``gravity`` (:data:`~physbench.scene.GRAVITY`), a
parameter of one of the run's effects (``linear_drag.c``) or of the camera that made the
observation (``camera.scale``, ``camera.clock``). Any of them may carry its own range,
``KEY=LOW:HIGH`` (``gravity=-11:-9``), on the command line, in the API and in a sweep spec.
:func:`simulate_seen` is where each value acts: body parameters, gravity and effect parameters go
to the simulator, the camera's change how the simulated world is seen.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError, SceneError, UnknownNameError
from physbench.parameter import Parameter
from physbench.scene import GRAVITY, MAX_GRAVITY, check_body_param

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.trajectory import Trajectory

Params = dict[str, float]

#: Share of an unknown's range from either end within which an estimate counts as at its bound.
AT_BOUND = 1e-3

#: Owner of the measurement parameters: the camera (or other recorder) that made the observation.
CAMERA = "camera"
#: The calibration's scale error: true metres per metre of the calibration the observation was
#: measured with (1: the calibration is right; 1.02 when what it calls 1 m is truly 1.02 m). It
#: scales the observation about the scene's origin, positions and sizes alike, so the model is
#: seen through the same error: every length of the simulated world is divided by it.
CAMERA_SCALE = Parameter(
    "scale", 0.9, 1.1, owner=CAMERA, doc="true metres per metre of the calibration"
)
#: The recording clock's rate error: true seconds per second of the recording's clock (1: the
#: stated frame rate is right); frame ``k``, stamped ``k / fps``, shows the world at
#: ``clock · k / fps``, so the model is sampled at ``fps / clock``.
CAMERA_CLOCK = Parameter(
    "clock", 0.9, 1.1, owner=CAMERA, doc="true seconds per second of the recording's clock"
)
CAMERA_PARAMS = (CAMERA_SCALE, CAMERA_CLOCK)
#: The ranges a run may give the scene-level parameters that are not an effect's (an effect's
#: parameter keeps to its declared range, or, when extensible, to its zero end).
LIMITS: dict[str, tuple[float, float]] = {
    GRAVITY.key: (-MAX_GRAVITY, MAX_GRAVITY),
    CAMERA_SCALE.key: (0.1, 10.0),
    CAMERA_CLOCK.key: (0.1, 10.0),
}
_CAMERA_KEYS = frozenset(p.key for p in CAMERA_PARAMS)
#: ``KEY`` or ``KEY=LOW:HIGH``, the numbers as Python writes floats.
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ITEM = re.compile(rf"(?P<key>[^=\s]+)(?:=(?P<low>{_NUMBER}):(?P<high>{_NUMBER}))?")


def split_params(value: str | Sequence[str]) -> tuple[str, ...]:
    """The unknown names of one set as the user spelled it: ``"mass+elasticity"``,
    ``"mass,elasticity"``, ``"mass elasticity"`` or ``["mass", "elasticity"]`` (each item split the
    same way; a ``+`` inside a range's number, ``c=0:1e+2``, does not split). Called by ``run
    --params``, ``train --params`` and a sweep spec's ``unknowns``; an empty set or a repeated
    name is a :class:`~physbench.errors.PhysbenchError`."""
    items = [value] if isinstance(value, str) else list(value)
    names = tuple(n for item in items for n in re.split(r"[\s,]+|(?<!\d[eE])\+", item.strip()) if n)
    if not names or len(set(names)) != len(names):
        raise PhysbenchError(
            f"unknown-parameter set {value!r}: expected names such as mass, mass+elasticity, "
            "mass,elasticity or mass elasticity (no repeats)"
        )
    return names


def parse_unknown(item: str) -> tuple[str, tuple[float, float] | None]:
    """One ``--params`` item: its name or key and the range it gives (``None``: the default),
    from ``KEY`` or ``KEY=LOW:HIGH`` (``gravity=-11:-9``)."""
    m = _ITEM.fullmatch(item)
    if m is None:
        raise PhysbenchError(
            f"unknown {item!r}: expected a name or key, optionally with a range KEY=LOW:HIGH "
            "(e.g. gravity=-11:-9 or linear_drag.c=0:0.5)"
        )
    if m["low"] is None:
        return m["key"], None
    low, high = float(m["low"]), float(m["high"])
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise PhysbenchError(f"unknown {item!r}: the range needs finite ends with LOW < HIGH")
    return m["key"], (low, high)


def scene_parameters(effects: Iterable[Effect] = ()) -> tuple[Parameter, ...]:
    """The scene-level parameters a run may fit besides its scene's body unknowns, with their
    default ranges: :data:`~physbench.scene.GRAVITY`, the camera's (:data:`CAMERA_PARAMS`) and
    each of the run's ``effects``' parameters, keyed by the effect (``linear_drag.c``)."""
    return (GRAVITY, *CAMERA_PARAMS, *(p for e in effects for p in e.parameters()))


def with_range(p: Parameter, bounds: tuple[float, float] | None, *, body: bool) -> Parameter:
    """``p`` with the range a run gave it (``None``: as declared). A body parameter's range must
    hold values the body can take; :data:`LIMITS` bound gravity's and the camera's; an effect's
    parameter keeps inside its declared range, except past an end that is not zero when the range
    is only a typical span (:attr:`~physbench.parameter.Parameter.extensible`)."""
    if bounds is None:
        return p
    low, high = bounds
    given = f"{p.key}={low:g}:{high:g}"
    if body:
        try:
            check_body_param(given, p.name, low)
            check_body_param(given, p.name, high)
        except SceneError as exc:
            raise PhysbenchError(f"{given}: {exc.reason}") from None
        return replace(p, low=low, high=high)
    if p.key in LIMITS:
        lo, hi = LIMITS[p.key]
    else:
        lo = -math.inf if p.extensible and p.low != 0 else p.low
        hi = math.inf if p.extensible and p.high != 0 else p.high
    if not lo <= low < high <= hi:
        raise PhysbenchError(
            f"{given}: the range must lie in [{lo:g}, {hi:g}] {p.unit}".rstrip()
            + ("" if p.extensible or p.key in LIMITS else f" ({p.key}'s declared range)")
        )
    return replace(p, low=low, high=high)


def scene_values(params: Mapping[str, float], effects: Iterable[Effect] = ()) -> Params:
    """The values of ``params`` that :meth:`Scene.with_params <physbench.scene.Scene.with_params>`
    takes: the body parameters and gravity, without the camera's and the ``effects``'."""
    owned = {e.key for e in effects} | {CAMERA}
    return {k: v for k, v in params.items() if k.rpartition(".")[0] not in owned}


def simulate_seen(
    simulator: Simulator,
    scene: Scene,
    params: Mapping[str, float],
    effects: Sequence[Effect] = (),
) -> tuple[Scene, Trajectory]:
    """Called for every point a run simulates (the observation's truth, each iteration, each
    probe): simulate ``params`` on ``scene``, the body, gravity and effect values applied by the
    simulator, pass the trajectory through every measurement effect
    (:attr:`~physbench.effects.base.Effect.measures`), and see it through the camera's values:
    ``camera.clock`` samples the world at ``fps / clock``, ``camera.scale`` divides every length
    of the world and its motion by the scale (:meth:`Scene.scaled
    <physbench.scene.Scene.scaled>`), as a calibration off by it shows them, in the same frame.
    Returns the scene to render the trajectory in and the trajectory."""
    rest = {k: v for k, v in params.items() if k not in _CAMERA_KEYS}
    clock, scale = params.get(CAMERA_CLOCK.key), params.get(CAMERA_SCALE.key)
    timed = scene if clock is None else replace(scene, fps=scene.fps / float(clock))
    traj = simulator.simulate(timed, rest, effects=effects)
    for eff in effects:
        if eff.measures:
            traj = eff.measure(traj)
    if scale is None:
        return scene, traj
    f = 1.0 / float(scale)
    states = traj.states.copy()
    states[..., [0, 1, 3, 4]] *= f
    return scene.scaled(f), type(traj)(traj.bodies, traj.times, states, engine=traj.engine)


@dataclass(frozen=True)
class ParamSpace:
    """An ordered set of unknowns. Order is the vector order everywhere. ``scene_keys``: the keys
    of the unknowns that belong to the scene rather than to a body (gravity, an effect, the
    camera; :func:`scene_parameters`)."""

    unknowns: tuple[Parameter, ...]
    scene_keys: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.unknowns:
            raise PhysbenchError("a parameter space needs at least one unknown")
        keys = [u.key for u in self.unknowns]
        twice = sorted({k for k in keys if keys.count(k) > 1})
        if twice:
            raise PhysbenchError(f"unknowns {twice} appear twice; each key once")
        stray = sorted(set(self.scene_keys) - set(keys))
        if stray:
            raise PhysbenchError(f"scene-level keys {stray} are not among the unknowns {keys}")

    @classmethod
    def from_scene(
        cls,
        scene: Scene,
        params: Iterable[str] | None = None,
        bodies: Iterable[str] | None = None,
        *,
        offered: Sequence[Parameter] | None = None,
    ) -> ParamSpace:
        """The scene's unknowns, filtered to parameter names (``mass``) and/or bodies.

        ``offered``: the scene-level parameters a run may also fit (:func:`scene_parameters`),
        named by key in ``params`` after the scene's body unknowns, and every name may then carry
        a range (``KEY=LOW:HIGH``, :func:`parse_unknown`). ``None`` (training sets): body
        parameters only. Raises :class:`UnknownNameError` for a name neither the scene declares
        unknown nor ``offered`` holds, or for a body without unknowns.
        """
        unknowns = list(scene.unknowns)
        if not unknowns and offered is None:
            raise PhysbenchError(f"scene {scene.name!r} declares no unknown parameters")
        level = {p.key: p for p in offered or ()}
        items = None if params is None else [_item(p, offered is not None) for p in params]
        chosen: list[Parameter] = []
        ranges: dict[str, tuple[float, float] | None] = {}
        if items is not None:
            known = sorted({u.name for u in unknowns} | set(level))
            for name, bounds in items:
                if name not in known:
                    raise UnknownNameError(
                        "parameter", name, known, where=f"of scene {scene.name!r}"
                    )
                if name in ranges:
                    raise PhysbenchError(f"unknown {name!r} is named twice; name it once")
                ranges[name] = bounds
            unknowns = [u for u in unknowns if u.name in ranges]
            chosen = [with_range(level[n], b, body=False) for n, b in items if n in level]
        if bodies is not None:
            bodies = list(bodies)
            known = sorted({u.owner for u in unknowns})
            for b in bodies:
                if b not in known:
                    raise UnknownNameError(
                        "body", b, known, where=f"with unknowns in scene {scene.name!r}"
                    )
            unknowns = [u for u in unknowns if u.owner in bodies]
        unknowns = [with_range(u, ranges.get(u.name), body=True) for u in unknowns]
        if not unknowns and not chosen:
            raise PhysbenchError(
                f"scene {scene.name!r} declares no unknown parameters; name a scene-level one: "
                + (", ".join(level) or "(none offered)")
            )
        return cls((*unknowns, *chosen), tuple(p.key for p in chosen))

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(u.key for u in self.unknowns)

    @property
    def bodies(self) -> tuple[str, ...]:
        """Bodies with at least one unknown, in first-appearance order."""
        return tuple(dict.fromkeys(u.owner for u in self.body_unknowns))

    @property
    def body_unknowns(self) -> tuple[Parameter, ...]:
        """The unknowns that are a body's parameters (not :attr:`scene_keys`)."""
        return tuple(u for u in self.unknowns if u.key not in self.scene_keys)

    @property
    def low(self) -> np.ndarray:
        return np.array([u.low for u in self.unknowns])

    @property
    def high(self) -> np.ndarray:
        return np.array([u.high for u in self.unknowns])

    def __len__(self) -> int:
        return len(self.unknowns)

    def to_vector(self, params: Mapping[str, float]) -> np.ndarray:
        try:
            return np.array([float(params[k]) for k in self.keys])
        except KeyError as exc:
            raise UnknownNameError("parameter", str(exc.args[0]), self.keys) from None

    def from_vector(self, vec: Sequence[float] | np.ndarray) -> Params:
        vec = np.asarray(vec, dtype=float).reshape(-1)
        if vec.shape[0] != len(self):
            raise PhysbenchError(
                f"expected {len(self)} values for {list(self.keys)}, got {vec.shape[0]}"
            )
        return {k: float(v) for k, v in zip(self.keys, vec, strict=True)}

    def to_unit(self, params: Mapping[str, float]) -> np.ndarray:
        return (self.to_vector(params) - self.low) / (self.high - self.low)

    def from_unit(self, unit: Sequence[float] | np.ndarray) -> Params:
        u = np.clip(np.asarray(unit, dtype=float), 0.0, 1.0)
        return self.from_vector(self.low + u * (self.high - self.low))

    def clip(self, params: Mapping[str, float]) -> Params:
        return self.from_vector(np.clip(self.to_vector(params), self.low, self.high))

    def contains(self, params: Mapping[str, float]) -> bool:
        v = self.to_vector(params)
        return bool(np.all(v >= self.low - 1e-12) and np.all(v <= self.high + 1e-12))

    def at_bound(self, params: Mapping[str, float], tolerance: float = AT_BOUND) -> tuple[str, ...]:
        """The keys of ``params`` within ``tolerance`` of their range's width from either end: an
        estimate there may be held by the range rather than by the data."""
        u = self.to_unit(params)
        return tuple(k for k, x in zip(self.keys, u, strict=True) if min(x, 1 - x) <= tolerance)

    def sample(self, rng: np.random.Generator) -> Params:
        """Uniform draw inside the ranges."""
        return self.from_unit(rng.random(len(self)))

    def normalized_mse(self, estimate: Mapping[str, float], truth: Mapping[str, float]) -> float:
        """The paper's metric: each parameter divided by the maximum of its range, MSE over
        unknowns. (A range below zero, gravity's, is divided by its largest magnitude; for the
        body parameters, never negative, that is the maximum.)"""
        scale = np.maximum(np.abs(self.low), np.abs(self.high))
        d = (self.to_vector(estimate) - self.to_vector(truth)) / scale
        return float(np.mean(d * d))

    def subset(self, body: str) -> ParamSpace:
        """The unknowns of ``body``."""
        return ParamSpace(tuple(u for u in self.body_unknowns if u.owner == body))


def _item(text: str, ranged: bool) -> tuple[str, tuple[float, float] | None]:
    """A name of ``--params`` with its range (:func:`parse_unknown`) when ``ranged``, else as
    given."""
    return parse_unknown(text) if ranged else (text, None)
