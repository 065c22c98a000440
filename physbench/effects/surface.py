"""Losses of bodies moving on a supporting surface that the 2D scene does not model, e.g. balls on
a billiards table seen from above (scene gravity 0)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect, smooth_unit, substep
from physbench.parameter import Parameter
from physbench.scene import Scene


class RollingResistance(Effect):
    """A constant deceleration ``mu·g`` against the velocity of each selected body, until it stops.

    ``F = -mu m g v / sqrt(|v|² + eps²)``. The regularisation speed ``eps`` keeps the force smooth
    at rest (no chatter); it is at least the speed the force removes in one substep, so the force
    never reverses a velocity within a step. ``g`` is the surface's gravity (the scene's gravity is
    0 in a top-down view), a fixed option, not a parameter. Rotation is not affected.
    """

    name: ClassVar[str] = "rolling_resistance"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "mu",
            0.0,
            0.1,
            unit="",
            default=0.0,
            doc="rolling resistance coefficient (deceleration / g)",
            extensible=True,
        ),
    )

    def __init__(self, *, g: float = 9.81, eps: float = 1e-3, **kw: object) -> None:
        super().__init__(**kw)  # type: ignore[arg-type]
        self.g, self.eps = float(g), float(eps)
        self._eps = self.eps

    def configure(self, scene: Scene) -> None:
        self._eps = max(self.eps, self.values["mu"] * self.g * substep(scene))

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        m = self.masses[self.sel, None]
        f[self.sel] = (
            -self.values["mu"] * self.g * m * smooth_unit(states[self.sel, 3:5], self._eps)
        )
        return f, tau
