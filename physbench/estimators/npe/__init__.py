"""The amortized posterior estimator ``npe`` (torch, lazily imported)."""

from __future__ import annotations

from physbench.hookspecs import hookimpl


@hookimpl
def register_estimators() -> list[type]:
    from physbench.estimators.npe.estimator import NPEEstimator

    return [NPEEstimator]
