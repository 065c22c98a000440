"""The committed tracking benchmarks (``results/track``; ``benchmarks/track_accuracy.py``,
``track_shading.py``, ``track_edges.py``, ``track_fast_lit.py``, ``track_pendulum_median.py`` and
``track_speed.py``): the figures
the docs quote, held against the issues' bars."""

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
    # radius (here: up to 3.6 px). Over three walls the outline fit keeps the bias within
    # 0.17-0.18 px in nineteen cases in twenty at 13-22 px: 0.14 px in raw frames, 0.22 px in
    # H.264-coded ones, whose colour at half the resolution bleeds past a rim (edges.json);
    # with those halo edges in the fit, coded frames were 0.30 px.
    data = json.loads((RESULTS / "shading.json").read_text())
    rows = {r["radius"]: r for r in data["summary"]}
    assert set(rows) == {6, 13, 17, 22} and data["gamma"] == 1.0  # the painter's linear light
    assert {c["wall"] for c in data["cases"]} == {0, 1, 2}
    # A black 6 px ball on a warm wall was rejected as another colour in 21 coded frames (its
    # hue is noise): appearance.SAME_COLOUR.
    assert rows[6]["missed_frames"] == 0
    for radius in (13, 17, 22):
        r = rows[radius]
        assert r["cases"] == 384 and r["missed_frames"] == 0
        assert r["bias_median_px"] <= 0.04 and r["bias_p95_px"] <= 0.2 and r["bias_max_px"] <= 0.5
        assert r["centroid_bias_p95_px"] >= 1.5  # what it was: nine to fourteen times as much
    assert rows[6]["bias_p95_px"] > 0.3  # a 6 px ball: not met (docs/video.md)
    raw = [abs(c["bias_px"]) for c in data["cases"] if c["radius"] >= 13 and not c["coded"]]
    assert len(raw) == 576 and np.percentile(raw, 95) <= 0.15 and max(raw) <= 0.25
    coded = [abs(c["bias_px"]) for c in data["cases"] if c["radius"] >= 13 and c["coded"]]
    assert 0.2 < np.percentile(coded, 95) <= 0.23  # coded frames alone: over the bar, said so


def test_under_a_cameras_transfer_coded_frames_are_over_a_fifth_of_a_pixel() -> None:
    # The same cases with the light encoded by a 1/2.2 power, as a camera's BT.709 or sRGB
    # transfer does (track_shading.py --gamma 2.2): raw frames lean less than in linear light,
    # 0.10 px at the 95th percentile at 13-22 px (0.14), coded ones more, 0.24 px (0.22), so
    # 13 px is over the bar (0.22 px) and 17 and 22 px just under it.
    data = json.loads((RESULTS / "shading_gamma22.json").read_text())
    rows = {r["radius"]: r for r in data["summary"]}
    assert data["gamma"] == 2.2 and set(rows) == {6, 13, 17, 22}
    assert all(r["cases"] == 384 and r["missed_frames"] == 0 for r in rows.values())
    assert rows[13]["bias_p95_px"] > 0.2 and rows[6]["bias_p95_px"] > 0.3
    assert rows[17]["bias_p95_px"] <= 0.2 and rows[22]["bias_p95_px"] <= 0.2
    big = [c for c in data["cases"] if c["radius"] >= 13]
    raw = [abs(c["bias_px"]) for c in big if not c["coded"]]
    coded = [abs(c["bias_px"]) for c in big if c["coded"]]
    assert np.percentile(raw, 95) <= 0.11 and max(raw) <= 0.2
    assert 0.2 < np.percentile(coded, 95) <= 0.25 and max(coded) <= 0.45
    # Still an order of magnitude under the centroid's.
    assert all(r["centroid_bias_p95_px"] >= 1.5 for r in rows.values() if r["radius"] >= 13)


def test_what_coded_frames_add_is_the_codings_not_the_shadings() -> None:
    # The same discs painted unshaded (track_shading.py --gamma 2.2 --flat: all ambient light,
    # no highlight). In raw frames they lean 0.04-0.05 px at the 95th percentile at 13-22 px,
    # the shaded spheres 0.09-0.11: that difference is the shading's own. Coded as H.264 at CRF
    # 23 they lean 0.29-0.34 px, more than the shaded spheres (0.23-0.25), worst where the disc
    # is of about the wall's brightness (light grey, steel): the part over the bar is the
    # coding's, for any disc.
    flat = json.loads((RESULTS / "flat_gamma22.json").read_text())
    lit = json.loads((RESULTS / "shading_gamma22.json").read_text())
    assert flat["flat"] and flat["gamma"] == lit["gamma"] == 2.2

    def p95(data: dict, radius: int, coded: bool) -> float:
        cases = [c for c in data["cases"] if c["radius"] == radius and c["coded"] == coded]
        assert len(cases) == 192
        return float(np.percentile([abs(c["bias_px"]) for c in cases], 95))

    for radius in (13, 17, 22):
        assert p95(flat, radius, False) <= 0.05 and p95(lit, radius, False) <= 0.12
        assert p95(lit, radius, False) - p95(flat, radius, False) <= 0.08  # the shading's share
        assert p95(flat, radius, True) > 0.28 and p95(flat, radius, True) > p95(lit, radius, True)


def test_coded_frames_move_a_coloured_rim_outwards_and_the_luma_difference_is_no_cure() -> None:
    # Why coded frames' centres lean (benchmarks/track_edges.py): edge points found from the
    # true centre sit on the rim in raw frames (within 0.04 px, each side's median), and outside
    # it in coded ones, most on the lit side, so a circle through them leans towards the
    # highlight. Edges on the luma difference do not bleed, but a lit limb darker than the
    # sphere further in puts them inside the rim there: their circles lean 1.5 to 7 times as
    # far at the 95th percentile.
    data = json.loads((RESULTS / "edges.json").read_text())
    rows = {(r["radius"], r["coded"], r["difference"]): r for r in data["summary"]}
    assert len(rows) == 8 and all(r["cases"] == 96 for r in rows.values())
    raw = rows[13, False, "colour"]
    assert all(abs(raw[f"{side}_median_px"]) <= 0.04 for side in ("toward", "sides", "away"))
    for radius in (6, 13):
        coded = rows[radius, True, "colour"]
        assert coded["toward_median_px"] >= 0.25 and coded["sides_median_px"] >= 0.15
        assert coded["toward_median_px"] >= coded["away_median_px"] + 0.2
        for is_coded in (False, True):
            luma, colour = rows[radius, is_coded, "luma"], rows[radius, is_coded, "colour"]
            assert luma["toward_median_px"] < 0 and luma["bias_p95_px"] > colour["bias_p95_px"]


def test_a_fast_flat_lit_ball_is_centred_along_its_smear() -> None:
    # A 15 px ball tossed across the field camera's view at 28-32 px a frame, smeared by
    # exposures of 0.15-0.62 of the interval over eight camera seeds: flat-lit, its smear is
    # symmetric about its mid-exposure pose and the centre is within 0.3 px of it along the
    # motion, on average over the flight.
    cases = json.loads((RESULTS / "fast_lit.json").read_text())["cases"]
    flat = [c for c in cases if not c["lit"]]
    assert len(flat) == 8 and all(c["frames"] == 18 for c in cases)
    assert all(abs(c["along_px"]) <= 0.3 for c in flat)
    assert max(c["median_px"] for c in flat) <= 0.65


@pytest.mark.xfail(
    strict=True,
    reason="issue 26: a fast lit ball's centre leans along its smear, by 0.7 and 1.6 px where "
    "the light comes from behind it (camera seeds 15, 16): the shaded leading end's edges fail "
    "the contrast test, and the lit trailing end sets the centre (docs/video.md)",
)
def test_a_fast_lit_ball_is_centred_along_its_smear() -> None:
    cases = json.loads((RESULTS / "fast_lit.json").read_text())["cases"]
    lit = [c for c in cases if c["lit"]]
    assert len(lit) == 8
    assert all(abs(c["along_px"]) <= 0.5 for c in lit)


def test_speed_with_either_background_and_flat_memory() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    assert {(c["seconds"], c["background"]) for c in clips} == {
        (s, b) for s in (5, 20) for b in ("plate", "median")
    }
    assert all(0 < c["track_fps"] < c["decode_fps"] for c in clips)
    for background in ("plate", "median"):
        peaks = [c["peak_mib"] for c in clips if c["background"] == background]
        assert max(peaks) <= 1.5 * min(peaks) + 1.0  # four times the frames, the same memory


def test_against_a_plate_at_least_200_frames_per_second_of_cpu_time() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    plate = [c for c in clips if c["background"] == "plate"]
    assert len(plate) == 2 and all(c["track_fps"] >= 200 for c in plate)
    # Both over a quarter of decoding alone in the same run: the rate is not the machine's alone.
    assert all(c["ratio"] >= 0.25 for c in plate)


def test_with_the_median_the_clip_is_decoded_and_tracked_once() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    median = [c for c in clips if c["background"] == "median"]
    # Both clips' medians hold resting balls. Tracked twice (the code before the scout), they
    # ran at 0.11-0.15 of decoding; found by the scout in the median's own frames, 0.20-0.26.
    assert len(median) == 2 and all(c["ratio"] >= 0.16 for c in median)


def test_at_least_200_frames_per_second_of_cpu_time() -> None:
    clips = json.loads((RESULTS / "speed.json").read_text())["clips"]
    # Frames per second of CPU time (the machine is shared), decoding included, with a plate and
    # with the clip's median: 208 on the 5 s median clip, where the code before gave 178 in the
    # same session (one camera meter, the median taken again in compiled loops, no smear
    # direction in the scout's sparse frames).
    assert len(clips) == 4 and all(c["track_fps"] >= 200 for c in clips)


def test_a_fresh_process_pays_for_the_compiled_loops_once() -> None:
    # Loading numba and the tracker's machine code from its disk cache, and compiling it where
    # the cache is empty (the first run after installing): the startup `physbench track` says
    # it is compiling for, measured by the benchmark in fresh processes.
    once = json.loads((RESULTS / "speed.json").read_text())["once"]
    assert 0 < once["cached_s"] < 2.0
    assert once["cached_s"] < once["compiling_s"] < 120.0


def test_pendulums_against_the_median_are_off_and_the_seen_end_only_helps() -> None:
    # benchmarks/track_pendulum_median.py: 40 field-camera pendulum clips (seeds 0 and 2). The
    # clip's median holds part of an arm; tracked against it mended, the arms' 95th percentiles
    # have a median of 3.4 px against 0.6 px with a plate, and a double pendulum's upper arm is
    # 10-21 px off while its stated accuracy says 0.5-0.57 px: what track's warning says.
    # Measuring a cut-short arm from its seen end lowered 8 of 48 and raised none.
    data = json.loads((RESULTS / "pendulum_median.json").read_text())
    rows = data["rows"]
    assert len(rows) == 40 and data["seeds"] == [0, 2]
    assert all("failure" not in r[way] for r in rows for way in data["ways"])

    def p95(way: str) -> dict[tuple[str, str], float]:
        return {(r["case"], b): e["p95"] for r in rows for b, e in r[way]["centre_px"].items()}

    plate, both, seen = p95("plate"), p95("median, both ends"), p95("median")
    assert len(plate) == len(both) == len(seen) == 48
    assert all(seen[k] <= both[k] for k in seen)
    assert sum(seen[k] < both[k] for k in seen) >= 8
    assert np.median(list(plate.values())) < 1.0 < 3.0 < np.median(list(seen.values()))
    upper = [r["median"] for r in rows if "upper" in r["median"]["held"]]
    assert len(upper) == 8
    assert all(u["centre_px"]["upper"]["p95"] > 10 * u["accuracy_px"]["upper"] for u in upper)
