"""Shared inputs of the discovery tests: a tiny sliding-ball scene with noisy tracks, and one
synthetic recording (a puck slowed by hidden linear drag) with its fitted base model."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from physbench.discover import Discovery, Run, Scored, Settings, discover, fit_base
from physbench.discover.synthetic import SyntheticRun, make_case
from physbench.effects import LinearDrag
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Scene
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory


def _slide(v=(2.0, 0.5), mass=1.0, frames=41, fps=20.0, unknowns=()) -> Scene:
    return Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=v, mass=mass),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=fps,
        frames=frames,
        substeps=4,
        unknowns=unknowns,
    ).validate()


def _noisy(traj: Trajectory, sigma=0.002, seed=0, fields=None) -> Recording:
    rng = np.random.default_rng(seed)
    rec = Recording.from_trajectory(traj)
    tracks = {
        b: Track(
            t.t,
            t.x + rng.normal(0, sigma, len(t)),
            t.y + rng.normal(0, sigma, len(t)),
            None if t.angle is None else t.angle + rng.normal(0, sigma, len(t)),
        )
        for b, t in rec.tracks.items()
    }
    return Recording(tracks, fields=fields or ("x", "y"))


@pytest.fixture
def slide() -> Callable[..., Scene]:
    """A ball sliding on a table seen from above (no gravity): ``slide(v=..., mass=...)``."""
    return _slide


@pytest.fixture
def noisy() -> Callable[..., Recording]:
    """Tracks of a trajectory with Gaussian noise (seeded): ``noisy(traj, sigma=..., seed=...)``."""
    return _noisy


@pytest.fixture(scope="session")
def puck() -> SyntheticRun:
    """A puck sliding from above, slowed by hidden linear drag (seed 0, pymunk)."""
    return make_case("linear_drag", "puck", 0, PymunkSimulator())


@pytest.fixture(scope="session")
def puck_base(puck: SyntheticRun) -> Scored:
    """The base model (no effect) fitted to :func:`puck`."""
    return fit_base([puck.run], PymunkSimulator(), Settings())


@pytest.fixture(scope="session")
def drag_discovery() -> Discovery:
    """A discovery on a ball slowed by linear drag (c = 0.4) among four candidates."""
    scene = _slide()
    rec = _noisy(PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.4)]))
    return discover(
        [Run("r", scene, recording=rec)],
        "pymunk",
        settings=Settings(
            effects=["linear_drag", "quadratic_drag", "rolling_resistance", "sensor_offset"]
        ),
    )
