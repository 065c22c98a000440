"""Losses in pivot joints: viscous, Coulomb (dry bearing) and quadratic (air on the arm) torques
on the relative rotation rate of the two sides."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import JointEffectBase, smooth_sign, substep
from physbench.protocols import EffectParam
from physbench.scene import Scene


class JointViscousDamping(JointEffectBase):
    """``tau = -c·w`` with ``w`` the joint's relative rate: exponential amplitude decay."""

    name: ClassVar[str] = "joint_viscous_damping"
    params: ClassVar[tuple[EffectParam, ...]] = (
        EffectParam("c", 0.0, 0.0, 0.1, "N·m·s/rad", "torque per unit relative rate"),
    )

    def law(self, rate: np.ndarray) -> np.ndarray:
        return -self.values["c"] * rate


class JointCoulombFriction(JointEffectBase):
    """``tau = -tau_f · w / sqrt(w² + eps²)``: a constant friction torque, linear amplitude decay.

    The regularisation rate ``eps`` (rad/s) keeps the torque smooth through zero rate; it is at
    least ``tau_f·h/I`` (``h`` the substep, ``I`` the smaller inertia on the joint), so one substep
    of friction cannot reverse the rate, which would chatter. A joint at rest creeps under a load
    below ``tau_f`` at rate ``≈ eps·load/tau_f`` instead of sticking.
    """

    name: ClassVar[str] = "joint_coulomb_friction"
    params: ClassVar[tuple[EffectParam, ...]] = (
        EffectParam("tau", 0.0, 0.0, 0.1, "N·m", "friction torque while the joint turns"),
    )

    def __init__(self, *, eps: float = 0.02, **kw: object) -> None:
        super().__init__(**kw)  # type: ignore[arg-type]
        self.eps = float(eps)
        self._eps = np.zeros(0)

    def configure(self, scene: Scene) -> None:
        super().configure(scene)
        self._eps = np.maximum(self.eps, self.values["tau"] * substep(scene) / self.reduced_inertia)

    def law(self, rate: np.ndarray) -> np.ndarray:
        return -self.values["tau"] * smooth_sign(rate, self._eps)


class JointQuadraticDamping(JointEffectBase):
    """``tau = -c·|w|·w``: losses growing with the square of the rate (air drag on a swinging arm),
    which makes the decrement per swing grow with amplitude."""

    name: ClassVar[str] = "joint_quadratic_damping"
    params: ClassVar[tuple[EffectParam, ...]] = (
        EffectParam("c", 0.0, 0.0, 0.01, "N·m·s²/rad²", "torque per unit squared relative rate"),
    )

    def law(self, rate: np.ndarray) -> np.ndarray:
        return -self.values["c"] * np.abs(rate) * rate
