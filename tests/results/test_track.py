"""The committed tracking benchmarks (``results/track``, ``benchmarks/track_accuracy.py`` and
``benchmarks/track_speed.py``): the figures docs/results.md quotes, held against the issue's
bars."""

from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "track"


def test_accuracy_over_20_seeds_of_2_to_6_balls_on_both_engines() -> None:
    data = json.loads((RESULTS / "accuracy.json").read_text())
    cases = data["cases"]
    for engine in ("pymunk", "box2d"):
        mine = [c for c in cases if c["engine"] == engine]
        assert sorted(c["seed"] for c in mine) == list(range(20))
        assert {c["balls"] for c in mine} == {2, 3, 4, 5, 6}
        summary = data["summary"][engine]
        assert summary["median_px"] <= 0.5 and summary["p95_px"] <= 1.5
        assert summary["swaps"] == 0 and summary["missed"] == 0
        assert sum(c["swaps"] for c in mine) == 0


def test_speed_with_either_background_and_flat_memory() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    assert {(c["seconds"], c["background"]) for c in clips} == {
        (s, b) for s in (5, 20) for b in ("plate", "median")
    }
    assert all(200 <= c["track_fps"] < c["decode_fps"] for c in clips)
    for background in ("plate", "median"):
        peaks = [c["peak_mib"] for c in clips if c["background"] == background]
        assert max(peaks) <= 1.5 * min(peaks) + 1.0  # four times the frames, the same memory
