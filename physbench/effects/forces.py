"""Constant external forces: a force independent of mass (wind, a thread) and a uniform
acceleration (a tilted table seen from above, a gravity misalignment)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import EffectBase
from physbench.protocols import EffectParam


class ConstantForce(EffectBase):
    """``F = (fx, fy)`` on the centre of mass of each selected body (default: all)."""

    name: ClassVar[str] = "constant_force"
    params: ClassVar[tuple[EffectParam, ...]] = (
        EffectParam("fx", 0.0, -10.0, 10.0, "N", "force along x"),
        EffectParam("fy", 0.0, -10.0, 10.0, "N", "force along y"),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        f[self.sel] = (self.values["fx"], self.values["fy"])
        return f, tau


class TableTilt(EffectBase):
    """``F = m (ax, ay)``: the in-plane pull of gravity on a slightly tilted table (``a ≈ g·slope``)."""

    name: ClassVar[str] = "table_tilt"
    params: ClassVar[tuple[EffectParam, ...]] = (
        EffectParam("ax", 0.0, -1.0, 1.0, "m/s²", "acceleration along x"),
        EffectParam("ay", 0.0, -1.0, 1.0, "m/s²", "acceleration along y"),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        m = self.masses[self.sel, None]
        f[self.sel] = m * np.array([self.values["ax"], self.values["ay"]])
        return f, tau
