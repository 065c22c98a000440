"""``tpe``: hyperopt's Tree of Parzen Estimators, the paper's baseline, driven ask/tell-style.

hyperopt's ``fmin`` owns the loop; calling it once per iteration would rebuild everything each
time. Instead one ``Trials`` object lives for the whole run: each told point is inserted as a
finished trial and ``tpe.suggest`` is asked for the next one directly.

``startup``: trials told (the initial guess included) before TPE models anything. hyperopt's
default is 20, so with the paper's 11 iterations its "TPE" was random search throughout; ours
defaults to :data:`DEFAULT_STARTUP` for small budgets. ``design``: where the start-up trials fall,
hyperopt's own uniform draws (``"random"``, the default) or a Latin hypercube (``"lhs"``,
:mod:`physbench.estimators.design`).

Why these defaults: at 11 simulations no start-up setting measurably changed TPE's error. Over 400
held-out seeds of the eight Table 1 rows (benchmarks/small_budget.toml), a Latin-hypercube start
(``startup`` 5, 7 or 20) had 0.96-1.02 x the error of the default (paired bootstrap 95 % intervals
all include 1), and the default had 0.82 x random search's error.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.estimators.ask_tell import AskTellEstimator
from physbench.estimators.design import DESIGNS, startup_design
from physbench.estimators.options import choice_option, float_option, int_option
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Task

DEFAULT_STARTUP = 5
#: hyperopt's own default, for comparison runs (``--option startup=20``).
HYPEROPT_STARTUP = 20


class TPE(AskTellEstimator):
    """hyperopt TPE over the unit cube. Options: ``startup`` (start-up trials before TPE models,
    the initial guess included; default :data:`DEFAULT_STARTUP`), ``design`` (``"random"``,
    default, or ``"lhs"``), ``candidates`` (EI candidates per ask, 24), ``gamma`` (share of trials
    modelled as good, 0.25)."""

    name: ClassVar[str] = "tpe"

    def __init__(
        self,
        startup: int = DEFAULT_STARTUP,
        design: str = "random",
        candidates: int = 24,
        gamma: float = 0.25,
    ) -> None:
        super().__init__()
        self.options = {
            "startup": int_option(self.name, "startup", startup, low=0),
            "design": choice_option(self.name, "design", design, DESIGNS),
            "candidates": int_option(self.name, "candidates", candidates, low=1),
            "gamma": float_option(self.name, "gamma", gamma, low=0.0, high=1.0),
        }

    def _begin(self, task: Task, seed: int) -> None:
        from hyperopt import Domain, Trials, hp

        self._keys = task.space.keys
        self._domain = Domain(lambda _: 0.0, {k: hp.uniform(k, 0.0, 1.0) for k in self._keys})
        self._trials = Trials()
        self._rng = np.random.default_rng(seed)
        # The initial guess is trial 0; the design fills the start-up trials the budget allows
        # after it. "random" leaves them to hyperopt's own draws.
        n = min(self.options["startup"], task.iterations) - 1
        kind = self.options["design"]
        self._design = startup_design(kind, n if kind == "lhs" else 0, len(self._keys), self._rng)
        self._pending: dict[str, Any] = {
            k: float(v) for k, v in zip(self._keys, self.x0, strict=True)
        }

    def _tell(self, loss: float) -> None:
        from hyperopt import JOB_STATE_DONE, STATUS_OK

        tid = len(self._trials.trials)
        misc = {
            "tid": tid,
            "cmd": self._domain.cmd,
            "workdir": None,
            "idxs": {k: [tid] for k in self._keys},
            "vals": {k: [self._pending[k]] for k in self._keys},
        }
        (doc,) = self._trials.new_trial_docs(
            [tid], [None], [{"loss": loss, "status": STATUS_OK}], [misc]
        )
        doc["state"] = JOB_STATE_DONE
        self._trials.insert_trial_docs([doc])
        self._trials.refresh()

    def _ask(self) -> np.ndarray:
        from hyperopt import tpe

        new_id = len(self._trials.trials)
        if 1 <= new_id <= len(self._design):
            x = self._design[new_id - 1]
            self._pending = {k: float(v) for k, v in zip(self._keys, x, strict=True)}
            return x.copy()
        (doc,) = tpe.suggest(
            [new_id],
            self._domain,
            self._trials,
            int(self._rng.integers(2**31 - 1)),
            n_startup_jobs=self.options["startup"],
            n_EI_candidates=self.options["candidates"],
            gamma=self.options["gamma"],
            verbose=False,
        )
        vals = doc["misc"]["vals"]
        self._pending = {k: float(vals[k][0]) for k in self._keys}
        return np.array([self._pending[k] for k in self._keys])


@hookimpl
def register_estimators() -> list[type]:
    return [TPE]
