"""The stages and their composition (physbench/discover/pipeline.py)."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.discover import (
    CandidateResult,
    DiscoverError,
    Run,
    Settings,
    candidate_specs,
    conclude,
    describe,
    diagnose,
    discover,
    fit_base,
    prune_causes,
    renderer_for,
    select_causes,
    try_effect,
)
from physbench.discover.synthetic import make_case
from physbench.discover.verdict import to_dict
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_the_worked_example_in_the_docs():
    # the calls of docs/discover.md, "Step by step": base fit -> residuals -> one effect
    sim = PymunkSimulator()
    puck = make_case("linear_drag", "puck", 0, sim)  # a puck slowed by hidden linear drag
    settings = Settings()

    base = fit_base([puck.run], sim, settings)  # the scene's model, fitted and scored
    assert base.causes == () and base.heldout > 3 * base.fit.rms  # it cannot predict ahead

    diagnosis = diagnose(base)  # what the base model gets wrong, as numbers
    sentences = [describe(f) for f in diagnosis.findings]
    assert sentences[0].startswith("puck: in free flight the observed speed falls")
    assert "linear_drag" in diagnosis.findings[0].suggests
    assert diagnosis.breakdown.per_event["puck"]["free"] > 0

    trial = try_effect(base, "linear_drag", settings)  # fit base + drag, judge it
    assert isinstance(trial, CandidateResult) and trial.significant
    assert trial.params["c"] == pytest.approx(puck.truth["c"], rel=0.05)

    # the same candidate, fitted inside a whole discovery, has the same numbers
    disc = discover([puck.run], sim, settings=settings)
    inside = next(c for c in disc.candidates if c.round == 1 and c.effect == "linear_drag")
    assert inside.params == trial.params and inside.heldout_error == trial.heldout_error


def test_discover_is_the_composition_of_the_stages(puck):
    settings = Settings(effects=["linear_drag", "quadratic_drag"])
    sim = PymunkSimulator()
    base = fit_base([puck.run], sim, settings)
    specs, skipped = candidate_specs(puck.run.scene, settings)
    staged = conclude(
        prune_causes(select_causes(base, specs, settings, skipped), settings), settings
    )
    whole = discover([puck.run], sim, settings=settings)
    a, b = to_dict(staged), to_dict(whole)
    a.pop("seconds"), b.pop("seconds")
    assert a == b and a["causes"] == ["linear_drag"]


def test_named_effects_that_do_not_apply_are_refused(puck):
    with pytest.raises(DiscoverError, match="none of the requested effects applies"):
        candidate_specs(puck.run.scene, Settings(effects=["joint_viscous_damping"]))


def test_the_renderer_of_frames_is_chosen_by_name_with_mode_and_width_from_the_frames(slide, noisy):
    scene = slide()  # 12 m x 9 m: 48 px wide frames are 36 px high
    mask = renderer_for([Run("r", scene, frames=np.zeros((4, 1, 36, 48), np.float32))])
    assert (type(mask).name, mask.mode, mask.shape(scene)[1:]) == ("raster", "mask", (1, 36, 48))
    mark = renderer_for([Run("r", scene, frames=np.zeros((4, 2, 36, 48), np.float32))], "raster")
    assert mark.mode == "mark"
    with pytest.raises(DiscoverError, match=r"frames have 3 channels"):
        renderer_for([Run("r", scene, frames=np.zeros((4, 3, 36, 48), np.float32))])
    with pytest.raises(DiscoverError, match=r"but the 'raster' renderer in 'mark' mode gives"):
        renderer_for([Run("r", scene, frames=np.zeros((4, 1, 36, 48), np.float32))], mode="mark")
    track = Run("r", scene, recording=noisy(PymunkSimulator().simulate(scene)))
    with pytest.raises(DiscoverError, match="holds tracks, not frames"):
        renderer_for([track])
