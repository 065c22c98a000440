"""``nevergrad``: any optimiser of nevergrad's registry by name (``-o optimizer=NGOpt``).

The optimiser works on the unit cube with the run's iterations as its budget, so budget-aware
ones (``NGOpt`` picks its algorithm from budget and dimension) plan for the real run. The initial
guess is handed over with ``suggest``, so it is the first point asked and told; the parametrization
draws from the run's seed. ``optimizer=CMA`` is nevergrad's default CMA-ES; the ``cmaes``
estimator is the same library's ``ParametrizedCMA`` with its step size and population as options.

Once the budget is told, the last proposal (made but never simulated) is the optimiser's
recommendation, and the optimiser is dropped: nevergrad runs its scipy-based optimisers (COBYLA,
NelderMead, ..., which ``NGOpt`` picks for small budgets) in a thread that it stops when the
optimiser is deleted.
"""

from __future__ import annotations

import difflib
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.ask_tell import AskTellEstimator
from physbench.estimators.options import EstimatorOptionError
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Task

DEFAULT_OPTIMIZER = "NGOpt"


def _registry() -> Any:
    import nevergrad as ng

    return ng.optimizers.registry


def check_optimizer(name: object) -> str:
    """``name`` if nevergrad's registry has it, else :class:`EstimatorOptionError` listing the
    closest names (the registry is case-sensitive: ``cma`` suggests ``CMA``)."""
    registry = _registry()
    if isinstance(name, str) and name in registry:
        return name
    by_lower = {k.lower(): k for k in registry}
    close = difflib.get_close_matches(str(name).lower(), by_lower, n=5, cutoff=0.6)
    hint = ", ".join(by_lower[c] for c in close) or f"{DEFAULT_OPTIMIZER}, CMA, TwoPointsDE, PSO"
    raise EstimatorOptionError(
        f"nevergrad: optimizer = {name!r}: not in nevergrad's registry ({len(registry)} "
        f"optimizers); close: {hint} (all: python -c 'import nevergrad as ng; "
        "print(sorted(ng.optimizers.registry))')"
    )


class NevergradOptimizer(AskTellEstimator):
    """Any optimiser of ``nevergrad.optimizers.registry``. Option: ``optimizer`` (its registry
    name, default :data:`DEFAULT_OPTIMIZER`)."""

    name: ClassVar[str] = "nevergrad"

    def __init__(self, optimizer: str = DEFAULT_OPTIMIZER) -> None:
        super().__init__()
        self.options = {"optimizer": check_optimizer(optimizer)}
        self._opt: Any = None

    def _begin(self, task: Task, seed: int) -> None:
        import nevergrad as ng

        self._budget = int(task.iterations)
        self._told = 0
        param = ng.p.Array(init=self.x0.copy(), lower=0.0, upper=1.0)
        param.random_state = np.random.RandomState(seed % 2**32)
        algo = _registry()[self.options["optimizer"]]
        self._opt = algo(parametrization=param, budget=self._budget, num_workers=1)
        self._opt.suggest(self.x0.copy())
        self._pending: Any = self._opt.ask()

    def _tell(self, loss: float) -> None:
        if self._opt is None:
            raise PhysbenchError(
                f"estimator {self.name!r}: propose() called after the run's {self._budget} "
                "iterations (its budget); start() begins a new run"
            )
        self._opt.tell(self._pending, loss)
        self._told += 1

    def _ask(self) -> np.ndarray:
        if self._told < self._budget:
            self._pending = self._opt.ask()
            return np.asarray(self._pending.value, dtype=float)
        best = np.asarray(self._opt.provide_recommendation().value, dtype=float)
        self._opt = self._pending = None
        return best


@hookimpl
def register_estimators() -> list[type]:
    return [NevergradOptimizer]
