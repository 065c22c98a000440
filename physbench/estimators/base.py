"""The CorrectionEstimator contract and what the loop hands an estimator: :class:`Task` once per
run, :class:`Step` after every simulation.

One iteration of :func:`physbench.loop.refine` is exactly one simulation and one
:meth:`CorrectionEstimator.propose` call, whatever the estimator, so iteration counts are a fair
cost. ``physbench.testing.check_estimator`` runs the conformance kit.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

from physbench.requirements import Requirements

if TYPE_CHECKING:
    import numpy as np

    from physbench.posterior.samples import Posterior
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory
    from physbench.unknowns import Params, ParamSpace

#: The estimator a run uses unless told otherwise.
DEFAULT_ESTIMATOR = "tpe"


@dataclass
class Task:
    """What an estimator learns once per run, in :meth:`CorrectionEstimator.start`.

    ``observation`` holds the observed frames ``(T, C, H, W)``; ``marked_observation`` the
    observed frames with one body marked (``focus=body``), per unknown body, for estimators that
    are :attr:`~CorrectionEstimator.per_object` (empty otherwise). ``renderer`` is the model's
    renderer (``None`` when the loss is not on images, e.g. a discovery fit on tracks),
    ``iterations`` the run's budget (simulations = ``propose`` calls).
    """

    scene: Scene
    space: ParamSpace
    observation: np.ndarray
    initial: Params
    renderer: Renderer | None
    iterations: int
    marked_observation: Mapping[str, np.ndarray] = field(default_factory=dict)
    #: The standard deviation of the observation's Gaussian pixel noise when the observation model
    #: states it (a simulated observation), ``None`` when unknown (a file, a camera).
    noise: float | None = None


@dataclass
class Step:
    """What an estimator sees after each simulation, in :meth:`CorrectionEstimator.propose`.

    ``frames`` are the simulated frames for ``params`` and ``loss`` their image MSE against the
    observation; ``trajectory`` is ``None`` when the simulation failed (``frames`` are then zeros
    and ``loss`` the worst possible). ``marked`` holds the simulated frames rendered once per
    unknown body with that body marked, for a ``per_object`` estimator (empty otherwise).
    """

    iteration: int
    params: Params
    frames: np.ndarray
    loss: float
    trajectory: Trajectory | None = None
    marked: Mapping[str, np.ndarray] = field(default_factory=dict)


class CorrectionEstimator(Requirements):
    """Base class of every correction estimator (plugin contract).

    The framework builds it with keyword options (``Cls(**options)``; an unknown option must raise
    naming it), calls :meth:`start` once per run and :meth:`propose` after every simulation.
    """

    #: Registered name (unique among estimators).
    name: ClassVar[str] = ""
    #: Whether the estimator corrects one marked object at a time (e.g. a learned model): the loop
    #: then renders every unknown body marked, for the observation and for each simulation.
    per_object: ClassVar[bool] = False
    #: The options the run used, as recorded in its history (set in ``__init__``; default none).
    options: Mapping[str, Any] = MappingProxyType({})

    def start(self, task: Task, *, seed: int) -> None:
        """Called once per run, before the first simulation. Same seed, same task -> same run:
        derive all randomness from ``seed``."""
        raise NotImplementedError(f"{type(self).__name__} must implement start()")

    def propose(self, step: Step) -> Params:
        """Called after every simulation: the next parameters, one value per key of
        ``task.space`` inside its range. Raise :class:`~physbench.errors.PhysbenchError` saying
        that ``start()`` must come first when called before it."""
        raise NotImplementedError(f"{type(self).__name__} must implement propose()")

    def posterior(self) -> Posterior | None:
        """Called once after the last :meth:`propose`: how sure the estimator is, as a
        :class:`~physbench.posterior.samples.Posterior` over ``task.space``. Default ``None``: the
        estimator gives a point estimate only."""
        return None
