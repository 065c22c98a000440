"""Greedy selection of causes and the backward check (physbench/discover/select.py)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from physbench.discover import (
    CandidateResult,
    CandidateSpec,
    Selection,
    Settings,
    prune_causes,
    select_causes,
    try_effect,
)


def test_the_significant_candidate_is_added_and_the_rest_refitted_on_top(puck, puck_base):
    specs = [CandidateSpec(n) for n in ("linear_drag", "quadratic_drag", "rolling_resistance")]
    sel = select_causes(puck_base, specs, Settings(), [("clock_scale", "no force")])
    assert sel.causes == ["linear_drag"] and sel.skipped == [("clock_scale", "no force")]
    first = [c for c in sel.candidates if c.round == 1]
    assert [c.effect for c in first] == ["linear_drag", "quadratic_drag", "rolling_resistance"]
    (chosen,) = [c for c in sel.candidates if c.chosen]
    assert chosen.effect == "linear_drag" and chosen.scored is sel.final
    # round 2 tries the others with a held-out gain on top of the cause; none is significant
    later = [c for c in sel.candidates if c.round == 2]
    assert later and all(not c.significant and c.previous is sel.final for c in later)
    assert sel.gain == pytest.approx(1 - sel.final.heldout / sel.base.heldout)
    one = select_causes(puck_base, specs, Settings(max_causes=1))
    assert one.causes == ["linear_drag"] and {c.round for c in one.candidates} == {1}


def test_a_cause_that_a_later_one_made_redundant_is_dropped(puck_base):
    # quadratic drag first, then linear drag on top: the truth (linear) alone does as well
    s = Settings()
    quad = try_effect(puck_base, "quadratic_drag", s)
    assert isinstance(quad, CandidateResult) and quad.scored is not None
    lin = try_effect(quad.scored, "linear_drag", s, base=puck_base, round=2)
    assert isinstance(lin, CandidateResult) and lin.scored is not None
    chosen = [replace(quad, chosen=True), replace(lin, chosen=True)]
    sel = Selection(puck_base, lin.scored, chosen, ["quadratic_drag", "linear_drag"], {}, [])
    pruned = prune_causes(sel, s)
    assert pruned.causes == ["linear_drag"] and pruned.final.causes == ("linear_drag",)
    dropped, kept = pruned.candidates
    assert not dropped.chosen and kept.chosen
    assert dropped.note.startswith("added in round 1, then dropped: without it the other causes")
    assert pruned.final.heldout <= lin.scored.heldout
    assert sel.causes == ["quadratic_drag", "linear_drag"]  # the input is not changed
