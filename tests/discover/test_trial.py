"""Trying one effect on top of a fitted model (physbench/discover/trial.py)."""

from __future__ import annotations

import math

import pytest

from physbench.discover import CandidateResult, Settings, Skipped, try_effect
from physbench.discover.candidates import CandidateSpec


def test_an_effect_is_fitted_on_top_of_the_model_and_judged(puck, puck_base):
    c = try_effect(puck_base, "linear_drag", Settings())
    assert isinstance(c, CandidateResult) and c.significant and c.previous is puck_base
    assert c.params["c"] == pytest.approx(puck.truth["c"], rel=0.05)
    assert c.scored is not None and c.scored.causes == ("linear_drag",)
    assert c.heldout_error < 0.1 * puck_base.heldout and c.gain > 0.9
    assert c.shift is None  # drag changes the motion, not what is measured of it


def test_parameters_the_data_cannot_see_stay_fixed_and_invisible_effects_are_skipped(
    puck_base,
):
    offset = try_effect(puck_base, CandidateSpec("sensor_offset"))
    assert isinstance(offset, CandidateResult)
    assert set(offset.params) == {"dx", "dy"} and offset.fixed == {"dangle": 0.0}  # x, y tracked
    # a sensor's bias moves every recorded position by its fitted (dx, dy), and no angle
    assert offset.shift is not None
    assert offset.shift[0] == pytest.approx(math.hypot(offset.params["dx"], offset.params["dy"]))
    assert offset.shift[1] == 0.0
    bounce = try_effect(puck_base, "velocity_dependent_restitution")  # nothing to hit
    assert bounce == Skipped(
        "velocity_dependent_restitution", "none of its parameters changes the fitted data"
    )
