"""Shared by the simulator tests: both built-in engines as a parametrized fixture, and their
float tolerances."""

from __future__ import annotations

import pytest

from physbench.scene import Body, Box, Circle, Force, Polygon, Scene
from physbench.scenes.bin import bin_walls
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.simulators.stepping import SteppingSimulator

ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
#: Absolute tolerance for values of order 1-10 after a few hundred steps, per engine.
FLOAT = {"pymunk": 1e-9, "box2d": 1e-4}


@pytest.fixture(params=sorted(ENGINES))
def sim(request: pytest.FixtureRequest) -> SteppingSimulator:
    """Each built-in engine in turn."""
    return ENGINES[request.param]()


@pytest.fixture
def tol(sim: SteppingSimulator) -> float:
    """The float tolerance of ``sim``."""
    return FLOAT[sim.name]


@pytest.fixture
def busy_scene() -> Scene:
    bodies = (
        Body("a", Circle(0.3), (1.0, 2.5), velocity=(3.0, 0.0), elasticity=0.7, friction=0.4),
        Body("b", Box(0.5, 0.4), (2.0, 0.3), angle=0.1, mass=2.0, elasticity=0.3),
        Body(
            "c",
            Polygon(((-0.2, -0.2), (0.3, -0.2), (0.0, 0.3))),
            (3.0, 1.0),
            com_offset=(0.05, 0.0),
        ),
    )
    return Scene(
        "busy",
        bodies,
        statics=bin_walls((0.0, 0.0, 4.0, 4.0)),
        forces=(Force("a", (50.0, -30.0), 0.0, 0.2),),
        frames=90,
    )
