"""Correction estimators: the contract (:mod:`~physbench.estimators.base`), the ask/tell base of
the black-box optimisers (:mod:`~physbench.estimators.ask_tell`) and the built-ins, each in its own
module and registered by name: ``random``, ``tpe``, ``cmaes``, ``optuna`` and the learned
``resnet3d``."""

from __future__ import annotations

from physbench.estimators.base import CorrectionEstimator, Step, Task

__all__ = ["CorrectionEstimator", "Step", "Task"]
