"""Shared machinery of the built-in effects: parameter handling, body/joint selection, smoothing.

An effect is configured in two ways that combine: keyword values at construction
(``LinearDrag(c=0.1)``) and :meth:`EffectBase.setup` before each simulation, whose values override
the constructor's. Values are keyed by the bare parameter name (``"c"``) or the qualified one
(``"linear_drag.c"``, or ``"<label>.c"`` for an instance built with ``label=...``); every value must
be finite and inside the parameter's ``[low, high]``.

The simulators call :meth:`EffectBase.setup` themselves before every simulation, with the scene as
simulated and the values found in ``simulate(params=...)`` under the effect's :attr:`~EffectBase.key`
(``{"linear_drag.c": 0.2}``), so an effect can be fitted like any body parameter. Two instances of
one effect need distinct labels (``LinearDrag(label="drag_a", bodies=["a"])``): the label is the
prefix of their parameter keys.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

import numpy as np

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.protocols import EffectParam

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory


class EffectError(PhysbenchError, ValueError):
    """A bad effect value or configuration; the message names the effect, the key and the value."""


@runtime_checkable
class MeasurementEffect(Protocol):
    """An effect on what the sensor reports rather than on the dynamics."""

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation, before the trajectory is compared with a recording:
        returns the trajectory as the sensor would have reported it."""
        ...


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


class EffectBase:
    """Base of the built-in effects. Subclasses set ``name``, ``params``, and implement
    :meth:`forces` (and :meth:`configure` when they precompute from the scene)."""

    name: ClassVar[str] = ""
    params: ClassVar[tuple[EffectParam, ...]] = ()
    #: False for effects whose :meth:`forces` are always zero (measurement and contact laws): the
    #: stepping loop then does not call them every substep.
    applies_forces: ClassVar[bool] = True

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
        self.values: dict[str, float] = {p.name: p.default for p in self.params}
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
        """The current values keyed ``"<key>.<param>"``, as :meth:`setup` and ``simulate`` take them."""
        return {f"{self.key}.{k}": v for k, v in self.values.items()}

    # ----------------------------------------------------------------- configuration

    @classmethod
    def param(cls, name: str) -> EffectParam:
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
            p = self.param(name)
            if isinstance(value, bool) or not isinstance(
                value, int | float | np.floating | np.integer
            ):
                raise EffectError(
                    f"{self.key}.{name} = {value!r}: must be a number in [{p.low:g}, {p.high:g}] {p.unit}"
                )
            v = float(value)
            if not math.isfinite(v) or not p.low <= v <= p.high:
                raise EffectError(
                    f"{self.key}.{name} = {v!r}: must lie in [{p.low:g}, {p.high:g}] {p.unit}".rstrip()
                )
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
                f"effect {self.name!r} was not set up for this scene ({states.shape[0]} bodies): "
                "call setup(scene, values) before simulating"
            )

    # ----------------------------------------------------------------- forces

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Called every substep with ``(N, 6)`` CoM states; returns ``(N, 2)`` forces and
        ``(N,)`` torques."""
        raise NotImplementedError

    @staticmethod
    def zeros(n: int) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros((n, 2)), np.zeros(n)


class JointEffectBase(EffectBase):
    """A torque law on the relative rotation rate of each selected pivot joint.

    A joint to the world gets ``tau = law(omega_a)`` on body ``a``; a joint between two bodies
    gets ``law(omega_a - omega_b)`` on ``a`` and the opposite on ``b``. ``joints`` selects joints
    by index into ``scene.joints`` (default: all). ``bodies`` is not used by joint effects.
    """

    def __init__(self, *, joints: Sequence[int] | None = None, **values: float) -> None:
        super().__init__(**values)
        self.joints = None if joints is None else tuple(int(j) for j in joints)
        self.ia = np.zeros(0, dtype=int)
        self.ib = np.zeros(0, dtype=int)  # -1: the world
        self.reduced_inertia = np.zeros(0)
        self._to_world = False

    def configure(self, scene: Scene) -> None:
        chosen = range(len(scene.joints)) if self.joints is None else self.joints
        if not scene.joints:
            raise EffectError(
                f"effect {self.name!r} needs a scene with joints; scene {scene.name!r} has none"
            )
        for j in chosen:
            if not 0 <= j < len(scene.joints):
                raise EffectError(
                    f"{self.name}: joint index {j} out of range; scene {scene.name!r} has joints 0..{len(scene.joints) - 1}"
                )
        sel = [scene.joints[j] for j in chosen]
        self.ia = np.array([scene.body_index(j.a) for j in sel], dtype=int)
        self.ib = np.array(
            [scene.body_index(j.b) if j.b is not None else -1 for j in sel], dtype=int
        )
        ia_inv = 1.0 / self.inertias[self.ia]
        ib_inv = np.where(self.ib >= 0, 1.0 / self.inertias[np.maximum(self.ib, 0)], 0.0)
        # Smallest inertia the torque acts on: the pivot only adds inertia, so this bounds the
        # fastest response of the relative rate and sets the regularisation floor.
        self.reduced_inertia = 1.0 / (ia_inv + ib_inv)
        self._to_world = bool(np.all(self.ib < 0) and len(set(self.ia.tolist())) == len(self.ia))

    def law(self, rate: np.ndarray) -> np.ndarray:
        """Torque on body ``a`` for relative rates ``rate`` (one per selected joint)."""
        raise NotImplementedError

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        n = states.shape[0]
        f, tau = self.zeros(n)
        omega = states[:, 5]
        if self._to_world:  # every selected joint ties a distinct body to the world
            tau[self.ia] = self.law(omega[self.ia])
            return f, tau
        rate = omega[self.ia] - np.where(self.ib >= 0, omega[np.maximum(self.ib, 0)], 0.0)
        torque = self.law(rate)
        np.add.at(tau, self.ia, torque)
        has_b = self.ib >= 0
        np.add.at(tau, self.ib[has_b], -torque[has_b])
        return f, tau
