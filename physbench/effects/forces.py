"""Constant external forces: a force independent of mass (wind, a thread) and a uniform
acceleration (a tilted table seen from above, a gravity misalignment)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.parameter import Parameter


class ConstantForce(Effect):
    """``F = (fx, fy)`` on the centre of mass of each selected body (default: all)."""

    name: ClassVar[str] = "constant_force"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("fx", -10.0, 10.0, unit="N", default=0.0, doc="force along x", extensible=True),
        Parameter("fy", -10.0, 10.0, unit="N", default=0.0, doc="force along y", extensible=True),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        f[self.sel] = (self.values["fx"], self.values["fy"])
        return f, tau


class TableTilt(Effect):
    """``F = m (ax, ay)``: the in-plane pull of gravity on a slightly tilted table (``a ≈
    g·slope``)."""

    name: ClassVar[str] = "table_tilt"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "ax", -1.0, 1.0, unit="m/s²", default=0.0, doc="acceleration along x", extensible=True
        ),
        Parameter(
            "ay", -1.0, 1.0, unit="m/s²", default=0.0, doc="acceleration along y", extensible=True
        ),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self._require_setup(states)
        f, tau = self.zeros(states.shape[0])
        m = self.masses[self.sel, None]
        f[self.sel] = m * np.array([self.values["ax"], self.values["ay"]])
        return f, tau
