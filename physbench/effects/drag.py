"""Fluid drag on the translation of bodies: linear (Stokes) and quadratic (Newton) laws."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.parameter import Parameter


class LinearDrag(Effect):
    """``F = -c v`` on the centre of mass of each selected body (default: all)."""

    name: ClassVar[str] = "linear_drag"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "c",
            0.0,
            10.0,
            unit="N·s/m",
            default=0.0,
            doc="drag force per unit speed",
            extensible=True,
        ),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        f[self.sel] = -self.values["c"] * states[self.sel, 3:5]
        return f, tau


class QuadraticDrag(Effect):
    """``F = -c |v| v`` on the centre of mass of each selected body (default: all).

    ``c = ½ ρ C_d A``; a body of mass ``m`` falling under ``g`` tends to ``sqrt(m g / c)``.
    """

    name: ClassVar[str] = "quadratic_drag"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "c",
            0.0,
            1.0,
            unit="kg/m",
            default=0.0,
            doc="drag force per unit squared speed",
            extensible=True,
        ),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        v = states[self.sel, 3:5]
        speed = np.sqrt((v * v).sum(axis=1, keepdims=True))
        f[self.sel] = -self.values["c"] * speed * v
        return f, tau
