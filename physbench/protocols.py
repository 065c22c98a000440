"""The component contracts: Simulator, Renderer, CorrectionEstimator, Effect.

Components are plain classes registered through the ``physbench`` entry-point group (see
:mod:`physbench.hookspecs`). The framework instantiates them with keyword options
(``Cls(**options)``) and calls the methods below; docstrings say when.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from physbench.params import Params, ParamSpace
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory


@dataclass(frozen=True)
class EffectParam:
    """A parameter an :class:`Effect` adds to the model."""

    name: str
    default: float
    low: float
    high: float
    unit: str = ""
    doc: str = ""


@runtime_checkable
class Effect(Protocol):
    """A model extension (drag, rolling resistance, joint damping, ...) that every engine applies
    the same way: as extra forces and torques on the bodies at every substep.

    Optional members the framework uses when present:

    ``key: str``
        prefix of the effect's parameter keys (default ``name``); two instances of one effect in a
        simulation need distinct keys.
    ``applies_forces: bool``
        ``False`` when :meth:`forces` is always zero; the stepping loop then skips it.
    ``restitution(normal_speed, a, b) -> float | None``
        called by the engine once when a contact starts between bodies ``a`` and ``b`` (indices
        into ``scene.bodies``, ``b`` ``None`` for static geometry) with the approach speed along
        the normal (m/s, >= 0); returns the coefficient of restitution for that contact, or
        ``None`` to keep the scene's.
    ``measure(traj) -> Trajectory``
        a measurement effect: called after every simulation, before the trajectory is compared
        with data (:func:`physbench.effects.apply_measurements`).
    """

    name: ClassVar[str]
    params: ClassVar[tuple[EffectParam, ...]]

    def setup(self, scene: Scene, values: Mapping[str, float]) -> None:
        """Called by the simulator once before each simulation, with the scene as simulated (body
        parameters applied) and the effect's parameter values given to ``simulate`` as
        ``"<key>.<param>"`` (bare names; missing ones keep their current value)."""

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Called every substep with ``states`` ``(N, 6)`` (x, y, angle, vx, vy, omega of the
        centres of mass). Returns forces ``(N, 2)`` in N and torques ``(N,)`` in N·m."""
        ...


@runtime_checkable
class Simulator(Protocol):
    """A physics engine that builds any :class:`~physbench.scene.Scene`."""

    name: ClassVar[str]

    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        """Called once per iteration: build the scene with ``params`` applied, step it for
        ``scene.frames`` frames and return the trajectory. Raises
        :class:`~physbench.errors.SimulationError` when the simulation explodes."""
        ...


@runtime_checkable
class Renderer(Protocol):
    """Turns a trajectory into frames ``(T, C, H, W)`` float32 in [0, 1]."""

    name: ClassVar[str]

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Called after every simulation. ``focus`` names the marked object (for renderers
        that mark one); ``out`` is an optional buffer of the right shape to render into."""
        ...


@dataclass
class Task:
    """What an estimator learns once per run, in :meth:`CorrectionEstimator.start`."""

    scene: Scene
    space: ParamSpace
    observation: np.ndarray  # (T, C, H, W) observed frames
    initial: Params  # the first guess, simulated in iteration 0
    renderer: Renderer | None = None
    meta: dict[str, object] = field(default_factory=dict)


@dataclass
class Step:
    """What an estimator sees after each simulation, in :meth:`CorrectionEstimator.propose`."""

    iteration: int
    params: Params  # the parameters just simulated
    frames: np.ndarray  # (T, C, H, W) simulated frames for ``params``
    loss: float  # image-space MSE between ``frames`` and the observation
    trajectory: Trajectory | None = None


@runtime_checkable
class CorrectionEstimator(Protocol):
    """Proposes the next parameters from the observation and the latest simulation.

    One iteration of :func:`physbench.loop.refine` is exactly one simulation and one
    :meth:`propose` call, whatever the estimator, so iteration counts are a fair cost.
    """

    name: ClassVar[str]
    #: True when the estimator corrects one marked object at a time (e.g. a learned model).
    per_object: ClassVar[bool]

    def start(self, task: Task, *, seed: int) -> None:
        """Called once per run, before the first simulation. Same seed, same task -> same run."""

    def propose(self, step: Step) -> Params:
        """Called after every simulation; returns parameters inside ``task.space``'s ranges."""
        ...
