"""The committed discovery-from-video table on the second, independent camera
(``results/video_discover_field``, ``benchmarks/video_discover.py --camera field``): the whole
grid ran, each clip in a domain of its own, and what it measured, held against issue 26's targets
(every effect named first within 10 %, no false alarm, no clip refused). The targets are not met;
these tests hold the measured figures and where the misses lie, so that a change that moves them
must update the table and the docs (docs/video.md)."""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

from physbench.discover.synthetic import EFFECT_SCENES, SCENES

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "results" / "video_discover_field"
DATA = json.loads((FOLDER / "results.json").read_text())
ROWS = DATA["rows"]
HIDDEN = [r for r in ROWS if r["effect"]]
CONTROLS = [r for r in ROWS if not r["effect"]]
TOLERANCE = 0.10
#: Balls below this radius (px) are below the noise of this camera in many frames.
TINY = 2.0
#: The scenes whose swinging arm's centre is biased under this camera's gamma and light drift.
ARMS = {"pendulum_xy", "pendulum_both"}


def right(row: dict) -> bool:
    got = row["filmed"]
    if row["effect"] is None:
        return got["causes"] == []
    return (got["causes"] or [])[:1] == [row["effect"]] and got["error"] <= TOLERANCE


def test_every_effect_scene_engine_and_seed_was_filmed_in_a_domain_of_its_own() -> None:
    assert DATA["seeds"] == [0, 1, 2] and DATA["camera_kind"] == "field"
    assert DATA["tolerance"] == TOLERANCE and DATA["code"]
    want = {
        (e, sc, eng, s)
        for e, scenes in EFFECT_SCENES.items()
        for sc in scenes
        for eng in ("pymunk", "box2d")
        for s in DATA["seeds"]
    }
    assert {(r["effect"], r["scene"], r["engine"], r["seed"]) for r in HIDDEN} == want
    assert len(CONTROLS) == len(SCENES) * 2 * len(DATA["seeds"])
    domains = [r["field"]["domain"] for r in ROWS]
    assert len({d["seed"] for d in domains}) == len(ROWS)
    assert {d["texture"] for d in domains} == {"bricks", "planks", "plaster"}
    assert all(18 <= d["crf"] <= 30 and 0.03 <= d["drift"] <= 0.10 for d in domains)
    assert all(r["clean"]["ok"] for r in ROWS)  # the clean tracks: every case right


def test_the_table_is_the_results() -> None:
    table = (FOLDER / "table.md").read_text()
    refused = sum("filmed_failure" in r for r in ROWS)
    assert f"Clips refused (field camera): {refused} of {len(ROWS)}" in table
    alarms = sum(not right(r) for r in CONTROLS if "filmed_failure" not in r)
    assert f"False alarms on controls: {alarms} of {len(CONTROLS)}" in table


def test_bodies_of_two_pixels_or_more_are_right_but_on_a_swinging_arm() -> None:
    big = [r for r in ROWS if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 175)
    wrong = [r for r in big if not right(r) and "filmed_failure" not in r]
    # every wrong answer on a filmed clip: a measurement cause named beside or instead of the
    # truth, where the arm's centre is biased (an expected failure of issue 26's target)
    assert {r["scene"] for r in wrong} == ARMS and len(wrong) == 19
    refused = Counter(r["scene"] for r in big if "filmed_failure" in r)
    assert refused == Counter({"drops": 3, "two_pucks": 1, "puck_kicked": 1, "puck": 1})
    rest = [r for r in big if r["scene"] not in ARMS]
    assert (len(rest), sum(right(r) for r in rest)) == (158, 152)


def test_balls_under_two_pixels_are_mostly_lost_and_every_false_alarm_is_an_arm() -> None:
    tiny = [r for r in ROWS if r["body_px"] < TINY]
    assert (len(tiny), sum(right(r) for r in tiny)) == (70, 15)
    assert sum("filmed_failure" in r for r in tiny) == 51
    alarms = [r for r in CONTROLS if not right(r) and "filmed_failure" not in r]
    assert len(alarms) == 12 and {r["scene"] for r in alarms} == ARMS


def test_the_refused_tiny_balls_are_mostly_absent_from_the_coded_pixels() -> None:
    # benchmarks/field_visibility.py: no tracker, only whether the matched filter responds at a
    # refused small ball's true centre above what it gives at places without it. In 46 of the 51
    # refused clips a ball under 2 px radius is absent in more than a tenth of its frames, so the
    # clip fails the lost-share rule whatever tracks it.
    vis = json.loads((FOLDER / "visibility.json").read_text())
    refused = {
        f"{r['effect'] or 'control'}/{r['scene']}/{r['engine']}/{r['seed']}"
        for r in ROWS
        if r["field"].get("failure") and r["body_px"] < 2.5
    }
    cases = {row["case"] for row in vis["rows"]}
    assert cases == refused and len(cases) == 51
    worst: dict[str, float] = {}
    for row in vis["rows"]:
        assert row["radius_px"] < TINY and row["in_view"] == 41
        worst[row["case"]] = max(worst.get(row["case"], 0.0), row["absent"] / row["in_view"])
    assert sum(v > 0.10 for v in worst.values()) == vis["summary"]["clips_absent_over_10pct"] == 46


def test_the_arms_rerun_holds_what_each_tracker_gave() -> None:
    # results/video_discover_field/pendulum_rerun (benchmarks/field_rerun.py): the 42 swinging-arm
    # clips of the grid, rerun with the camera's gamma decoded and then with the arm's faint far
    # end measured too. Its summaries follow from its rows, and the rows of its first stage are
    # the grid's.
    data = json.loads((FOLDER / "pendulum_rerun.json").read_text())
    stages = data["stages"]
    assert [s["name"] for s in stages] == [
        "before (results.json)",
        "gamma decoded",
        "+ faint end",
    ]
    key = "{effect}/{scene}/{engine}/{seed}"
    grid = {key.format(**r): r for r in ROWS if r["scene"] in ARMS}
    assert {key.format(**r): r for r in stages[0]["rows"]} == grid and len(grid) == 42
    got = []
    for s in stages:
        rows = s["rows"]
        assert not any(r["field"].get("failure") for r in rows)
        summary = {
            "right": sum(right(r) for r in rows),
            "false_alarms": sum(1 for r in rows if not r["effect"] and r["filmed"]["causes"]),
        }
        assert summary.items() <= s["summary"].items(), s["name"]
        got.append((summary["right"], summary["false_alarms"], s["summary"]["centre_px_median"]))
    assert got == [(23, 12, 3.5), (26, 11, 1.99), (33, 8, 1.13)]


def test_the_drops_rerun_has_no_refused_clip() -> None:
    # results/video_discover_field/drops_rerun: the 12 clips of two balls dropped onto a floor,
    # rerun since a body that hits a surface is predicted to bounce off it. Three were refused
    # in the grid (a ball lost for the 6 frames of its rise); rerun, all 12 are right.
    stages = json.loads((FOLDER / "drops_rerun.json").read_text())["stages"]
    key = "{effect}/{scene}/{engine}/{seed}"
    grid = {key.format(**r): r for r in ROWS if r["scene"] == "drops"}
    assert {key.format(**r): r for r in stages[0]["rows"]} == grid and len(grid) == 12
    assert sum(1 for r in grid.values() if r["field"].get("failure")) == 3
    rerun = stages[-1]["rows"]
    assert not any(r["field"].get("failure") for r in rerun)
    assert all(right(r) for r in rerun) and len(rerun) == 12
