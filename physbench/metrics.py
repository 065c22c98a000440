"""The paper's measures: image-space MSE (the objective) and normalized parameter MSE (the score).

*Normalized MSE*: each parameter divided by the maximum of its range, squared error averaged over
the unknowns (:meth:`physbench.unknowns.ParamSpace.normalized_mse`). *Minimum after N iterations*:
the normalized MSE of the best-so-far iterate, where best means lowest **image** MSE, so the truth
is never used to pick (the note under the paper's Fig. 3).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

import numpy as np

from physbench.unknowns import ParamSpace


def image_mse(a: np.ndarray, b: np.ndarray) -> float:
    """Mean squared pixel difference of two equally shaped frame stacks (accumulated in float64)."""
    if a.shape != b.shape:
        raise ValueError(f"frame shapes differ: {a.shape} vs {b.shape}")
    d = np.subtract(a, b, dtype=np.float64)
    # numpy's own pairwise sum, not BLAS: a BLAS dot may sum in an order that depends on threads
    # and memory alignment, and the same seed must give bit-identical losses in every process.
    np.square(d, out=d)
    return float(d.sum() / d.size)


def normalized_mse(
    space: ParamSpace, estimate: Mapping[str, float], truth: Mapping[str, float]
) -> float:
    """The paper's parameter error; see the module docstring."""
    return space.normalized_mse(estimate, truth)


def running_best(losses: Sequence[float]) -> list[int]:
    """Index of the best-so-far (lowest) loss after each iteration; ties keep the earlier one."""
    out: list[int] = []
    best = 0
    for i, loss in enumerate(losses):
        if loss < losses[best]:
            best = i
        out.append(best)
    return out


def mean_std(values: Iterable[float]) -> tuple[float, float]:
    """Mean and sample standard deviation (``ddof=1``; 0 for a single value)."""
    v = np.asarray(list(values), dtype=float)
    if v.size == 0:
        return math.nan, math.nan
    return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0


def format_mean_std(mean: float, std: float) -> str:
    """``(1.1 ± 0.3)e-02``: mean and std sharing the mean's power of ten, as in the paper's Table
    1."""
    if not math.isfinite(mean) or mean == 0:
        return f"{mean:.2g} ± {std:.2g}"
    exp = math.floor(math.log10(abs(mean)))
    scale = 10.0**exp
    return f"({mean / scale:.2g} ± {std / scale:.2g})e{exp:+03d}"
