"""The verdict as text and JSON (physbench/discover/verdict.py)."""

from __future__ import annotations

import json

import pytest

from physbench.discover import describe
from physbench.discover.verdict import format_interval, text, to_dict


def test_discovery_finds_linear_drag_and_writes_json_with_the_documented_keys(drag_discovery):
    d = to_dict(drag_discovery)
    assert d["causes"] == ["linear_drag"] and d["gain"] > 0.9
    assert {"base", "candidates", "causes", "gain"} <= set(d)
    for c in d["candidates"]:
        assert {"effect", "params", "heldout_error", "gain", "criterion"} <= set(c)
    chosen = next(c for c in d["candidates"] if c["chosen"])
    assert chosen["params"]["c"] == pytest.approx(0.4, rel=0.05) and chosen["stderr"]["c"] > 0
    json.dumps(d)  # strictly serialisable


def test_findings_are_phrased_in_the_json_and_the_text(drag_discovery):
    d = to_dict(drag_discovery)
    found = drag_discovery.findings["base"]
    assert found and [f["text"] for f in d["findings"]["base"]] == [describe(f) for f in found]
    assert list(d["findings"]["base"][0]) == ["kind", "run", "body", "text", "values", "suggests"]
    assert describe(found[0]) in text(drag_discovery)


def test_values_are_shown_with_their_interval_to_the_digits_it_allows():
    assert format_interval(0.41234, (0.39, 0.4346), "N") == "0.412 N (90 % interval [0.390, 0.435])"
    assert format_interval(0.41234, (0.39, 0.4346), words=False) == "0.412 [0.390, 0.435]"
    assert format_interval(12.3456, None) == "12.35"
    assert format_interval(0.000123, (0.0001, 0.00015)) == (
        "0.000123 (90 % interval [0.0001, 0.00015])"
    )


def test_the_chosen_cause_carries_a_90_percent_interval_in_json_and_text(drag_discovery):
    d = to_dict(drag_discovery)
    chosen = next(c for c in d["candidates"] if c["chosen"])
    low, high = chosen["intervals"]["c"]
    assert low < chosen["params"]["c"] < high and chosen["interval_level"] == 0.9
    assert chosen["interval_method"].startswith("profile likelihood")
    # Wider than the i.i.d. Jacobian ±1.645 stderr is allowed; narrower than a third of it is not.
    assert high - low > 0.3 * 2 * 1.645 * chosen["stderr"]["c"]
    c = drag_discovery.cause_results[0]
    assert format_interval(c.params["c"], c.intervals["c"], "N·s/m") in text(drag_discovery)
    line = next(x for x in text(drag_discovery).splitlines() if x.startswith("  1. linear_drag"))
    assert "90 % interval" in line and "±" not in line
