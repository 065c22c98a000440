"""Intervals for fitted parameters that allow for residuals correlated in time.

The i.i.d. least-squares covariance ``s² (JᵀJ)⁻¹`` assumes independent residuals. Tracking errors
and model error (a missed impact time, a slightly wrong law) make neighbouring residuals of one
series (one run, body and field, in time order) alike, and that covariance then undercounts the
uncertainty. Here each series gets its own noise level ``σ²`` and lag-1 autocorrelation ``ρ``
(an AR(1) noise model, estimated from the residuals at the optimum), and the covariance is the
sandwich ``A⁻¹ (Σ σ² Jₛᵀ Rₛ Jₛ) A⁻¹`` with ``A = JᵀJ`` and ``Rₛ[i, j] = ρ^|i-j|``. The interval
uses a Student-t quantile with the effective degrees of freedom ``Σ Tₛ (1-ρ)/(1+ρ) - p``.

:func:`~physbench.discover.fit.least_squares` calls :func:`ar1_covariance` once per full fit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from physbench.discover.data import DiscoverError

#: The name of the interval method, as carried in results and JSON.
METHOD = "AR(1) sandwich, t quantile with effective dof"
#: Coverage the intervals aim at.
LEVEL = 0.90
#: Largest autocorrelation used: a series that is nearly all drift still counts as some evidence.
MAX_RHO = 0.98


@dataclass(frozen=True)
class Uncertainty:
    """The covariance of the free parameters (in the fit's scaled units), its effective degrees of
    freedom, and the per-series autocorrelations it assumed."""

    cov: np.ndarray
    dof: float
    rho: np.ndarray

    def half_width(self, level: float = LEVEL) -> np.ndarray:
        """Half widths of the two-sided ``level`` intervals, in scaled units."""
        from scipy import stats

        q = float(stats.t.ppf(0.5 + level / 2, self.dof))
        return q * np.sqrt(np.clip(np.diag(self.cov), 0.0, None))


def _ar1_apply(x: np.ndarray, rho: float) -> np.ndarray:
    """``R x`` for the AR(1) correlation matrix ``R[i, j] = rho^|i-j|`` (columns of ``x`` along
    axis 0), by a forward and a backward exponential filter instead of a T×T matrix."""
    if rho == 0.0 or x.shape[0] < 2:
        return x
    from scipy.signal import lfilter

    fwd = lfilter([1.0], [1.0, -rho], x, axis=0)
    bwd = lfilter([1.0], [1.0, -rho], x[::-1], axis=0)[::-1]
    return fwd + bwd - x


def lag1(r: np.ndarray) -> float:
    """Lag-1 autocorrelation of one series of residuals, clipped to ``[0, MAX_RHO]`` (a negative
    estimate is taken as none: narrowing intervals on it would not be cautious)."""
    if r.size < 3:
        return 0.0
    den = float(r @ r)
    if den <= 0:
        return 0.0
    return float(np.clip((r[1:] @ r[:-1]) / den, 0.0, MAX_RHO))


def ar1_covariance(
    jac: np.ndarray, r: np.ndarray, series: Sequence[int] | np.ndarray
) -> Uncertainty:
    """The AR(1) sandwich covariance of the parameters of a least-squares fit with Jacobian ``jac``
    (n × p) and residuals ``r`` (n) at the optimum; ``series[i]`` labels the series of entry ``i``
    (entries of one series are consecutive and in time order)."""
    j = np.asarray(jac, dtype=float)
    r = np.asarray(r, dtype=float)
    labels = np.asarray(series)
    n, p = j.shape
    if labels.shape != (n,) or r.shape != (n,):
        raise DiscoverError(
            f"jacobian of shape {j.shape}, residuals {r.shape} and series labels "
            f"{labels.shape}: expected ({n}, p), ({n},) and ({n},)"
        )
    inflate = n / max(n - p, 1)  # the fit used p degrees of freedom of the residuals
    meat = np.zeros((p, p))
    rhos, n_eff = [], 0.0
    starts = np.flatnonzero(np.r_[True, labels[1:] != labels[:-1], True])
    for a, b in pairwise(starts):
        rs, js = r[a:b], j[a:b]
        rho = lag1(rs)
        var = float(rs @ rs) / rs.size * inflate
        meat += var * js.T @ _ar1_apply(js, rho)
        rhos.append(rho)
        n_eff += rs.size * (1 - rho) / (1 + rho)
    bread = np.linalg.pinv(j.T @ j, rcond=1e-12)
    return Uncertainty(bread @ meat @ bread, max(n_eff - p, 1.0), np.array(rhos))
