"""The verdict as text and JSON (physbench/discover/verdict.py)."""

from __future__ import annotations

import json

import pytest

from physbench.discover import describe
from physbench.discover.verdict import format_value, text, to_dict


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


def test_values_are_shown_to_the_digits_their_error_allows():
    assert format_value(0.41234, 0.0123) == "0.412 ± 0.012"
    assert format_value(12.3456, None) == "12.35"
    assert format_value(0.000123, 0.00001) == "0.000123 ± 1e-05"
