"""The Effect contract, and the machinery every effect shares: parameter values, body selection,
smoothing.

An effect is a model extension (drag, rolling resistance, joint damping, a contact law, a sensor
bias) that every engine applies the same way. It acts in up to three ways, each declared by a
class trait so that the framework calls only what an effect uses:

``applies_forces`` (default ``True``)
    :meth:`Effect.forces` is called every substep and its forces and torques are applied;
``changes_contacts`` (default ``False``)
    :meth:`Effect.restitution` is installed as the engine's contact hook;
``measures`` (default ``False``)
    :meth:`Effect.measure` is applied to every simulated trajectory before it is compared with
    data (:func:`physbench.effects.apply_measurements`).

An effect is configured in two ways that combine: keyword values at construction
(``LinearDrag(c=0.1)``) and :meth:`Effect.setup` before each simulation, whose values override
the constructor's. Values are keyed by the bare parameter name (``"c"``) or the qualified one
(``"linear_drag.c"``, or ``"<label>.c"`` for an instance built with ``label=...``); every value must
be finite and inside the parameter's ``[low, high]``.

The simulators call :meth:`Effect.setup` themselves before every simulation, with the scene as
simulated and the values found in ``simulate(params=...)`` under the effect's :attr:`Effect.key`
(``{"linear_drag.c": 0.2}``), so an effect can be fitted like any body parameter. Two instances of
one effect need distinct labels (``LinearDrag(label="drag_a", bodies=["a"])``): the label is the
prefix of their parameter keys.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from physbench.errors import PhysbenchError, UnknownNameError, counted
from physbench.parameter import Parameter
from physbench.requirements import Requirements

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory


#: Scene features an effect can need (:attr:`Effect.scene_needs`).
SCENE_FEATURES = ("joints", "contacts")


class EffectError(PhysbenchError, ValueError):
    """A bad effect value or configuration; the message names the effect, the key and the value."""


def smooth_sign(v: np.ndarray, eps: float | np.ndarray) -> np.ndarray:
    """``v / sqrt(v² + eps²)``: sign(v) for ``|v| >> eps``, linear (slope ``1/eps``) near 0."""
    return v / np.sqrt(v * v + eps * eps)


def smooth_unit(v: np.ndarray, eps: float) -> np.ndarray:
    """Rows of ``v`` ``(N, 2)`` scaled to unit length, regularised like :func:`smooth_sign`."""
    norm = np.sqrt((v * v).sum(axis=1, keepdims=True) + eps * eps)
    return v / norm


def substep(scene: Scene) -> float:
    """The integration step the built-in simulators use for ``scene`` (s)."""
    return scene.dt / scene.substeps


class Effect(Requirements):
    """Base class of every effect (plugin contract).

    Subclasses set the class attributes :attr:`name` and :attr:`params` (each
    :class:`~physbench.unknowns.Parameter` with a ``default`` inside its range) and the traits they
    need, and override :meth:`forces`, :meth:`restitution` or :meth:`measure` accordingly;
    :meth:`configure` is the place to precompute from the scene. Constructor keywords:
    ``bodies`` (names of the bodies it acts on; default all), ``label`` (the key prefix of its
    parameters; default :attr:`name`) and parameter values.
    """

    #: Registered name (unique among effects).
    name: ClassVar[str] = ""
    #: The parameters the effect adds to the model, without owner (instances qualify them).
    params: ClassVar[tuple[Parameter, ...]] = ()
    #: Whether :meth:`forces` can be non-zero; ``False`` (contact laws, measurement effects) keeps
    #: the stepping loop from calling it every substep.
    applies_forces: ClassVar[bool] = True
    #: Whether :meth:`restitution` replaces the scene's restitution when a contact starts.
    changes_contacts: ClassVar[bool] = False
    #: Whether :meth:`measure` changes the reported trajectory.
    measures: ClassVar[bool] = False
    #: What a scene must contain for the effect to act (:data:`SCENE_FEATURES`): ``"joints"`` for
    #: an effect on pivot joints (it raises on a scene without), ``"contacts"`` for one that acts
    #: when bodies collide (implied by :attr:`changes_contacts`). The conformance kit probes the
    #: effect on a scene that has them.
    scene_needs: ClassVar[tuple[str, ...]] = ()

    def __init__(
        self, *, bodies: Iterable[str] | None = None, label: str | None = None, **values: float
    ) -> None:
        if isinstance(bodies, str):
            raise EffectError(
                f"{self.name}: bodies must be a list of body names, not the string {bodies!r}"
            )
        if label is not None and (not isinstance(label, str) or not label or "." in label):
            raise EffectError(
                f"{self.name}: label = {label!r}: expected a non-empty name without '.'"
            )
        self.bodies = None if bodies is None else tuple(bodies)
        #: Prefix of this instance's parameter keys (``"<key>.<param>"``): the label, else the name.
        self.key: str = label or self.name
        missing = [p.name for p in self.params if p.default is None]
        if missing:
            raise EffectError(
                f"effect {self.name!r} declares parameters {missing} without a default"
            )
        #: This instance's parameters: the class's, with any ranges widened (:meth:`widen`).
        self.declared: dict[str, Parameter] = {p.name: p for p in self.params}
        self.values: dict[str, float] = {p.name: float(p.default or 0.0) for p in self.params}
        self.values.update(self._checked(values))
        self.scene: Scene | None = None
        self.mask = np.zeros(0, dtype=bool)
        self.sel: slice | np.ndarray = slice(None)
        self.masses = np.zeros(0)
        self.inertias = np.zeros(0)

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:g}" for k, v in self.values.items())
        sel = f", bodies={list(self.bodies)!r}" if self.bodies is not None else ""
        lab = f", label={self.key!r}" if self.key != self.name else ""
        return f"{type(self).__name__}({vals}{sel}{lab})"

    def qualified(self) -> dict[str, float]:
        """The current values keyed ``"<key>.<param>"``, as :meth:`setup` and ``simulate`` take
        them."""
        return {f"{self.key}.{k}": v for k, v in self.values.items()}

    # ----------------------------------------------------------------- configuration

    @classmethod
    def option_names(cls) -> tuple[str, ...]:
        """Called by the component factory when a user's options are refused: the options this
        effect takes, ``bodies``, ``label`` and its parameters (each also as ``<key>.<param>``)."""
        return ("bodies", "label", *(p.name for p in cls.params))

    @classmethod
    def neutral(cls) -> dict[str, float] | None:
        """Parameter values at which the effect changes nothing (the simulated and measured
        trajectory equal those without it), or ``None`` when there are none (a contact law
        replaces the scene's restitution at every value). Default: the parameters' defaults; the
        conformance kit checks it."""
        return {p.name: float(p.default) for p in cls.params if p.default is not None}

    def parameters(self) -> tuple[Parameter, ...]:
        """This instance's parameters, qualified by its :attr:`key` (``linear_drag.c``)."""
        return tuple(p.owned_by(self.key) for p in self.declared.values())

    def widen(self, name: str, low: float, high: float) -> None:
        """Called by discovery when a fit reaches the end of an extensible parameter's range:
        accept values in ``[low, high]`` (a range containing the current one) from now on."""
        p = self.declared.get(name) or self.param(name)
        if not p.extensible:
            raise EffectError(
                f"{self.key}.{name}: its range {p.describe()} is a physical limit, not widened"
            )
        if not (math.isfinite(low) and math.isfinite(high) and low <= p.low and high >= p.high):
            raise EffectError(
                f"{self.key}.{name}: new range [{low!r}, {high!r}] must be finite and contain "
                f"{p.describe()}"
            )
        self.declared[name] = replace(p, low=float(low), high=float(high))

    @classmethod
    def param(cls, name: str) -> Parameter:
        for p in cls.params:
            if p.name == name:
                return p
        raise UnknownNameError(
            f"parameter of effect {cls.name!r}", name, [p.name for p in cls.params]
        )

    def _checked(self, values: Mapping[str, float]) -> dict[str, float]:
        out: dict[str, float] = {}
        for key, value in values.items():
            name = key.removeprefix(f"{self.key}.").removeprefix(f"{self.name}.")
            p = self.declared.get(name) or self.param(name)
            if isinstance(value, bool) or not isinstance(
                value, int | float | np.floating | np.integer
            ):
                raise EffectError(
                    f"{self.key}.{name} = {value!r}: must be a number in {p.describe()}"
                )
            v = float(value)
            if not math.isfinite(v) or not p.low <= v <= p.high:
                raise EffectError(f"{self.key}.{name} = {v!r}: must lie in {p.describe()}")
            out[name] = v
        return out

    def setup(self, scene: Scene, values: Mapping[str, float]) -> None:
        """Called by the simulator once before each simulation, with the scene as simulated (body
        parameters applied) and the effect's parameter values (missing ones keep their current
        value)."""
        self.values.update(self._checked(values))
        names = scene.body_names
        if self.bodies is None:
            self.mask = np.ones(len(names), dtype=bool)
        else:
            for b in self.bodies:
                if b not in names:
                    raise UnknownNameError(
                        f"body of scene {scene.name!r} (effect {self.name})", b, names
                    )
            self.mask = np.array([n in self.bodies for n in names], dtype=bool)
        # Index of the selected bodies: a plain slice when all are selected (cheaper every substep).
        self.sel = slice(None) if self.mask.all() else np.nonzero(self.mask)[0]
        self.masses = np.array([b.mass for b in scene.bodies], dtype=float)
        self.inertias = np.array([b.inertia() for b in scene.bodies], dtype=float)
        self.scene = scene
        self.configure(scene)

    def configure(self, scene: Scene) -> None:
        """Hook for subclasses: precompute what :meth:`forces` needs from ``scene``."""

    def _require_setup(self, states: np.ndarray) -> None:
        if self.scene is None or len(self.mask) != states.shape[0]:
            raise EffectError(
                f"effect {self.name!r} was not set up for this scene "
                f"({counted(states.shape[0], 'body')}): "
                "call setup(scene, values) before simulating"
            )

    # ----------------------------------------------------------------- forces

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Called every substep (when :attr:`applies_forces`) with ``states`` ``(N, 6)`` (x, y,
        angle, vx, vy, omega of the centres of mass). Returns forces ``(N, 2)`` in N and torques
        ``(N,)`` in N·m. Default: none."""
        return self.zeros(states.shape[0])

    def restitution(self, normal_speed: float, a: int, b: int | None) -> float | None:
        """Called by the engine (when :attr:`changes_contacts`) once when a contact starts between
        bodies ``a`` and ``b`` (indices into ``scene.bodies``, ``b`` ``None`` for static geometry)
        with the approach speed along the normal (m/s, >= 0). Returns the coefficient of
        restitution for that contact, or ``None`` to keep the scene's. Default: ``None``."""
        return None

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation (when :attr:`measures`), before the trajectory is
        compared with data: the trajectory as the sensor would have reported it. Default: as is."""
        return traj

    @staticmethod
    def zeros(n: int) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros((n, 2)), np.zeros(n)
