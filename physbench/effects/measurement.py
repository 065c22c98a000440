"""Measurement effects: they change what the sensor reports, not the motion.

They return zero forces. The framework must call :meth:`measure` on every simulated trajectory
(after simulating, before comparing with a recording or rendering the observation);
:func:`physbench.effects.apply_measurements` does it for a list of effects.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from physbench.effects.base import Effect, EffectError
from physbench.parameter import Parameter
from physbench.trajectory import Trajectory


class _Measurement(Effect):
    applies_forces: ClassVar[bool] = False
    measures: ClassVar[bool] = True

    def _body_mask(self, traj: Trajectory) -> np.ndarray:
        if self.bodies is None:
            return np.ones(len(traj.bodies), dtype=bool)
        missing = [b for b in self.bodies if b not in traj.bodies]
        if missing:
            raise EffectError(
                f"{self.name}: bodies {missing} are not in the trajectory (bodies: "
                f"{list(traj.bodies)})"
            )
        return np.array([b in self.bodies for b in traj.bodies], dtype=bool)


class SensorOffset(_Measurement):
    """A constant bias added to the tracked ``x``, ``y`` and ``angle`` of each selected body
    (default: all), e.g. an encoder zero that is not the rest angle.

    A position bias has no physical limit (a camera's origin can be anywhere), so ``dx`` and
    ``dy`` widen at either end; ``dangle`` does not, as widening ten-fold would pass ±π, where
    an angle bias repeats."""

    name: ClassVar[str] = "sensor_offset"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter(
            "dx", -0.5, 0.5, unit="m", default=0.0, doc="bias of the tracked x", extensible=True
        ),
        Parameter(
            "dy", -0.5, 0.5, unit="m", default=0.0, doc="bias of the tracked y", extensible=True
        ),
        Parameter("dangle", -0.5, 0.5, unit="rad", default=0.0, doc="bias of the tracked angle"),
    )

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation: the trajectory shifted by the biases."""
        states = traj.states.copy()
        sel = self._body_mask(traj)
        states[:, sel, 0] += self.values["dx"]
        states[:, sel, 1] += self.values["dy"]
        states[:, sel, 2] += self.values["dangle"]
        return Trajectory(traj.bodies, traj.times, states, engine=traj.engine)


class ClockScale(_Measurement):
    """A recorder clock that runs at the wrong rate: a sample stamped ``t`` was taken at true time
    ``scale·t`` (e.g. a logger whose nominal sample interval is shorter than the real one).

    The measured trajectory is stamped ``t/scale`` and its velocities are per recorder second.
    Simulate at least ``scale`` times the recording's duration.
    """

    name: ClassVar[str] = "clock_scale"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("scale", 0.8, 1.25, default=1.0, doc="true seconds per recorded second"),
    )

    def measure(self, traj: Trajectory) -> Trajectory:
        """Called after every simulation: the trajectory on the recorder's clock."""
        s = self.values["scale"]
        states = traj.states.copy()
        states[:, :, 3:6] *= s
        return Trajectory(traj.bodies, traj.times / s, states, engine=traj.engine)
