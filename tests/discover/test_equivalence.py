"""What a recording cannot tell apart (physbench/discover/equivalence.py): rivals of a cause, the
degeneracies by construction, the paired held-out comparison and the setup's priors."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from physbench.discover import Settings, discover
from physbench.discover.equivalence import _prior, beats, degeneracies, noise, paired
from physbench.discover.results import Rival
from physbench.discover.synthetic import make_case
from physbench.discover.verdict import headline, text, to_dict
from physbench.simulators.pymunk_sim import PymunkSimulator

SIM = PymunkSimulator()


def _flight(**distortion):
    return make_case(None, "projectile", 0, SIM, distortion=distortion)


@pytest.fixture(scope="module")
def scaled():
    """A ball's free flight recorded with a length scale 3 % short, and no force."""
    return discover([_flight(calibration_scale={"scale": 0.97}).run], SIM)


@pytest.fixture(scope="module")
def scaled_and_turned():
    """The same flight with the scale 3 % short and the axes turned by 1°."""
    case = _flight(calibration_scale={"scale": 0.97}, axis_rotation={"angle": 0.0175})
    return discover([case.run], SIM)


def test_scale_clock_and_g_are_named_together_in_free_flight(scaled):
    (cause,) = scaled.causes
    amb = scaled.ambiguity(cause)
    assert amb is not None
    names = {n for m in amb.members for n in m}
    # the three one-and-the-same uniform accelerations, whichever the greedy step took
    assert {"calibration_scale", "clock_scale", "constant_force"} <= names
    assert "g" in amb.degeneracies
    assert all(r.same for r in amb.rivals if set(r.names) <= {"calibration_scale", "clock_scale"})
    words = text(scaled)
    assert "cannot tell these explanations apart" in words
    assert "a reference length in the plane of motion" in words and "a known frame rate" in words
    d = to_dict(scaled)
    assert d["named_alone"] == [] and d["indistinguishable"][0]["cause"] == cause
    assert d["indistinguishable"][0]["separate_by"]
    assert "indistinguishable here" in headline(scaled)


def test_a_force_that_scale_and_turn_explain_is_not_named_alone(scaled_and_turned):
    disc = scaled_and_turned
    assert disc.causes[:1] == ["constant_force"]
    amb = disc.ambiguity("constant_force")
    assert amb is not None and not amb.physical_alone
    combined = [r for r in amb.rivals if r.measurement and "axis_rotation" in r.names]
    assert combined and len(combined[0].names) == 2  # a scale (or clock) and the turn together
    assert set(amb.degeneracies) >= {"g", "tilt"}
    assert "is not named alone" in text(disc)
    # the setup's prior: no horizontal force in still air; it is the 1° turn of the axes
    (prior,) = disc.priors
    assert prior.kind == "still_air" and prior.body == "ball"
    assert prior.values["turn"] == pytest.approx(0.0175, abs=0.002)
    assert prior.values["scale"] == pytest.approx(-0.03, abs=0.003)
    assert "in still air no horizontal constant force" in to_dict(disc)["priors"][0]["text"]


def test_a_reference_fixes_scale_and_clock_and_a_real_force_is_named_alone():
    # a pull mostly along g (buoyancy-like): with scale and clock fixed no measurement error
    # can change the size of g, so the force beats every measurement cause
    case = make_case("constant_force", "projectile", 0, SIM, truth={"fx": 0.05, "fy": 0.25})
    disc = discover([case.run], SIM, settings=Settings(references=("scale", "clock")))
    assert disc.causes[:1] == ["constant_force"]
    assert disc.ambiguity("constant_force") is None
    skipped = dict(disc.skipped)
    assert skipped["calibration_scale"].startswith("fixed by a reference")
    assert "known frame rate" in skipped["clock_scale"]
    assert to_dict(disc)["named_alone"] == ["constant_force"]


def test_paired_comparison_of_a_fit_with_itself_and_the_noise(scaled):
    best = scaled.final
    sigma, rho = noise(best)
    assert sigma == pytest.approx(best.fit.rms) and 0.0 <= rho < 1.0
    assert paired(best, best, sigma, rho) == (0.0, True)
    base = scaled.base
    z, same = paired(best, base, sigma, rho)
    assert z > 10 and not same  # the base model misses the whole scale error


def test_a_cause_beats_a_rival_only_beyond_the_noise_and_by_the_margin():
    settings = Settings()
    c = SimpleNamespace(heldout_error=1.0)

    def rival(err: float, z: float) -> Rival:
        return Rival(("x",), ("x",), True, err, z)

    assert beats(c, rival(2.0, 5.0), 0.0, settings)
    assert not beats(c, rival(2.0, 1.0), 0.0, settings)  # within the noise
    assert not beats(c, rival(1.05, 5.0), 0.0, settings)  # beyond the noise but 5 % better
    assert not beats(c, rival(2.0, math.nan), 0.0, settings)  # not comparable: kept
    assert not beats(c, rival(2.0, 5.0), 10.0, settings)  # both below the data's accuracy


def test_degeneracies_by_construction():
    same = Rival(("calibration_scale",), ("calibration_scale",), True, 1.0, 0.0, True)
    turned = Rival(("axis_rotation",), ("axis_rotation",), True, 1.0, 0.0, True)
    apart = Rival(("clock_scale",), ("clock_scale",), True, 1.0, 1.0, False)
    assert degeneracies("constant_force", [same], gravity=True) == ("g",)
    assert degeneracies("constant_force", [same], gravity=False) == ()  # no g from above
    assert degeneracies("constant_force", [apart], gravity=True) == ()  # different predictions
    assert degeneracies("constant_force", [turned], gravity=True) == ("tilt",)
    assert degeneracies("sensor_offset", [turned], gravity=False) == ("angle",)


def test_priors_convert_a_pull_into_the_camera_errors_that_give_it():
    g = np.array([0.0, -9.81])
    side = _prior("constant_force", "ball", np.array([9.81 * math.sin(0.01), 0.0]), g)
    assert side.kind == "still_air"
    assert side.values["turn"] == pytest.approx(0.01, rel=1e-3)
    assert side.values["scale"] == pytest.approx(0.0, abs=1e-4)
    up = _prior("constant_force", "ball", np.array([0.0, 0.2943]), g)  # 3 % less g
    assert up.values["scale"] == pytest.approx(-0.03, rel=1e-6)
    assert up.values["clock"] == pytest.approx(math.sqrt(0.97) - 1)
    top = _prior("table_tilt", "puck", np.array([0.3, 0.4]), np.zeros(2))
    assert top.kind == "level_table" and top.values["slope"] == pytest.approx(0.5 / 9.81)
