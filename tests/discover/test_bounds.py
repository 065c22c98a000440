"""Effect ranges that a fit reaches (issue 14): the range widens and the fit goes on, and what is
still at a bound is flagged, never reported as a measurement.

The hidden-effect cases put the effect at 3x the upper end of its declared range, where on a
fixed range a fit stops at the bound, loses to another law and the verdict names the wrong one.
"""

from __future__ import annotations

import pytest

from physbench.discover import Run, Settings, discover
from physbench.discover import fit as fit_module
from physbench.discover.fit import least_squares
from physbench.discover.pipeline import problem_for, start_model
from physbench.discover.synthetic import magnitude_error, make_case
from physbench.discover.verdict import table, text
from physbench.effects import JointCoulombFriction, LinearDrag, VelocityDependentRestitution
from physbench.effects.base import EffectError
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
#: effect -> (scene, body parameters, parameter): the truth is 3x the parameter's declared high.
#: Drag at 30 N·s/m needs a heavy ball (c/m = 0.3 /s) to stay visible without swamping the flight.
BEYOND = {
    "joint_coulomb_friction": ("pendulum", {}, "tau"),
    "joint_viscous_damping": ("pendulum", {}, "c"),
    "linear_drag": ("projectile", {"ball.mass": 100.0}, "c"),
}
#: CI runs each effect on the engines in turn; ``nox -s extended`` the other engine's case.
CASES = [
    pytest.param(
        e,
        eng,
        id=f"{e}/{eng}",
        marks=() if list(ENGINES).index(eng) == k % len(ENGINES) else (pytest.mark.extended,),
    )
    for k, e in enumerate(BEYOND)
    for eng in ENGINES
]


def _case(effect: str, engine: str, seed: int = 0):
    from physbench.plugins import get_registry

    scene, body_params, name = BEYOND[effect]
    high = get_registry().get("effect", effect).param(name).high
    sim = ENGINES[engine]()
    return sim, make_case(effect, scene, seed, sim, truth={name: 3 * high}, body_params=body_params)


@pytest.mark.parametrize(("effect", "engine"), CASES)
def test_an_effect_at_three_times_its_declared_bound_is_named_with_its_magnitude(effect, engine):
    sim, case = _case(effect, engine)
    disc = discover([case.run], sim, diagnose=False)
    assert disc.causes[:1] == [effect], disc.causes
    found = disc.cause_results[0]
    assert magnitude_error(effect, case.truth, found.params) <= 0.15
    assert found.at_bound == ()


def test_a_cause_left_at_its_bound_is_flagged_in_the_verdict(monkeypatch):
    # Without widening, Coulomb friction at 3x its bound loses to viscous damping stuck at its own.
    monkeypatch.setattr(fit_module, "WIDENINGS", 0)
    sim, case = _case("joint_coulomb_friction", "pymunk")
    disc = discover([case.run], sim, diagnose=False)
    first = disc.cause_results[0]
    assert first.at_bound == tuple(first.params) != ()
    assert first.to_dict()["at_bound"] == list(first.params)
    assert "at its bound: " + next(iter(first.params)) in text(disc)
    assert "the true value may be larger" in text(disc)
    assert "CHOSEN*" in table(disc)


@pytest.mark.parametrize("sign", [1, -1])
def test_a_sensor_offset_beyond_its_declared_range_widens_at_either_end(sign):
    sim = PymunkSimulator()
    truth = {"dx": sign * 1.5, "dy": -sign * 1.5, "dangle": 0.0}
    case = make_case("sensor_offset", "pendulum_xy", 0, sim, truth=truth)
    disc = discover([case.run], sim, diagnose=False)
    assert disc.causes[:1] == ["sensor_offset"], disc.causes
    found = disc.cause_results[0]
    assert found.params["dx"] == pytest.approx(sign * 1.5, abs=0.02)
    assert found.params["dy"] == pytest.approx(-sign * 1.5, abs=0.02)
    assert found.at_bound == ()


def _drag_run(c: float, mass: float) -> Run:
    scene = (
        make_case(None, "puck", 0, PymunkSimulator())
        .run.scene.with_params({"puck.mass": mass})
        .validate()
    )
    drag = LinearDrag()
    drag.widen("c", 0.0, 100.0)
    drag.setup(scene, {"c": c})
    traj = PymunkSimulator().simulate(scene, effects=[drag])
    from physbench.recording import Recording

    return Run("r", scene, recording=Recording.from_trajectory(traj, fields=("x", "y")))


def test_a_fit_at_the_end_of_an_extensible_range_widens_it_and_goes_on(monkeypatch):
    settings = Settings()
    for widenings, want_c, flagged in ((0, 10.0, ("linear_drag.c",)), (3, 30.0, ())):
        monkeypatch.setattr(fit_module, "WIDENINGS", widenings)
        base = start_model(problem_for([_drag_run(30.0, 60.0)], "pymunk", settings), settings)
        model = base.extended(LinearDrag())
        fr = least_squares(model, model.free_keys())
        assert fr.at_bound == flagged
        assert model.values["linear_drag.c"] == pytest.approx(want_c, rel=0.02)
    assert model.param("linear_drag.c").high == 100.0
    assert model.effects[-1].parameters()[0].high == 100.0


def test_only_extensible_ranges_widen_and_only_on_the_instance():
    friction = JointCoulombFriction()
    friction.widen("tau", 0.0, 1.0)
    friction._checked({"tau": 0.5})
    with pytest.raises(EffectError, match=r"tau = 0.5: must lie in \[0, 0.1\]"):
        JointCoulombFriction(tau=0.5)
    with pytest.raises(EffectError, match="must be finite and contain"):
        friction.widen("tau", 0.0, 0.5)
    with pytest.raises(EffectError, match="physical limit"):
        VelocityDependentRestitution().widen("e0", 0.0, 10.0)


def test_a_truth_override_keeps_the_scene_and_the_noise_of_the_seed():
    sim = PymunkSimulator()
    drawn = make_case("joint_coulomb_friction", "pendulum", 3, sim)
    big = make_case("joint_coulomb_friction", "pendulum", 3, sim, truth={"tau": 0.3})
    assert big.truth == {"tau": 0.3} and drawn.truth["tau"] < 0.1
    assert big.run.scene == drawn.run.scene
