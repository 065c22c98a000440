"""The committed tracking benchmarks (``results/track``, ``benchmarks/track_accuracy.py``,
``benchmarks/track_shading.py`` and ``benchmarks/track_speed.py``): the figures the docs quote,
held against the issues' bars."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

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


def test_lit_spheres_are_centred_within_a_fifth_of_a_pixel() -> None:
    # Issue 26: a weighted centroid leans 0.7-1.1 px away from a sphere's highlight at 13-22 px
    # radius (here: up to 3.6 px). The outline fit keeps the bias within a fifth of a pixel in
    # raw frames; H.264's halved colour resolution moves a saturated ball's coloured rim, and a
    # white ball's lit limb can be as bright as the wall, so coded frames keep nineteen cases in
    # twenty within 0.3 px, the worst 0.44 px (0.49 px at 6 px radius).
    data = json.loads((RESULTS / "shading.json").read_text())
    rows = {r["radius"]: r for r in data["summary"]}
    assert set(rows) == {6, 13, 17, 22}
    for radius in (13, 17, 22):
        r = rows[radius]
        assert r["cases"] == 128 and r["missed_frames"] == 0
        assert r["bias_median_px"] <= 0.05 and r["bias_p95_px"] <= 0.3 and r["bias_max_px"] <= 0.5
        assert r["centroid_bias_p95_px"] >= 1.5  # what it was: six to twelve times as much
    raw = [abs(c["bias_px"]) for c in data["cases"] if c["radius"] >= 13 and not c["coded"]]
    assert len(raw) == 192 and np.percentile(raw, 95) <= 0.15 and max(raw) <= 0.21


def test_speed_with_either_background_and_flat_memory() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    assert {(c["seconds"], c["background"]) for c in clips} == {
        (s, b) for s in (5, 20) for b in ("plate", "median")
    }
    assert all(0 < c["track_fps"] < c["decode_fps"] for c in clips)
    for background in ("plate", "median"):
        peaks = [c["peak_mib"] for c in clips if c["background"] == background]
        assert max(peaks) <= 1.5 * min(peaks) + 1.0  # four times the frames, the same memory


@pytest.mark.xfail(
    strict=True,
    reason="issue 26's target, not met since the light, outline and appearance stages: the "
    "tracker measures 99-157 frames per CPU second on these clips (206-401 before them)",
)
def test_at_least_200_frames_per_second_of_cpu_time() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    # Frames per second of CPU time (the machine is shared), decoding included.
    assert all(c["track_fps"] >= 200 for c in clips)
