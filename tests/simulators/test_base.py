"""The Simulator contract's documented defaults, and the engine-world base the stepping loop
builds on (no speed limit, no contact hook unless declared)."""

from __future__ import annotations

import math
from typing import ClassVar

import pytest

from physbench.effects import VelocityDependentRestitution
from physbench.errors import SimulationError
from physbench.plugins import get_registry
from physbench.scene import Body, Circle, Scene
from physbench.simulators.base import DEFAULT_SIMULATOR, Simulator
from physbench.simulators.pymunk_sim import PymunkSimulator, PymunkWorld
from physbench.simulators.stepping import EngineWorld


class Bare(Simulator):
    name: ClassVar[str] = "bare"


def test_simulate_names_the_class_that_must_implement_it_and_the_default_is_registered() -> None:
    scene = Scene("s", (Body("b", Circle(0.1), (1.0, 1.0)),))
    with pytest.raises(NotImplementedError, match=r"^Bare must implement simulate\(\)$"):
        Bare().simulate(scene)
    assert Simulator.name == "" and DEFAULT_SIMULATOR in get_registry().names("simulator")


class NoHookWorld(PymunkWorld):
    """A pymunk world that does not offer the contact hook (as a third-party engine might not)."""

    contact_hook = False


class NoHookPymunk(PymunkSimulator):
    name: ClassVar[str] = "no_hook"

    def build(self, scene: Scene) -> EngineWorld:
        return NoHookWorld(scene, self.iterations)


def test_an_engine_world_has_no_speed_limit_and_no_contact_hook_unless_it_declares_them() -> None:
    assert EngineWorld.max_speed == math.inf and EngineWorld.max_angular_speed == math.inf
    assert EngineWorld.contact_hook is False and PymunkWorld.contact_hook is True
    with pytest.raises(NotImplementedError):
        EngineWorld().set_restitution_hook(lambda speed, a, b: None)
    scene = Scene("s", (Body("b", Circle(0.1), (1.0, 1.0)),), frames=3)
    assert NoHookPymunk().simulate(scene).frames == 3  # no contact effect: no hook needed
    with pytest.raises(
        SimulationError, match="change contacts, but this engine has no contact hook"
    ):
        NoHookPymunk().simulate(scene, effects=[VelocityDependentRestitution()])
