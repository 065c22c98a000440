"""The simulator kit passes a small correct engine and catches deliberately broken ones."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar

import numpy as np
import pytest

from physbench.effects.base import Effect
from physbench.scene import Scene
from physbench.simulators.stepping import EngineWorld, SteppingSimulator
from physbench.testing import (
    Check,
    ConformanceError,
    Subject,
    check_simulator,
    parametrize_with_checks,
)
from physbench.testing.simulators import (
    check_applies_effects,
    check_applies_params,
    check_collision,
    check_deterministic,
    check_deterministic_in_subprocess,
    check_explosion_raises,
    check_free_fall,
    check_protocol,
)
from physbench.trajectory import Trajectory


class BallWorld(EngineWorld):
    """Every body a free disc of its shape's extent: semi-implicit Euler, impulses between
    overlapping approaching discs with the product of their elasticities. No statics, no joints."""

    def __init__(self, scene: Scene, gravity: tuple[float, float]) -> None:
        self.g = np.array(gravity, dtype=float)
        self.m = np.array([b.mass for b in scene.bodies])
        self.inertia = np.array([b.inertia() for b in scene.bodies])
        self.r = np.array([b.shape.extent() for b in scene.bodies])
        self.e = np.array([b.elasticity for b in scene.bodies])
        self.s = np.array(
            [(*b.position, b.angle, *b.velocity, b.angular_velocity) for b in scene.bodies]
        )
        self.f = np.zeros((len(scene.bodies), 3))

    def step(self, h: float) -> None:
        s = self.s
        s[:, 3:5] += h * (self.g + self.f[:, :2] / self.m[:, None])
        s[:, 5] += h * self.f[:, 2] / self.inertia
        s[:, 0:3] += h * s[:, 3:6]
        self.f[:] = 0.0
        self.collide()

    def collide(self) -> None:
        s, n = self.s, len(self.s)
        for i in range(n):
            for j in range(i + 1, n):
                d = s[j, :2] - s[i, :2]
                dist = math.hypot(*d)
                if dist == 0 or dist > self.r[i] + self.r[j]:
                    continue
                normal = d / dist
                approach = float((s[j, 3:5] - s[i, 3:5]) @ normal)
                if approach >= 0:
                    continue
                impulse = -(1 + self.e[i] * self.e[j]) * approach / (1 / self.m[i] + 1 / self.m[j])
                self.exchange(i, j, impulse, normal)

    def exchange(self, i: int, j: int, impulse: float, normal: np.ndarray) -> None:
        self.s[i, 3:5] -= impulse * normal / self.m[i]
        self.s[j, 3:5] += impulse * normal / self.m[j]

    def read(self) -> list[float]:
        out: list[float] = self.s.ravel().tolist()
        return out

    def apply_force(self, i: int, fx: float, fy: float) -> None:
        self.f[i, :2] += (fx, fy)

    def apply_torque(self, i: int, tau: float) -> None:
        self.f[i, 2] += tau

    def apply_impulse(self, i: int, jx: float, jy: float) -> None:
        self.s[i, 3:5] += np.array([jx, jy]) / self.m[i]


class BallSimulator(SteppingSimulator):
    """A correct (if crude) engine: passes the kit."""

    name: ClassVar[str] = "balls"

    def __init__(self, gravity_scale: float = 1.0) -> None:
        self.gravity_scale = gravity_scale

    def build(self, scene: Scene) -> EngineWorld:
        return BallWorld(scene, tuple(self.gravity_scale * g for g in scene.gravity))


class NoGravity(BallSimulator):
    def build(self, scene: Scene) -> EngineWorld:
        return BallWorld(scene, (0.0, 0.0))


class MassBlindWorld(BallWorld):
    def exchange(self, i: int, j: int, impulse: float, normal: np.ndarray) -> None:
        self.s[i, 3:5], self.s[j, 3:5] = self.s[j, 3:5].copy(), self.s[i, 3:5].copy()


class MassBlind(BallSimulator):
    """Swaps the velocities of colliding bodies, whatever their masses."""

    def build(self, scene: Scene) -> EngineWorld:
        return MassBlindWorld(scene, scene.gravity)


class Inelastic(BallSimulator):
    def build(self, scene: Scene) -> EngineWorld:
        world = BallWorld(scene, scene.gravity)
        world.e[:] = 0.0
        return world


class IgnoresParams(BallSimulator):
    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        return super().simulate(scene, None, effects=effects)


class IgnoresEffects(BallSimulator):
    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        body = {k: v for k, v in (params or {}).items() if not k.startswith("kit_push.")}
        return super().simulate(scene, body)


class Jittery(BallSimulator):
    def build(self, scene: Scene) -> EngineWorld:
        world = BallWorld(scene, scene.gravity)
        world.s[:, 0] += np.random.default_rng().normal(0, 1e-9, len(world.s))
        return world


class HashDependent(BallSimulator):
    """The same in one process, different in another: a string hash leaks into the state."""

    def build(self, scene: Scene) -> EngineWorld:
        world = BallWorld(scene, scene.gravity)
        world.s[:, 0] += (hash("physbench") % 1000) * 1e-12
        return world


class NeverExplodes(BallSimulator):
    def _check(self, scene: Scene, states: np.ndarray, world: EngineWorld) -> None:
        pass


class ExplodesWithValueError(BallSimulator):
    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        if any(f.kind == "impulse" and abs(f.vector[0]) > 1e6 for f in scene.forces):
            raise ValueError("impulse too large")
        return super().simulate(scene, params, effects=effects)


class SlowClock(BallSimulator):
    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        traj = super().simulate(scene, params, effects=effects)
        return Trajectory(traj.bodies, traj.times * 2, traj.states, engine=self.name)


class DropsTheFirstFrame(BallSimulator):
    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        traj = super().simulate(scene, params, effects=effects)
        return Trajectory(traj.bodies, traj.times[:-1], traj.states[1:], engine=self.name)


class Nameless(BallSimulator):
    name: ClassVar[str] = ""


def test_a_correct_engine_passes() -> None:
    check_simulator(BallSimulator)
    check_simulator(BallSimulator, subprocess=False, gravity_scale=1.0)


@parametrize_with_checks([BallSimulator, Subject(BallSimulator, {"gravity_scale": 1.0}, id="g1")])
def test_a_correct_engine_passes_every_parametrized_check(component: Subject, check: Check) -> None:
    check(component)


def failing_checks(cls: type, **options: object) -> list[str]:
    """The names of the checks ``check_simulator`` reports as failed."""
    try:
        check_simulator(cls, subprocess=False, **options)
    except ConformanceError as exc:
        return re.findall(r"^- (check_\w+):", str(exc), flags=re.MULTILINE)
    return []


@pytest.mark.parametrize(
    ("broken", "check", "message", "also"),
    [
        (
            NoGravity,
            check_free_fall,
            r"free fall: body 'ball' at frame 30 \(t = 1 s\) has y = 5.5, expected 0.595 ± 0.033",
            (),
        ),
        (MassBlind, check_collision, "momentum is not conserved in a collision", ()),
        (
            Inelastic,
            check_collision,
            r"velocities are \[-1.0, -1.0\] m/s, expected \[-4.0, 0.0\]",
            (),
        ),
        (
            IgnoresParams,
            check_applies_params,
            r"with params \{'pushed.mass': 4.0\} body 'pushed' has x = ",
            ("check_applies_effects",),  # the effect's values come through params too
        ),
        (IgnoresEffects, check_applies_effects, "must call each effect's setup", ()),
        (Jittery, check_deterministic, "again with the same instance differs at frame 0", ()),
        (NeverExplodes, check_explosion_raises, r"returned a trajectory \(largest \|position", ()),
        (
            ExplodesWithValueError,
            check_explosion_raises,
            "raised ValueError: impulse too large; raise physbench.errors.SimulationError",
            (),
        ),
        (SlowClock, check_protocol, r"trajectory times \[0.0, 0.0666", ()),
        (
            DropsTheFirstFrame,
            check_protocol,
            r"states \(30, 3, 6\); expected bodies .* and states \(31, 3, 6\)",
            (),
        ),
        (Nameless, check_protocol, "'name' must be a non-empty string", ()),
    ],
)
def test_a_broken_engine_fails_only_its_check_with_a_clear_message(
    broken: type, check: Callable[..., None], message: str, also: tuple[str, ...]
) -> None:
    with pytest.raises(ConformanceError, match=message):
        check(broken)
    if check is check_protocol:
        assert failing_checks(broken) == ["check_protocol"]  # the kit stops there
    else:
        assert set(failing_checks(broken)) == {check.__name__, *also}


def test_an_engine_whose_result_depends_on_the_process_fails_only_in_another_process() -> None:
    check_deterministic(HashDependent)
    with pytest.raises(ConformanceError, match="in another process differs at frame 0"):
        check_deterministic_in_subprocess(HashDependent)


def test_options_reach_the_engine() -> None:
    check_free_fall(BallSimulator, gravity_scale=1.0)
    with pytest.raises(ConformanceError, match=r"has y = .* \(gravity \(0.0, -9.81\) m/s²"):
        check_free_fall(BallSimulator, gravity_scale=1.1)
