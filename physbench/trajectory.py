"""Trajectory: what a simulator returns, sampled at the scene's frame rate."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physbench.errors import UnknownNameError, counted

#: Columns of :attr:`Trajectory.states`, in order.
STATE_FIELDS = ("x", "y", "angle", "vx", "vy", "omega")


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Per frame, per body: ``x, y`` (shape centre, m), ``angle`` (rad, CCW), ``vx, vy``
    (velocity of the shape centre, m/s), ``omega`` (rad/s). ``states`` has shape ``(T, N, 6)``;
    frame 0 is the initial state and frame ``k`` is at ``times[k] = k / fps``."""

    bodies: tuple[str, ...]
    times: np.ndarray  # (T,)
    states: np.ndarray  # (T, N, 6) float64
    engine: str = ""

    def __post_init__(self) -> None:
        t, n, c = self.states.shape
        if n != len(self.bodies) or c != len(STATE_FIELDS) or self.times.shape != (t,):
            raise ValueError(
                f"states {self.states.shape} do not match {counted(len(self.bodies), 'body')} "
                f"and {counted(len(self.times), 'time')}"
            )

    @property
    def frames(self) -> int:
        return self.states.shape[0]

    def body(self, name: str) -> np.ndarray:
        """``(T, 6)`` state of one body."""
        if name not in self.bodies:
            raise UnknownNameError("body", name, self.bodies, where="of the trajectory")
        return self.states[:, self.bodies.index(name)]

    def field(self, name: str) -> np.ndarray:
        """``(T, N)`` values of one state field across bodies."""
        if name not in STATE_FIELDS:
            raise UnknownNameError("state field", name, STATE_FIELDS)
        return self.states[:, :, STATE_FIELDS.index(name)]

    def to_npz_dict(self) -> dict[str, np.ndarray]:
        return {
            "bodies": np.array(self.bodies),
            "times": self.times,
            "states": self.states,
            "engine": np.array(self.engine),
        }

    @classmethod
    def from_npz_dict(cls, d: dict[str, np.ndarray]) -> Trajectory:
        return cls(
            bodies=tuple(str(b) for b in d["bodies"]),
            times=np.asarray(d["times"], dtype=float),
            states=np.asarray(d["states"], dtype=float),
            engine=str(d["engine"]) if "engine" in d else "",
        )
