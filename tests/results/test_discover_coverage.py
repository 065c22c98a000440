"""The committed coverage of discovery's 90 % intervals on the hidden-effect cases
(``results/discover_coverage/``, written by ``python benchmarks/discover_coverage.py``). These
tests read the committed files; they do not recompute anything."""

from __future__ import annotations

import json
from pathlib import Path

from physbench.discover.synthetic import EFFECT_SCENES

RESULTS = Path(__file__).resolve().parents[2] / "results" / "discover_coverage"


def _summary() -> dict:
    return json.loads((RESULTS / "summary.json").read_text())


def _rows() -> list[dict]:
    return [json.loads(x) for x in (RESULTS / "cases.jsonl").read_text().splitlines()]


def test_every_hidden_effect_case_of_seeds_0_to_2_in_both_engines_was_run():
    s = _summary()
    assert s["seeds"] == [0, 1, 2] and s["engines"] == ["pymunk", "box2d"]
    want = {
        (e, sc, eng, seed)
        for e, scenes in EFFECT_SCENES.items()
        for sc in scenes
        for eng in s["engines"]
        for seed in s["seeds"]
    }
    got = {(r["effect"], r["scene"], r["engine"], r["seed"]) for r in _rows()}
    assert got == want and s["cases"] == len(want)


def test_the_90_percent_intervals_hold_the_truth_in_85_to_95_percent_of_cases():
    s = _summary()
    named = [r for r in _rows() if r["named"]]
    covered = [r["low"] <= r["truth"] <= r["high"] for r in named]
    assert s["coverage"]["intervals"] == len(named) and s["coverage"]["covered"] == sum(covered)
    assert 0.85 <= s["coverage"]["fraction"] <= 0.95
    assert all(r["low"] <= r["value"] <= r["high"] for r in named)
