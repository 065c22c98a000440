"""The effect kit passes correct effects and catches deliberately broken ones."""

from __future__ import annotations

import re
from typing import Any, ClassVar

import numpy as np
import pytest

from physbench.effects.base import Effect, EffectError
from physbench.parameter import Parameter
from physbench.scene import Scene
from physbench.testing import (
    Check,
    ConformanceError,
    Subject,
    check_effect,
    checks_for,
    parametrize_with_checks,
)
from physbench.testing.effects import (
    active_values,
    check_acts,
    check_defaults_in_range,
    check_engines_agree,
    check_neutral,
    check_protocol,
    check_rejects_out_of_range,
    check_traits,
    check_values_from_params,
    probe_scene,
)
from physbench.trajectory import Trajectory


class Wind(Effect):
    """A correct force effect: ``f`` newtons along x on each selected body."""

    name: ClassVar[str] = "wind"
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("f", -5.0, 5.0, unit="N", default=0.0, doc="force along x"),
    )

    def forces(self, t: float, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f, tau = self.zeros(states.shape[0])
        f[self.sel, 0] = self.force(t)
        return f, tau

    def force(self, t: float) -> float:
        return self.values["f"]


class FixedRestitution(Effect):
    """A correct contact law: every contact gets restitution ``e``; no neutral value."""

    name: ClassVar[str] = "fixed_restitution"
    applies_forces: ClassVar[bool] = False
    changes_contacts: ClassVar[bool] = True
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("e", 0.0, 1.0, default=0.5, doc="restitution of every contact"),
    )

    @classmethod
    def neutral(cls) -> None:
        return None

    def restitution(self, normal_speed: float, a: int, b: int | None) -> float | None:
        return self.values["e"]


class Offset(Effect):
    """A correct measurement effect: the tracked x is off by ``dx``."""

    name: ClassVar[str] = "offset"
    applies_forces: ClassVar[bool] = False
    measures: ClassVar[bool] = True
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("dx", -1.0, 1.0, unit="m", default=0.0, doc="bias of the tracked x"),
    )

    def measure(self, traj: Trajectory) -> Trajectory:
        states = traj.states.copy()
        states[:, :, 0] += self.values["dx"]
        return Trajectory(traj.bodies, traj.times, states, engine=traj.engine)


class DefaultOutside(Wind):
    params: ClassVar[tuple[Parameter, ...]] = (
        Parameter("f", -5.0, 5.0, unit="N", default=7.0, doc="force along x"),
    )

    @classmethod
    def neutral(cls) -> dict[str, float]:
        return {"f": 0.0}


class StoresUnchecked(Wind):
    """Keeps ``f`` itself, so neither the constructor nor setup checks its range."""

    def __init__(self, f: float = 0.0, **kw: Any) -> None:
        super().__init__(**kw)
        self.values["f"] = f

    def setup(self, scene: Scene, values: Any) -> None:
        super().setup(scene, {})
        self.values.update({k.rpartition(".")[2]: v for k, v in values.items()})


class VagueRangeError(Wind):
    def _checked(self, values: Any) -> dict[str, float]:
        try:
            return super()._checked(values)
        except EffectError:
            raise EffectError("wind: bad value") from None


class NotNeutral(Wind):
    def force(self, t: float) -> float:
        return self.values["f"] + 0.1


class ForcesUndeclared(Wind):
    applies_forces: ClassVar[bool] = False


class RestitutionUndeclared(Wind):
    def restitution(self, normal_speed: float, a: int, b: int | None) -> float | None:
        return 0.3


class MeasureUndeclared(Wind):
    def measure(self, traj: Trajectory) -> Trajectory:
        return Trajectory(traj.bodies, traj.times, traj.states + 0.1, engine=traj.engine)


class Inert(Wind):
    def force(self, t: float) -> float:
        return 0.0


class ReadsItsConstructorOnly(Wind):
    """Uses the constructor's value, not the one setup() received."""

    def __init__(self, **kw: Any) -> None:
        super().__init__(**kw)
        self.f = self.values["f"]

    def force(self, t: float) -> float:
        return self.f


class Fading(Wind):
    """Keeps a call count across simulations: the second simulation feels a weaker force."""

    calls = 0

    def force(self, t: float) -> float:
        self.calls += 1
        return self.values["f"] * 0.999**self.calls


class NeedsJointsUndeclared(Wind):
    def configure(self, scene: Scene) -> None:
        if not scene.joints:
            raise EffectError(f"wind needs joints; scene {scene.name!r} has none")


class BadTrait(Wind):
    measures: ClassVar[bool] = 1  # type: ignore[assignment]


class UnknownNeed(Wind):
    scene_needs: ClassVar[tuple[str, ...]] = ("water",)


def failing_checks(cls: type) -> list[str]:
    """The names of the checks ``check_effect`` reports as failed."""
    try:
        check_effect(cls)
    except ConformanceError as exc:
        return re.findall(r"^- (check_\w+):", str(exc), flags=re.MULTILINE)
    return []


def test_correct_effects_pass() -> None:
    check_effect(Wind)
    check_effect(Wind, bodies=["ball"], on_values={"f": -2.0})
    check_effect(FixedRestitution)
    check_effect(Offset)


@parametrize_with_checks(
    [Wind, FixedRestitution, Offset, Subject(Wind, {"label": "gust"}, {"on_values": {"f": 1.0}})]
)
def test_correct_effects_pass_every_parametrized_check(component: Subject, check: Check) -> None:
    check(component)


def test_the_probe_scene_and_the_checks_follow_the_traits() -> None:
    from physbench.effects import JointViscousDamping, VelocityDependentRestitution

    assert probe_scene(Wind).name == "kit_free"
    assert probe_scene(FixedRestitution).name == "kit_contacts"
    assert probe_scene(JointViscousDamping).name == "kit_joints"
    names = [c.name for c in checks_for(VelocityDependentRestitution)]
    assert "check_neutral" not in names and "check_engines_agree" in names
    assert "check_neutral" in [c.name for c in checks_for(Wind)]


def test_on_values_lie_halfway_from_neutral_to_the_farther_bound() -> None:
    from physbench.effects import ClockScale, VelocityDependentRestitution

    assert active_values(Wind) == {"f": 2.5}
    assert active_values(ClockScale) == {"scale": 1.125}
    assert active_values(VelocityDependentRestitution) == {"e0": 0.45, "k": 0.5}
    assert active_values(Wind, {"f": -1.0}) == {"f": -1.0}


@pytest.mark.parametrize(
    ("broken", "check", "message", "also"),
    [
        (
            DefaultOutside,
            check_defaults_in_range,
            r"parameter 'f' has default 7.0, outside its range",
            (),
        ),
        (
            StoresUnchecked,
            check_rejects_out_of_range,
            r"StoresUnchecked\(\*\*\{'f': 15.0\}\) was accepted",
            (),
        ),
        (
            VagueRangeError,
            check_rejects_out_of_range,
            "raised EffectError without naming 'f': wind: bad value",
            (),
        ),
        (
            NotNeutral,
            check_neutral,
            r"at its neutral values \{'f': 0.0\} the effect changes the probe scene 'kit_free'",
            (),
        ),
        (
            ForcesUndeclared,
            check_traits,
            r"declares applies_forces = False, but forces\(\) at \{'f': 2.5\} returns",
            ("check_acts",),  # the engines never call its forces, so it does nothing
        ),
        (
            RestitutionUndeclared,
            check_traits,
            r"declares changes_contacts = False, but restitution\(0.5, 0, None\) returns 0.3",
            (),
        ),
        (
            MeasureUndeclared,
            check_traits,
            r"declares measures = False, but measure\(\) changes the trajectory",
            (),
        ),
        (
            Inert,
            check_acts,
            r"at \{'f': 2.5\} the effect changes nothing on the probe scene 'kit_free'",
            (),
        ),
        (
            ReadsItsConstructorOnly,
            check_values_from_params,
            r"values \{'kit_effect.f': 2.5\} passed through simulate\(params=...\) act "
            "differently",
            (),
        ),
        (
            Fading,
            check_engines_agree,
            r"with \{'f': 2.5\} pymunk and Box2D disagree on the probe scene 'kit_free'",
            (),
        ),
        (
            NeedsJointsUndeclared,
            check_acts,
            r"raised EffectError: wind needs joints; .*declare it in scene_needs",
            ("check_neutral", "check_traits", "check_values_from_params", "check_engines_agree"),
        ),
        (BadTrait, check_protocol, "trait 'measures' must be True or False, got 1", ()),
        (UnknownNeed, check_protocol, r"scene_needs = \('water',\): expected a tuple of", ()),
    ],
)
def test_a_broken_effect_fails_only_its_check_with_a_clear_message(
    broken: type, check: Any, message: str, also: tuple[str, ...]
) -> None:
    with pytest.raises(ConformanceError, match=message):
        check(broken)
    if check is check_protocol:
        assert failing_checks(broken) == ["check_protocol"]  # the kit stops there
    else:
        assert set(failing_checks(broken)) == {check.__name__, *also}
