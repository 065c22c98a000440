"""The base of the built-in black-box optimisers: ``propose`` = *tell* the loss of the parameters
just simulated, then *ask* for the next point.

Every built-in black-box optimiser works on the unit cube (each unknown's range mapped to [0, 1]
by :meth:`~physbench.unknowns.ParamSpace.to_unit`); the first point told is the initial guess.
Importing an estimator module is cheap: the optimiser library is imported in :meth:`start`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator

if TYPE_CHECKING:
    from physbench.estimators.base import Step, Task
    from physbench.unknowns import Params, ParamSpace


class AskTellEstimator(CorrectionEstimator):
    """Base of the gradient-free estimators: ``propose`` = tell the loss, then ask for a new point.

    Subclasses set ``name``, store their options in ``self.options`` (recorded in the history) and
    implement :meth:`_begin` (set up the optimiser; the first point told will be ``self.x0``),
    :meth:`_tell` and :meth:`_ask` (a unit-cube vector).
    """

    name: ClassVar[str] = ""
    per_object: ClassVar[bool] = False

    def __init__(self) -> None:
        self.options: dict[str, Any] = {}
        self.space: ParamSpace | None = None
        self.x0 = np.zeros(0)

    def __repr__(self) -> str:
        opts = ", ".join(f"{k}={v!r}" for k, v in self.options.items())
        return f"{type(self).__name__}({opts})"

    def start(self, task: Task, *, seed: int) -> None:
        """Called once per run, before the first simulation: set up a fresh optimiser."""
        self.space = task.space
        self.x0 = task.space.to_unit(task.initial)
        self._begin(task, int(seed))

    def propose(self, step: Step) -> Params:
        """Called after every simulation: tell ``step.loss`` for the point last asked (the initial
        guess the first time), ask for the next one."""
        if self.space is None:
            raise PhysbenchError(f"estimator {self.name!r}: propose() called before start()")
        self._tell(float(step.loss))
        return self.space.from_unit(np.clip(np.asarray(self._ask(), dtype=float), 0.0, 1.0))

    def _begin(self, task: Task, seed: int) -> None:
        raise NotImplementedError

    def _tell(self, loss: float) -> None:
        raise NotImplementedError

    def _ask(self) -> np.ndarray:
        raise NotImplementedError
