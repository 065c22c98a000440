"""Chains of rigid arms hanging from a pivot: the scene and the tracked poses of pendulum data.

An arm's body frame has the arm along -y (hanging straight down at angle 0), its pivot at the top
end of the shape. Angles are the scene's: counter-clockwise from hanging down.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from physbench.recording import Track
from physbench.scene import Body, Box, Joint

ARM_WIDTH = 0.025  # m; collision shape only, the moment of inertia is given


@dataclass(frozen=True)
class Arm:
    name: str
    mass: float  # kg
    com: float  # distance of the centre of mass from the arm's pivot, m
    length: float  # shape length; for an inner arm, the distance to the next pivot, m
    inertia: float  # about the centre of mass, kg·m²


def _direction(angle: np.ndarray) -> np.ndarray:
    return np.stack([np.sin(angle), -np.cos(angle)], axis=-1)


def chain_poses(
    pivot: tuple[float, float], arms: Sequence[Arm], angles: np.ndarray
) -> list[np.ndarray]:
    """Shape-centre positions ``(T, 2)`` of each arm for absolute angles ``(T, n_arms)``."""
    p = np.broadcast_to(np.asarray(pivot, dtype=float), (angles.shape[0], 2))
    out = []
    for k, arm in enumerate(arms):
        u = _direction(angles[:, k])
        out.append(p + 0.5 * arm.length * u)
        p = p + arm.length * u
    return out


def chain(
    pivot: tuple[float, float], arms: Sequence[Arm], angles: Sequence[float], rates: Sequence[float]
) -> tuple[tuple[Body, ...], tuple[Joint, ...]]:
    """Bodies at ``angles`` (rad) turning at ``rates`` (rad/s), and their pivot joints."""
    bodies, joints = [], []
    p, vp = np.asarray(pivot, dtype=float), np.zeros(2)
    parent: str | None = None
    for arm, a, w in zip(arms, angles, rates, strict=True):
        u = _direction(np.asarray(a))
        r = 0.5 * arm.length * u
        centre, v = p + r, vp + w * np.array([-r[1], r[0]])
        bodies.append(
            Body(
                arm.name,
                Box(ARM_WIDTH, arm.length),
                (float(centre[0]), float(centre[1])),
                angle=float(a),
                velocity=(float(v[0]), float(v[1])),
                angular_velocity=float(w),
                mass=arm.mass,
                moment=arm.inertia,
                com_offset=(0.0, 0.5 * arm.length - arm.com),
                friction=0.0,
            )
        )
        joints.append(Joint(arm.name, (float(p[0]), float(p[1])), parent))
        r_next = arm.length * u
        p, vp = p + r_next, vp + w * np.array([-r_next[1], r_next[0]])
        parent = arm.name
    return tuple(bodies), tuple(joints)


def chain_tracks(
    pivot: tuple[float, float], arms: Sequence[Arm], t: np.ndarray, angles: np.ndarray
) -> dict[str, Track]:
    """Tracks of each arm: the measured angle and the shape centre it implies."""
    poses = chain_poses(pivot, arms, angles)
    return {
        arm.name: Track(t, xy[:, 0], xy[:, 1], angles[:, k])
        for k, (arm, xy) in enumerate(zip(arms, poses, strict=True))
    }
