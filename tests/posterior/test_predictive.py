"""The posterior predictive check: quiet when the model made the observation, failing when another
model did, with its cost and noise stated and its result in a run's JSON."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.loop import draw_problem
from physbench.observation import simulate_observation
from physbench.posterior import predictive
from physbench.posterior.samples import Posterior
from physbench.render.sensor import SensorModel
from physbench.testing.toy import ToyRenderer, ToySimulator, toy_scene
from physbench.unknowns import ParamSpace


class OtherEngine(ToySimulator):
    """Another engine's physics: the same bodies hop 30 % higher."""

    def simulate(self, scene, params=None, *, effects=()):  # type: ignore[no-untyped-def]
        traj = super().simulate(scene, params, effects=effects)
        start = traj.states[:1, :, 1]
        traj.states[:, :, 1] = start + 1.3 * (traj.states[:, :, 1] - start)
        return traj


def _case(seed: int, engine: ToySimulator, noise: float) -> predictive.PredictiveCheck:
    """A posterior whose draws scatter around the truth as a calibrated one's do (the truth is
    one more draw: the centre is itself drawn around it), checked against an observation that
    ``engine`` made."""
    scene = toy_scene()
    space = ParamSpace.from_scene(scene, ["mass", "elasticity"], ["a"])
    truth, _ = draw_problem(space, seed)
    obs = simulate_observation(
        scene, truth, engine, ToyRenderer(), sensor=SensorModel(noise=noise, seed=seed)
    )
    rng = np.random.default_rng(seed)
    unit = space.to_unit(truth)
    centre = unit + rng.normal(0, 0.02, unit.size)
    post = Posterior.from_unit(space, centre + rng.normal(0, 0.02, (400, unit.size)), "test")
    check = predictive.check(
        post, obs.frames, scene, ToySimulator(), ToyRenderer(), noise=obs.noise, seed=seed
    )
    assert check is not None
    return check


@pytest.mark.parametrize("noise", [0.0, 0.1])
def test_quiet_when_the_model_made_the_observation_failing_when_another_did(noise: float) -> None:
    same = [_case(seed, ToySimulator(), noise) for seed in range(20)]
    other = [_case(seed, OtherEngine(), noise) for seed in range(20)]
    # Under the model, p is uniform on {1/60, ..., 1}: one failure in 20 by chance.
    assert sum(not c.reproduced for c in same) <= 3, [c.p for c in same]
    assert all(not c.reproduced for c in other), [c.p for c in other]
    assert all(c.draws == predictive.DRAWS and c.failed == 0 for c in same)
    assert {c.noise for c in same} == {noise}


def test_the_verdict_names_its_cost_and_p_and_the_json_keeps_it() -> None:
    bad = _case(0, OtherEngine(), 0.1)
    text = bad.describe()
    assert text.startswith(
        "the model does not reproduce the observation (p = 0.017): these intervals assume it does"
    )
    assert "59 simulations" in text
    assert "reproduces the observation" in _case(0, ToySimulator(), 0.1).describe()
    d = bad.to_dict()
    assert d["reproduced"] is False and d["draws"] == 59
    assert predictive.PredictiveCheck.from_dict(d) == bad
    assert "seconds" not in bad.to_dict(timings=False)


def test_unknown_noise_is_estimated_from_the_frames() -> None:
    scene = toy_scene()
    space = ParamSpace.from_scene(scene, ["mass"], ["a"])
    truth, _ = draw_problem(space, 0)
    obs = simulate_observation(
        scene, truth, ToySimulator(), ToyRenderer(), sensor=SensorModel(noise=0.1, seed=0)
    )
    post = Posterior.from_unit(space, np.full((10, 1), 0.5), "test")
    check = predictive.check(post, obs.frames, scene, ToySimulator(), ToyRenderer(), draws=5)
    assert check is not None and check.noise_source == "estimated from the frames"
    assert check.draws == 5
    with pytest.raises(PhysbenchError, match="draws = 1: expected a whole number >= 2"):
        predictive.check(post, obs.frames, scene, ToySimulator(), ToyRenderer(), draws=1)
