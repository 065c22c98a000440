"""scipy.optimize's Nelder-Mead and Powell as a physbench correction estimator (``scipy``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Step, Task
    from physbench.unknowns import Params, ParamSpace

METHODS = ("nelder-mead", "powell")


class _Unseen(Exception):
    """Raised inside the replayed objective at the first point without a recorded loss."""

    def __init__(self, x: np.ndarray) -> None:
        self.x = x


class ScipyMinimize(CorrectionEstimator):
    """A deterministic scipy minimiser over the unit cube, turned ask/tell by replaying it
    against the losses recorded so far (see README). Restarts from a seeded random point when it
    converges before the budget is spent."""

    name: ClassVar[str] = "scipy"

    def __init__(self, method: str = "nelder-mead", step: float = 0.2, xatol: float = 1e-3) -> None:
        if method not in METHODS:
            raise PhysbenchError(
                f"scipy: method = {method!r}: expected one of {', '.join(METHODS)}"
            )
        for key, value, hi in (("step", step, 1.0), ("xatol", xatol, 1.0)):
            if isinstance(value, bool) or not isinstance(value, int | float) or not 0 < value <= hi:
                raise PhysbenchError(f"scipy: {key} = {value!r}: expected a number in (0, {hi:g}]")
        self.options: dict[str, Any] = {
            "method": method,
            "step": float(step),
            "xatol": float(xatol),
        }
        self.space: ParamSpace | None = None

    def start(self, task: Task, *, seed: int) -> None:
        """Called once per run: forget everything, begin at the initial guess."""
        self.space = task.space
        self._rng = np.random.default_rng(seed)
        self._seen: dict[bytes, float] = {}
        self._x0 = np.clip(task.space.to_unit(task.initial), 0.0, 1.0)
        self._pending = self._x0.copy()
        self.restarts = 0

    def propose(self, step: Step) -> Params:
        """Called after every simulation: record the loss of the point asked last, ask the next."""
        if self.space is None:
            raise PhysbenchError("scipy: propose() called before start()")
        self._seen[self._pending.tobytes()] = float(step.loss)
        x = self._replay()
        while x is None:  # converged: restart from a fresh point (its loss is not known yet)
            self.restarts += 1
            self._x0 = self._rng.random(len(self.space))
            x = self._replay()
        self._pending = x
        return self.space.from_unit(x)

    def _objective(self, x: np.ndarray) -> float:
        x = np.asarray(x, dtype=float)
        loss = self._seen.get(x.tobytes())
        if loss is None:
            raise _Unseen(x.copy())
        return loss

    def _replay(self) -> np.ndarray | None:
        from scipy.optimize import minimize

        d = len(self._x0)
        bounds = [(0.0, 1.0)] * d
        if self.options["method"] == "nelder-mead":
            # Simplex edges point away from the nearer bound so no vertex is clipped onto another.
            sign = np.where(self._x0 > 0.5, -1.0, 1.0)
            simplex = np.vstack([self._x0, self._x0 + np.diag(sign * self.options["step"])])
            kwargs: dict[str, Any] = {
                "method": "Nelder-Mead",
                "options": {
                    "initial_simplex": simplex,
                    "xatol": self.options["xatol"],
                    "fatol": 0.0,
                    "maxfev": 10**9,
                },
            }
        else:
            kwargs = {
                "method": "Powell",
                "options": {"xtol": self.options["xatol"], "ftol": 1e-12, "maxfev": 10**9},
            }
        try:
            minimize(self._objective, self._x0, bounds=bounds, **kwargs)
        except _Unseen as need:
            return np.clip(need.x, 0.0, 1.0)
        return None


@hookimpl
def register_estimators() -> list[type]:
    return [ScipyMinimize]
