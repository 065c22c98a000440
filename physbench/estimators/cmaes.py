"""``cmaes``: CMA-ES through nevergrad, started at the initial guess.

The search distribution is centred on the initial guess with initial step ``sigma`` in unit-cube
coordinates (a fraction of each range); nevergrad keeps candidates inside the ranges by bouncing
them off the bounds. The initial guess is handed over with ``suggest``, so it is the first point
asked and told.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.estimators.ask_tell import AskTellEstimator
from physbench.estimators.options import float_option, int_option
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Task


class CMAES(AskTellEstimator):
    """nevergrad ``ParametrizedCMA``. Options: ``sigma`` (initial step as a fraction of each range,
    default 0.3), ``popsize`` (default: CMA's ``4 + 3 ln d``), ``elitist`` (default False)."""

    name: ClassVar[str] = "cmaes"

    def __init__(
        self, sigma: float = 0.3, popsize: int | None = None, elitist: bool = False
    ) -> None:
        super().__init__()
        if not isinstance(elitist, bool):
            from physbench.estimators.options import EstimatorOptionError

            raise EstimatorOptionError(
                f"{self.name}: elitist = {elitist!r}: expected true or false"
            )
        self.options = {
            "sigma": float_option(self.name, "sigma", sigma, low=0.0, high=1.0),
            "popsize": int_option(self.name, "popsize", popsize, low=2, allow_none=True),
            "elitist": elitist,
        }

    def _begin(self, task: Task, seed: int) -> None:
        import cma  # noqa: F401  (nevergrad imports pycma at the first ask; pay that here, in start)
        import nevergrad as ng

        self._dim = len(self.x0)
        # nevergrad hands 1-D problems to fcmaes (an extra package); a second, ignored coordinate
        # keeps pycma in charge.
        x0 = np.append(self.x0, 0.5) if self._dim == 1 else self.x0.copy()
        # nevergrad starts CMA on a fully bounded parametrization with 0.3 x (0.15 x from 18
        # dimensions) the parametrization's sigma; undo that so ``sigma`` is the real first step.
        shrink = 0.3 if len(x0) < 18 else 0.15
        param = ng.p.Array(init=x0, lower=0.0, upper=1.0).set_mutation(
            sigma=self.options["sigma"] / shrink
        )
        param.random_state = np.random.RandomState(seed % 2**32)
        algo = ng.optimizers.ParametrizedCMA(
            popsize=self.options["popsize"], elitist=self.options["elitist"]
        )
        self._opt = algo(parametrization=param, budget=None, num_workers=1)
        self._opt.suggest(x0)
        self._pending: Any = self._opt.ask()

    def _tell(self, loss: float) -> None:
        self._opt.tell(self._pending, loss)

    def _ask(self) -> np.ndarray:
        self._pending = self._opt.ask()
        return np.asarray(self._pending.value, dtype=float)[: self._dim]


@hookimpl
def register_estimators() -> list[type]:
    return [CMAES]
