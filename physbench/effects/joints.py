"""Losses in pivot joints: viscous, Coulomb (dry bearing) and quadratic (air on the arm) torques
on the relative rotation rate of the two sides."""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect, EffectError, smooth_sign, substep
from physbench.parameter import Parameter
from physbench.scene import Scene


class JointEffect(Effect):
    """A torque law on the relative rotation rate of each selected pivot joint.

    A joint to the world gets ``tau = law(omega_a)`` on body ``a``; a joint between two bodies
    gets ``law(omega_a - omega_b)`` on ``a`` and the opposite on ``b``. ``joints`` selects joints
    by index into ``scene.joints`` (default: all). ``bodies`` is not used by joint effects.
    """

    scene_needs: ClassVar[tuple[str, ...]] = ("joints",)

    def __init__(self, *, joints: Sequence[int] | None = None, **values: float) -> None:
        super().__init__(**values)
        self.joints = None if joints is None else tuple(int(j) for j in joints)
        self.ia = np.zeros(0, dtype=int)
        self.ib = np.zeros(0, dtype=int)  # -1: the world
        self.reduced_inertia = np.zeros(0)
        self._to_world = False

    def configure(self, scene: Scene) -> None:
        chosen = range(len(scene.joints)) if self.joints is None else self.joints
        if not scene.joints:
            raise EffectError(
                f"effect {self.name!r} needs a scene with joints; scene {scene.name!r} has none"
            )
        for j in chosen:
            if not 0 <= j < len(scene.joints):
                raise EffectError(
                    f"{self.name}: joint index {j} out of range; scene {scene.name!r} has joints "
                    f"0..{len(scene.joints) - 1}"
                )
        sel = [scene.joints[j] for j in chosen]
        self.ia = np.array([scene.body_index(j.a) for j in sel], dtype=int)
        self.ib = np.array(
            [scene.body_index(j.b) if j.b is not None else -1 for j in sel], dtype=int
        )
        ia_inv = 1.0 / self.inertias[self.ia]
        ib_inv = np.where(self.ib >= 0, 1.0 / self.inertias[np.maximum(self.ib, 0)], 0.0)
        # Smallest inertia the torque acts on: the pivot only adds inertia, so this bounds the
        # fastest response of the relative rate and sets the regularisation floor.
        self.reduced_inertia = 1.0 / (ia_inv + ib_inv)
        self._to_world = bool(np.all(self.ib < 0) and len(set(self.ia.tolist())) == len(self.ia))

    def law(self, rate: np.ndarray) -> np.ndarray:
        """Torque on body ``a`` for relative rates ``rate`` (one per selected joint)."""
        raise NotImplementedError

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        n = states.shape[0]
        f, tau = self.zeros(n)
        omega = states[:, 5]
        if self._to_world:  # every selected joint ties a distinct body to the world
            tau[self.ia] = self.law(omega[self.ia])
            return f, tau
        rate = omega[self.ia] - np.where(self.ib >= 0, omega[np.maximum(self.ib, 0)], 0.0)
        torque = self.law(rate)
        np.add.at(tau, self.ia, torque)
        has_b = self.ib >= 0
        np.add.at(tau, self.ib[has_b], -torque[has_b])
        return f, tau


class JointViscousDamping(JointEffect):
    """``tau = -c·w`` with ``w`` the joint's relative rate: exponential amplitude decay."""

    name: ClassVar[str] = "joint_viscous_damping"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "c",
            0.0,
            0.1,
            unit="N·m·s/rad",
            default=0.0,
            doc="torque per unit relative rate",
            extensible=True,
        ),
    )

    def law(self, rate: np.ndarray) -> np.ndarray:
        return -self.values["c"] * rate


class JointCoulombFriction(JointEffect):
    """``tau = -tau_f · w / sqrt(w² + eps²)``: a constant friction torque, linear amplitude decay.

    The regularisation rate ``eps`` (rad/s) keeps the torque smooth through zero rate; it is at
    least ``tau_f·h/I`` (``h`` the substep, ``I`` the smaller inertia on the joint), so one substep
    of friction cannot reverse the rate, which would chatter. A joint at rest creeps under a load
    below ``tau_f`` at rate ``≈ eps·load/tau_f`` instead of sticking.
    """

    name: ClassVar[str] = "joint_coulomb_friction"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "tau",
            0.0,
            0.1,
            unit="N·m",
            default=0.0,
            doc="friction torque while the joint turns",
            extensible=True,
        ),
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


class JointQuadraticDamping(JointEffect):
    """``tau = -c·|w|·w``: losses growing with the square of the rate (air drag on a swinging arm),
    which makes the decrement per swing grow with amplitude."""

    name: ClassVar[str] = "joint_quadratic_damping"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "c",
            0.0,
            0.01,
            unit="N·m·s²/rad²",
            default=0.0,
            doc="torque per unit squared relative rate",
            extensible=True,
        ),
    )

    def law(self, rate: np.ndarray) -> np.ndarray:
        return -self.values["c"] * np.abs(rate) * rate
