"""Start-up designs: the points a black-box estimator evaluates before it models anything.

At the small budgets of the paper (11 simulations for two to four unknowns) *where* the first
points fall matters more than what any model does with them: independent uniform draws leave holes
and clumps, and a narrow basin in a hole is never found. A Latin hypercube puts exactly one point
in each of ``n`` equal slices of every unknown's range (scipy's ``qmc.LatinHypercube``).
benchmarks/small_budget.toml measures the effect; docs/estimators.md has the figures.
"""

from __future__ import annotations

import numpy as np

#: The designs an estimator's ``design`` option accepts.
DESIGNS = ("lhs", "random")


def startup_design(kind: str, n: int, dim: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` points of the unit cube ``[0, 1]^dim``: a Latin hypercube (``"lhs"``) or independent
    uniform draws (``"random"``); called once, in an estimator's ``start``."""
    if n <= 0:
        return np.zeros((0, dim))
    if kind == "random":
        return rng.random((n, dim))
    from scipy.stats import qmc

    return qmc.LatinHypercube(d=dim, rng=rng).random(n)
