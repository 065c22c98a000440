"""Contact laws that replace the scene's constant restitution.

They act through the simulators' contact hook, not through forces: when a contact starts, the
stepping loop asks every effect with ``changes_contacts`` set for the coefficient to use (see
:meth:`VelocityDependentRestitution.restitution`). pymunk applies it for the whole contact;
Box2D still treats impacts slower than its compiled-in 1 m/s as inelastic.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.parameter import Parameter


def restitution_law(normal_speed: float | np.ndarray, e0: float, k: float) -> float | np.ndarray:
    """``e(v) = clip(e0 - k·|v|, 0, 1)``: restitution falling linearly with normal impact speed."""
    e = np.clip(e0 - k * np.abs(normal_speed), 0.0, 1.0)
    return float(e) if np.ndim(e) == 0 else e


class VelocityDependentRestitution(Effect):
    """Coefficient of restitution ``e(v) = clip(e0 - k·v, 0, 1)`` for impacts at normal speed ``v``
    (m/s), replacing the product of the two materials' elasticities.

    ``statics_only`` restricts the law to contacts with static geometry (cushions, walls);
    ``bodies`` restricts it to contacts involving the selected bodies.
    """

    name: ClassVar[str] = "velocity_dependent_restitution"
    applies_forces: ClassVar[bool] = False
    changes_contacts: ClassVar[bool] = True
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("e0", 0.0, 1.0, default=0.9, doc="restitution of a very slow impact"),
        Parameter(
            "k",
            0.0,
            1.0,
            unit="s/m",
            default=0.0,
            doc="restitution lost per m/s of normal impact speed",
        ),
    )

    @classmethod
    def neutral(cls) -> None:
        """None: every value replaces the scene's restitution, so no value leaves it as is."""
        return None

    def __init__(self, *, statics_only: bool = False, **kw: object) -> None:
        super().__init__(**kw)  # type: ignore[arg-type]
        self.statics_only = bool(statics_only)

    def restitution(self, normal_speed: float, a: int, b: int | None) -> float | None:
        """Called by the engine once when a new contact starts between body ``a`` and body ``b``
        (indices into ``scene.bodies``; ``b`` is ``None`` for static geometry), before the solver
        runs, with the approach speed along the contact normal (>= 0). Returns the restitution to
        use for that contact, or ``None`` to keep the scene's."""
        if self.statics_only and b is not None:
            return None
        if self.bodies is not None and not (self.mask[a] or (b is not None and self.mask[b])):
            return None
        return float(restitution_law(normal_speed, self.values["e0"], self.values["k"]))
