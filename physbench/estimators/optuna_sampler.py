"""``optuna``: an Optuna study driven through its ask/tell interface, TPE sampler by default.

The initial guess is enqueued, so it is the study's first trial. ``startup`` counts trials (the
initial guess included) a model-based sampler draws at random before modelling; Optuna's own
default is 10, so at 11 iterations its TPE is almost pure random search. ``sampler="cmaes"`` needs
the ``cmaes`` package (``pip install cmaes``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.ask_tell import AskTellEstimator
from physbench.estimators.options import choice_option, int_option
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Task

SAMPLERS = ("tpe", "cmaes", "random", "qmc")
#: Random trials before a model-based sampler models (the initial guess included).
DEFAULT_STARTUP = 5
#: Optuna's own TPE default, for comparison runs (``--option startup=10``).
OPTUNA_STARTUP = 10


class Optuna(AskTellEstimator):
    """Options: ``sampler`` (tpe, cmaes, random, qmc; default tpe) and ``startup`` (random trials
    before tpe/cmaes model, default :data:`DEFAULT_STARTUP`)."""

    name: ClassVar[str] = "optuna"

    def __init__(self, sampler: str = "tpe", startup: int = DEFAULT_STARTUP) -> None:
        super().__init__()
        self.options = {
            "sampler": choice_option(self.name, "sampler", sampler, SAMPLERS),
            "startup": int_option(self.name, "startup", startup, low=0),
        }

    def _sampler(self, seed: int) -> Any:
        import optuna

        kind, startup = self.options["sampler"], self.options["startup"]
        if kind == "tpe":
            return optuna.samplers.TPESampler(n_startup_trials=startup, seed=seed)
        if kind == "random":
            return optuna.samplers.RandomSampler(seed=seed)
        if kind == "qmc":
            import warnings

            with warnings.catch_warnings():
                warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
                return optuna.samplers.QMCSampler(seed=seed, warn_independent_sampling=False)
        try:
            import cmaes  # noqa: F401  (optuna imports it lazily and fails late otherwise)
        except ImportError:
            raise PhysbenchError(
                "optuna: sampler = 'cmaes' needs the 'cmaes' package: pip install cmaes"
            ) from None
        return optuna.samplers.CmaEsSampler(
            n_startup_trials=max(startup, 1),
            seed=seed,
            independent_sampler=optuna.samplers.RandomSampler(seed=seed),
            warn_independent_sampling=False,
        )

    def _begin(self, task: Task, seed: int) -> None:
        import optuna
        from optuna.distributions import FloatDistribution

        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self._keys = task.space.keys
        self._dists = {k: FloatDistribution(0.0, 1.0) for k in self._keys}
        self._study = optuna.create_study(direction="minimize", sampler=self._sampler(seed % 2**32))
        self._study.enqueue_trial({k: float(v) for k, v in zip(self._keys, self.x0, strict=True)})
        self._pending = self._study.ask(self._dists)

    def _tell(self, loss: float) -> None:
        self._study.tell(self._pending, loss)

    def _ask(self) -> np.ndarray:
        self._pending = self._study.ask(self._dists)
        return np.array([self._pending.params[k] for k in self._keys])


@hookimpl
def register_estimators() -> list[type]:
    return [Optuna]
