"""Built-in model extensions (:class:`~physbench.effects.base.Effect` plugins).

Each adds named parameters and acts through forces and torques that both engines apply the same
way every substep. Measurement effects (:class:`SensorOffset`, :class:`ClockScale`,
:class:`CalibrationScale`, :class:`AxisRotation`, :class:`LensDistortion`, :class:`PlaneTilt`) apply
no forces and change the simulated trajectory through :meth:`~Effect.measure` instead;
:func:`apply_measurements` is what the framework calls on every simulated trajectory before
comparing it with data.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from physbench.effects.base import Effect, EffectError, smooth_sign, smooth_unit
from physbench.effects.contact import VelocityDependentRestitution, restitution_law
from physbench.effects.drag import LinearDrag, QuadraticDrag
from physbench.effects.forces import ConstantForce, TableTilt
from physbench.effects.joints import (
    JointCoulombFriction,
    JointQuadraticDamping,
    JointViscousDamping,
)
from physbench.effects.measurement import (
    AxisRotation,
    CalibrationScale,
    ClockScale,
    LensDistortion,
    PlaneTilt,
    SensorOffset,
)
from physbench.effects.surface import RollingResistance
from physbench.hookspecs import hookimpl
from physbench.trajectory import Trajectory

#: Every built-in effect class, in registration order.
BUILTIN_EFFECTS: tuple[type[Effect], ...] = (
    LinearDrag,
    QuadraticDrag,
    RollingResistance,
    ConstantForce,
    TableTilt,
    JointViscousDamping,
    JointCoulombFriction,
    JointQuadraticDamping,
    VelocityDependentRestitution,
    SensorOffset,
    ClockScale,
    CalibrationScale,
    AxisRotation,
    LensDistortion,
    PlaneTilt,
)


def apply_measurements(traj: Trajectory, effects: Iterable[Effect]) -> Trajectory:
    """Called after every simulation: ``traj`` passed through the :meth:`~Effect.measure` of each
    effect that :attr:`~Effect.measures`, in order."""
    for eff in effects:
        if eff.measures:
            traj = eff.measure(traj)
    return traj


@hookimpl
def register_effects() -> list[type[Any]]:
    return list(BUILTIN_EFFECTS)


__all__ = [
    "BUILTIN_EFFECTS",
    "AxisRotation",
    "CalibrationScale",
    "ClockScale",
    "ConstantForce",
    "Effect",
    "EffectError",
    "JointCoulombFriction",
    "JointQuadraticDamping",
    "JointViscousDamping",
    "LensDistortion",
    "LinearDrag",
    "PlaneTilt",
    "QuadraticDrag",
    "RollingResistance",
    "SensorOffset",
    "TableTilt",
    "VelocityDependentRestitution",
    "apply_measurements",
    "restitution_law",
    "smooth_sign",
    "smooth_unit",
]
