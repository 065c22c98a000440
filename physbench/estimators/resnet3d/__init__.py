"""The learned correction estimator ``resnet3d`` (torch, lazily imported)."""

from __future__ import annotations

from physbench.hookspecs import hookimpl


@hookimpl
def register_estimators() -> list[type]:
    from physbench.estimators.resnet3d.estimator import ResNet3DEstimator

    return [ResNet3DEstimator]
