"""``random``: uniform random search, the baseline every other estimator must beat."""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

import numpy as np

from physbench.estimators.ask_tell import AskTellEstimator
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Task


class RandomSearch(AskTellEstimator):
    """Proposes a uniform draw inside the ranges every iteration, ignoring the loss."""

    name: ClassVar[str] = "random"

    def _begin(self, task: Task, seed: int) -> None:
        self._rng = np.random.default_rng(seed)

    def _tell(self, loss: float) -> None:
        pass

    def _ask(self) -> np.ndarray:
        assert self.space is not None
        return self._rng.random(len(self.space))


@hookimpl
def register_estimators() -> list[type]:
    return [RandomSearch]
