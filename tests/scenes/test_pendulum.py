"""pendulum: the arm of each rig stays on its pivot and swings with the compound pendulum's
period; the unknown is the arm's moment of inertia; an unknown rig is refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.scenes import pendulum
from physbench.simulators.base import Simulator
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator


@pytest.mark.parametrize("engine", [PymunkSimulator, Box2DSimulator], ids=["pymunk", "box2d"])
@pytest.mark.parametrize("rig", list(pendulum.RIGS))
def test_matches_the_rig(rig: str, engine: type[Simulator]) -> None:
    """The arm stays on its pivot, and its small-swing period is the compound pendulum's
    2π√((I + m a²) / (m g a)): 0.784 s (kaheman) and 0.591 s (benard), as the data show."""
    p = pendulum.RIGS[rig]
    scene = pendulum.generate(0, rig=rig, angle=0.05, frames=1600)
    a, m = p.com_distance, p.mass
    period = 2 * math.pi * math.sqrt((p.moment + m * a * a) / (m * p.gravity * a))
    st = engine().simulate(scene).body("arm")
    end = st[:, :2] - a * np.stack([np.sin(st[:, 2]), -np.cos(st[:, 2])], axis=1)
    err = np.linalg.norm(end - np.asarray(scene.joints[0].anchor), axis=1).max()
    assert err < 2e-3, (engine.name, err)
    phi = st[:, 2]  # deflection from hanging down
    up = np.flatnonzero((phi[:-1] < 0) & (phi[1:] >= 0))  # upward zero crossings
    t = (up + phi[up] / (phi[up] - phi[up + 1])) / scene.fps
    assert len(t) >= 2 and abs(np.diff(t).mean() / period - 1) < 2e-3, (
        engine.name,
        np.diff(t),
        period,
    )


def test_the_unknown_is_the_arms_moment_and_the_release_is_seeded() -> None:
    scene = pendulum.generate(0)
    rig = pendulum.RIGS["kaheman"]
    assert [(u.key, u.low, u.high) for u in scene.unknowns] == [("arm.moment", 1e-5, 1e-3)]
    arm = scene.bodies[0]
    assert (arm.mass, arm.moment) == (rig.mass, rig.moment)
    assert rig.amplitude[0] <= arm.angle <= rig.amplitude[1]
    assert scene.fps == 1000.0 and scene.meta == {"seed": 0, "rig": "kaheman"}
    given = pendulum.generate(0, angle=0.5, omega=2.0)
    assert given.bodies[0].angle == 0.5 and given.bodies[0].angular_velocity == 2.0
    with pytest.raises(ValueError, match="rig = 'double': expected one of kaheman, benard"):
        pendulum.generate(0, rig="double")
