"""The committed discovery-from-video table on the second, independent camera
(``results/video_discover_field``, ``benchmarks/video_discover.py --camera field``): the whole
grid ran, each clip in a domain of its own, and what it measured, held against issue 26's targets
(every effect named first within 10 %, no false alarm, no clip refused). The targets are not met;
these tests hold the measured figures and where the misses lie, so that a change that moves them
must update the table and the docs (docs/video.md). ``earlier/`` holds the grid before the arms
were centred between their ends, with the reruns and the visibility study made against it;
``hires_1280/`` the small-ball clips filmed at twice the resolution; ``heldout_3_4/`` seeds 3 and
4, run once after the tracker changes that seeds 0-2 guided; ``rerun_c5024ee/`` the whole grid
again, on a later machine, with a small disc's codec ghost no longer followed;
``corner_bounces/`` that rerun's bouncers and drops with both frames of a corner bounce left
out."""

from __future__ import annotations

import json
from pathlib import Path

from physbench.discover.synthetic import EFFECT_SCENES, SCENES

ROOT = Path(__file__).resolve().parents[2]
FOLDER = ROOT / "results" / "video_discover_field"
EARLIER = FOLDER / "earlier"
DATA = json.loads((FOLDER / "results.json").read_text())
ROWS = DATA["rows"]
HIDDEN = [r for r in ROWS if r["effect"]]
CONTROLS = [r for r in ROWS if not r["effect"]]
EARLIER_ROWS = json.loads((EARLIER / "results.json").read_text())["rows"]
HELDOUT = json.loads((FOLDER / "heldout_3_4" / "results.json").read_text())
RERUN = json.loads((FOLDER / "rerun_c5024ee" / "results.json").read_text())
CORNERS = json.loads((FOLDER / "corner_bounces" / "results.json").read_text())
LATEST = json.loads((FOLDER / "rerun_62408a0" / "results.json").read_text())
TOLERANCE = 0.10
#: Balls below this radius (px) are below the noise of this camera in many frames.
TINY = 2.0
#: The scenes whose swinging arm's centre was biased under this camera's gamma and light drift.
ARMS = {"pendulum_xy", "pendulum_both"}
#: Every scene with a turning arm.
TURNING = ARMS | {"pendulum", "pendulum_large", "double_pendulum"}


def name(row: dict) -> str:
    return f"{row['effect'] or 'control'}/{row['scene']}/{row['engine']}/{row['seed']}"


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


def test_bodies_of_two_pixels_or_more_are_right_but_one_magnitude_at_the_line() -> None:
    big = [r for r in ROWS if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 199)
    # None refused: the three pucks on bricks refused before (a threshold of six robust
    # deviations above most of their pixels) are found since a faint disc brings it down to
    # the background's own tail, and a light puck beside a dark one is seeded by its own
    # contrast (docs/video.md).
    assert not any("filmed_failure" in r for r in big)
    for case in ("quadratic_drag/puck/pymunk/2", "table_tilt/two_pucks/box2d/0"):
        assert right(next(r for r in big if name(r) == case))
    # The one miss: a 6 % calibration scale named first, its magnitude 10.4 % off (10.7 % before
    # the halo rule, 8.7 % in the grid before that): a weak measurement effect at the line.
    wrong = [r for r in big if not right(r)]
    assert [(name(r), r["filmed"]["causes"]) for r in wrong] == [
        ("calibration_scale/puck_kicked/pymunk/1", ["calibration_scale"])
    ]
    assert wrong[0]["filmed"]["error"] < 0.11


def test_every_turning_arm_is_right_since_it_is_centred_between_its_ends() -> None:
    arms = [r for r in ROWS if r["scene"] in TURNING]
    assert len(arms) == 90 and all(right(r) for r in arms)
    before = [r for r in EARLIER_ROWS if r["scene"] in TURNING]
    assert sum(right(r) for r in before) == 71  # 12 false alarms and 7 wrong, all on ARMS
    centre = sorted(r["field"]["centre_px"]["arm"]["median"] for r in arms if r["scene"] in ARMS)
    assert centre[len(centre) // 2] < 0.3  # the clips' median arm centre, px (3.5 before)


def test_balls_under_two_pixels_are_mostly_lost() -> None:
    tiny = [r for r in ROWS if r["body_px"] < TINY]
    assert (len(tiny), sum(right(r) for r in tiny)) == (70, 17)
    assert sum("filmed_failure" in r for r in tiny) == 50


def test_no_control_raises_a_false_alarm() -> None:
    # The bouncing-ball control named clock_scale before: after a bounce its smear was fitted
    # along the direction before the bounce (the first frame after it 1.7 px off). Its stadium
    # is now kept only where it fits better than a circle, else searched over twelve
    # directions: that frame is 0.9 px off, the next is left out at the wall's bounce, and the
    # one after, whose exposure may span that bounce, is 1.7 px off (1.3 before). The alarm is
    # not gone for good: the same clip coded on a later machine names lens_distortion (below).
    alarms = [r for r in CONTROLS if not right(r) and "filmed_failure" not in r]
    assert alarms == []
    bouncer = next(r for r in CONTROLS if name(r) == "control/bouncer/pymunk/0")
    assert right(bouncer) and bouncer["field"]["centre_px"]["ball"]["max"] < 1.7


def test_the_refused_tiny_balls_are_mostly_absent_from_the_coded_pixels() -> None:
    # benchmarks/field_visibility.py: no tracker, only whether the matched filter responds at a
    # refused small ball's true centre above what it gives at places without it. Measured on
    # the earlier grid's 51 refused clips; this grid refuses 50 of them (the same clips, each in
    # its own domain). In 46 a ball under 2 px radius is absent in more than a tenth of its
    # frames, so the clip fails the lost-share rule whatever tracks it. The one no longer
    # refused held its balls in every frame: its heavier ball had been lost after the two
    # touched (the lighter measured on its disc), and it is right now.
    vis = json.loads((EARLIER / "visibility.json").read_text())
    refused = {name(r) for r in ROWS if r["field"].get("failure") and r["body_px"] < 2.5}
    before = {name(r) for r in EARLIER_ROWS if r["field"].get("failure") and r["body_px"] < 2.5}
    cases = {row["case"] for row in vis["rows"]}
    assert cases == before and len(cases) == 51
    assert cases - refused == {"control/two_projectiles/pymunk/2"} and len(refused) == 50
    assert right(next(r for r in ROWS if name(r) == "control/two_projectiles/pymunk/2"))
    worst: dict[str, float] = {}
    for row in vis["rows"]:
        assert row["radius_px"] < TINY and row["in_view"] == 41
        worst[row["case"]] = max(worst.get(row["case"], 0.0), row["absent"] / row["in_view"])
    assert sum(v > 0.10 for v in worst.values()) == vis["summary"]["clips_absent_over_10pct"] == 46
    assert worst["control/two_projectiles/pymunk/2"] == 0.0


def test_keeping_the_refused_tracks_with_their_gaps_gives_few_right_answers() -> None:
    # results/video_discover_field/allow_gaps (--allow-gaps --refused-in results.json): the 50
    # refused clips, tracked again keeping the gappy tracks. 14 are still refused in the first
    # frame, where gaps do not apply, and 6 leave too few samples for discover. Of the 21 effect
    # clips discovered, 4 are right, 4 are named but 12-28 % off, 8 name no cause and 5 name
    # another cause first; the 9 controls discovered are quiet. Refusing these clips costs 4
    # right answers and 9 quiet controls; keeping them would give 5 wrong causes.
    gaps = json.loads((FOLDER / "allow_gaps" / "results.json").read_text())
    rows = gaps["rows"]
    assert gaps["allow_gaps"] is True and gaps["tolerance"] == TOLERANCE
    assert {name(r) for r in rows} == {name(r) for r in ROWS if "filmed_failure" in r}
    failures = [r["filmed_failure"] for r in rows if "filmed_failure" in r]
    assert sum(f.startswith("BodyNotFoundError") for f in failures) == 14
    assert sum(f.startswith("DiscoverError") for f in failures) == 6 == len(failures) - 14
    found = [r for r in rows if r["effect"] and "filmed_failure" not in r]
    first = [(r["filmed"]["causes"] or [None])[0] for r in found]
    named = [r for r, c in zip(found, first, strict=True) if c == r["effect"]]
    assert (len(found), sum(right(r) for r in found), len(named)) == (21, 4, 8)
    assert max(r["filmed"]["error"] for r in named) < 0.3
    assert first.count(None) == 8
    controls = [r for r in rows if not r["effect"] and "filmed_failure" not in r]
    assert len(controls) == 9 and all(right(r) for r in controls)


def test_at_twice_the_resolution_half_the_refused_small_balls_are_right() -> None:
    # results/video_discover_field/hires_1280: the 70 clips of balls under 2 px radius, filmed
    # at 1280x960 in the same domains (balls of 1.7-3.9 px): 40 right, 25 refused (50 at
    # 640x480), no false alarm. In 22 of the 25 refused, a ball is absent from the coded pixels
    # in more than a tenth of its frames; the other 3 are the tracker's misses. The 18 two-ball
    # clips were rerun after two balls side by side stopped sharing one disc and kept their
    # identities where they collide: 7 right (4 before);
    # the heavier ball (3-3.7 px, in the coded pixels in 36-41 of 41 frames) is lost in over a
    # tenth of its frames in 2 of them (6 before), the lighter one in all 10 refused.
    hires = json.loads((FOLDER / "hires_1280" / "results.json").read_text())
    rows = hires["rows"]
    assert hires["resolution"] == 1280
    assert {name(r) for r in rows} == {name(r) for r in ROWS if r["body_px"] < TINY}
    refused = {name(r) for r in rows if "filmed_failure" in r}
    alarms = [r for r in rows if not r["effect"] and not right(r) and "filmed_failure" not in r]
    assert (sum(right(r) for r in rows), len(refused), len(alarms)) == (40, 25, 0)
    two = [r for r in rows if r["scene"] == "two_projectiles"]
    assert sum(right(r) for r in two) == 7
    failures = [r["filmed_failure"] for r in two if "filmed_failure" in r]
    assert len(failures) == 10 and all("body 'light'" in f for f in failures)
    assert sum("body 'heavy' was lost" in f for f in failures) == 2
    vis = json.loads((FOLDER / "hires_1280" / "visibility.json").read_text())
    assert vis["summary"]["resolution"] == 1280
    worst: dict[str, float] = {}
    for row in vis["rows"]:
        worst[row["case"]] = max(worst.get(row["case"], 0.0), row["absent"] / row["in_view"])
    assert set(worst) == refused
    assert sum(v > 0.10 for v in worst.values()) == vis["summary"]["clips_absent_over_10pct"] == 22
    assert {c for c, v in worst.items() if v <= 0.10} == {
        "axis_rotation/projectile_kicked/box2d/1",
        "control/projectile/box2d/2",
        "control/projectile_kicked/box2d/1",
    }


def test_the_arms_rerun_holds_what_each_tracker_gave() -> None:
    # results/video_discover_field/earlier/pendulum_rerun (benchmarks/field_rerun.py): the 42
    # swinging-arm clips of the earlier grid, rerun with the camera's gamma decoded and then
    # with the arm's faint far end measured too. Its summaries follow from its rows, and the
    # rows of its first stage are the earlier grid's.
    data = json.loads((EARLIER / "pendulum_rerun.json").read_text())
    stages = data["stages"]
    assert [s["name"] for s in stages] == [
        "before (results.json)",
        "gamma decoded",
        "+ faint end",
    ]
    key = "{effect}/{scene}/{engine}/{seed}"
    grid = {key.format(**r): r for r in EARLIER_ROWS if r["scene"] in ARMS}
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
    # results/video_discover_field/earlier/drops_rerun: the 12 clips of two balls dropped onto a
    # floor, rerun since a body that hits a surface is predicted to bounce off it. Three were
    # refused in the earlier grid (a ball lost for the 6 frames of its rise); rerun, all 12 are
    # right, as in the grid now.
    stages = json.loads((EARLIER / "drops_rerun.json").read_text())["stages"]
    key = "{effect}/{scene}/{engine}/{seed}"
    grid = {key.format(**r): r for r in EARLIER_ROWS if r["scene"] == "drops"}
    assert {key.format(**r): r for r in stages[0]["rows"]} == grid and len(grid) == 12
    assert sum(1 for r in grid.values() if r["field"].get("failure")) == 3
    rerun = stages[-1]["rows"]
    assert not any(r["field"].get("failure") for r in rerun)
    assert all(right(r) for r in rerun) and len(rerun) == 12
    assert all(right(r) for r in ROWS if r["scene"] == "drops")


def test_on_seeds_the_tracker_was_not_tuned_on_bodies_of_two_pixels_or_more_are_mostly_right() -> (
    None
):
    """Seeds 3 and 4, every effect, scene and engine with controls (180 clips, rerun in full at
    git ca4c5a4, the tracker of the grid above): bodies of 2 px or more right in 131 of 134 (199
    of 200 on seeds 0-2); one refused, a ball of 2.1 px; no false alarm. The two wrong: a lens
    distortion 13.2 % off on two pucks, and a bouncer's restitution 11.4 % off (6.8 % from its
    clean track). Balls under 2 px: 27 of 46 refused (30 at git d648fb7)."""
    rows = HELDOUT["rows"]
    assert HELDOUT["seeds"] == [3, 4] and len(rows) == 180
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (134, 131)
    refused = [r for r in big if "filmed_failure" in r]
    assert [name(r) for r in refused] == ["clock_scale/projectile_kicked/box2d/4"]
    assert refused[0]["body_px"] < 2.2
    wrong = sorted(name(r) for r in big if not right(r) and "filmed_failure" not in r)
    assert wrong == [
        "lens_distortion/two_pucks/box2d/3",
        "velocity_dependent_restitution/bouncer/box2d/4",
    ]
    alarms = [r for r in rows if not r["effect"] and not right(r) and "filmed_failure" not in r]
    assert alarms == [] and sum(not r["effect"] for r in rows) == 60
    small = [r for r in rows if r["body_px"] < TINY]
    assert (len(small), sum("filmed_failure" in r for r in small)) == (46, 27)
    assert HELDOUT["code"] == "git ca4c5a4"


def test_the_near_search_tracks_two_refused_small_balls_at_twice_the_resolution() -> None:
    # benchmarks/faint_near.py on the 25 refused clips of hires_1280 (3 refused in their first
    # frame either way): a small disc looked for near its prediction before its whole gate.
    # Two of the three clips whose ball is in the coded pixels in over nine tenths of its frames
    # (the tracker's misses above) are no longer refused; the frames it adds lie 0.1-3.5 px
    # from the truth, and it loses 2 frames elsewhere.
    near = json.loads((FOLDER / "hires_1280" / "near_search.json").read_text())
    s = near["summary"]
    assert (s["resolution"], s["clips"], s["refused_in_first_frame"]) == (1280, 25, 3)
    assert (s["refused_without"], s["refused_with"]) == (22, 20)
    assert s["frames_gained"] == 21 and s["frames_dropped"] == 2
    assert s["gained_error_max_px"] < 4.0 and s["gained_error_median_px"] < 1.5
    now = {r["case"] for r in near["rows"] if "bodies" in r and not r["refused_with"]}
    assert now == {"axis_rotation/projectile_kicked/box2d/1", "control/projectile/box2d/2"}
    for row in near["rows"]:
        for body in row.get("bodies", {}).values():
            assert body["seen_with"] >= body["seen_without"] - 2
    # Discovered again (near_rerun/, the three clips of the tracker's misses): the control is
    # right, the rotated axis is named first but 10.7 % off (the line is 10 %), the third is
    # still refused.
    rerun = json.loads((FOLDER / "hires_1280" / "near_rerun" / "results.json").read_text())
    got = {name(r): r for r in rerun["rows"]}
    assert right(got["control/projectile/box2d/2"])
    axis = got["axis_rotation/projectile_kicked/box2d/1"]["filmed"]
    assert axis["causes"][:1] == ["axis_rotation"] and 0.10 < axis["error"] < 0.11
    assert "filmed_failure" in got["control/projectile_kicked/box2d/1"]


def _centre_max(row: dict) -> float:
    return max(st["max"] for st in row["field"]["centre_px"].values())


def test_a_small_balls_imprint_is_refused_not_followed_in_the_rerun() -> None:
    # The grid's two worst tracks followed a 1 px ball's imprint where it had been (kept by the
    # codec's skipped blocks), 311 and 325 px off, one of them a control counted right. At git
    # c5024ee (the ghost rule) both clips are refused, and no tracked clip of a ball or puck is
    # further than 6.6 px off anywhere.
    by = {name(r): r for r in RERUN["rows"]}
    assert {name(r) for r in ROWS} == set(by) and RERUN["code"] == "git c5024ee"
    assert RERUN["environment"]["av"] and RERUN["environment"]["ffmpeg"]
    for case in ("control/projectile/box2d/1", "table_tilt/two_projectiles/pymunk/0"):
        grid = next(r for r in ROWS if name(r) == case)
        assert _centre_max(grid) > 300 and "filmed_failure" not in grid
        assert "filmed_failure" in by[case]
    flights = [r for r in by.values() if "pendulum" not in r["scene"] and r["field"]["centre_px"]]
    assert max(_centre_max(r) for r in flights) < 7.0
    tiny = [r for r in by.values() if r["body_px"] < TINY]
    assert (sum("filmed_failure" in r for r in tiny), sum(right(r) for r in tiny)) == (51, 16)


def test_the_rerun_on_another_machine_moves_big_balls_verdicts_at_the_line() -> None:
    # The same code codes other clips on another machine or PyAV build: git 4a62f1e, run here,
    # tracks the bouncing-ball control 1.03 px off at the 95th percentile (0.83 in the grid) and
    # names lens_distortion; two bouncers name a second cause after the right one. Bodies of 2
    # px or more: 198 of 200 right (199 in the grid), none refused.
    rows = RERUN["rows"]
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 198)
    assert not any("filmed_failure" in r for r in big)
    alarms = [
        (name(r), r["filmed"]["causes"])
        for r in rows
        if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == [("control/bouncer/pymunk/0", ["lens_distortion"])]
    extra = sorted(name(r) for r in big if r["effect"] and len(r["filmed"]["causes"] or []) > 1)
    assert extra == [
        "velocity_dependent_restitution/bouncer/box2d/0",
        "velocity_dependent_restitution/bouncer/pymunk/1",
    ]


def test_leaving_out_both_frames_of_a_corner_bounce_quiets_the_bouncer_control() -> None:
    # The rerun's bouncers and drops (24 clips, its library versions), tracked again leaving
    # out both frames of a bounce into a corner: its false alarm is gone and one of its two
    # second causes; every other verdict is the rerun's.
    rows = CORNERS["rows"]
    assert len(rows) == 24 and {r["scene"] for r in rows} == {"bouncer", "drops"}
    assert all(right(r) for r in rows) and not any("filmed_failure" in r for r in rows)
    before = {name(r): r["filmed"]["causes"] for r in RERUN["rows"]}
    changed = sorted(name(r) for r in rows if r["filmed"]["causes"] != before[name(r)])
    assert changed == ["control/bouncer/pymunk/0", "velocity_dependent_restitution/bouncer/box2d/0"]
    extra = [name(r) for r in rows if r["effect"] and len(r["filmed"]["causes"]) > 1]
    assert extra == ["velocity_dependent_restitution/bouncer/pymunk/1"]


def test_the_whole_grid_at_62408a0_refuses_only_tiny_balls_and_has_no_false_alarm() -> None:
    # The whole grid again at git 62408a0 (corner bounces left out, the sparse median): 51 of
    # 270 clips refused as before, all of them balls under 2 px; the bouncer control's false
    # alarm is gone, so no control names a cause and 199 of 200 bigger bodies are right (198 at
    # c5024ee).
    rows = LATEST["rows"]
    assert LATEST["code"] == "git 62408a0" and {name(r) for r in rows} == {name(r) for r in ROWS}
    assert sum("filmed_failure" in r for r in rows) == 51
    assert all(r["body_px"] < TINY for r in rows if "filmed_failure" in r)
    alarms = [
        name(r) for r in rows if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == []
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 199)


def test_the_whole_grid_at_992b068_names_no_second_cause_on_a_body_of_2_px_or_more() -> None:
    # The whole grid again at git 992b068: a measurement effect within the data's stated
    # accuracy is no cause, and a small ball's search passes by the first frame's fixed spots.
    # The bouncers' sensor offsets of under a millimetre (box2d/2 here, pymunk/1 at 62408a0) are
    # gone, so no effect clip of a body of 2 px or more names anything after its cause; 199 of
    # 200 of them right as before, no false alarm. 52 clips refused, all balls under 2 px: one
    # more than at 62408a0, a 1.3 px control lost in 8 of 41 frames (7 before, at the 10 % line).
    rerun = json.loads((FOLDER / "rerun_992b068" / "results.json").read_text())
    rows = rerun["rows"]
    assert rerun["code"] == "git 992b068" and {name(r) for r in rows} == {name(r) for r in ROWS}
    refused = [r for r in rows if "filmed_failure" in r]
    assert len(refused) == 52 and all(r["body_px"] < TINY for r in refused)
    newly = {name(r) for r in refused} - {name(r) for r in LATEST["rows"] if "filmed_failure" in r}
    assert newly == {"control/projectile_kicked/pymunk/0"}
    alarms = [
        name(r) for r in rows if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == []
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 199)
    assert [name(r) for r in big if r["effect"] and len(r["filmed"]["causes"] or []) > 1] == []
    then = {name(r): r["filmed"]["causes"] for r in LATEST["rows"]}
    now = {name(r): r["filmed"]["causes"] for r in rows}
    bouncer = "velocity_dependent_restitution/bouncer/pymunk/1"
    assert then[bouncer] == ["velocity_dependent_restitution", "sensor_offset"]
    assert now[bouncer] == ["velocity_dependent_restitution"]


def test_the_held_out_seeds_at_992b068_refuse_two_wrong_small_balls_and_keep_the_rest() -> None:
    # Seeds 3 and 4 again at git 992b068: 145 of 180 right as at ca4c5a4, no false alarm. Two
    # balls of 1.6 px that named another cause first are refused now (lost in 6 of 41 frames:
    # the fixed spots they had been measured on are passed by). One bouncer's second cause
    # moved from a sensor offset within the stated accuracy to a plane tilt, which moves the
    # recorded positions by more; the other (constant_force) is an effect on the motion.
    rerun = json.loads((FOLDER / "heldout_3_4" / "rerun_992b068" / "results.json").read_text())
    rows = rerun["rows"]
    assert rerun["code"] == "git 992b068" and rerun["seeds"] == [3, 4] and len(rows) == 180
    assert sum(right(r) for r in rows) == sum(right(r) for r in HELDOUT["rows"]) == 145
    was = {name(r): r for r in HELDOUT["rows"]}
    newly = sorted(
        name(r) for r in rows if "filmed_failure" in r and "filmed_failure" not in was[name(r)]
    )
    assert newly == [
        "axis_rotation/projectile_kicked/pymunk/4",
        "plane_tilt/projectile_kicked/pymunk/3",
    ]
    assert not any(right(was[n]) for n in newly)
    assert len([r for r in rows if "filmed_failure" in r]) == 30
    assert sorted(r["body_px"] for r in rows if "filmed_failure" in r and r["body_px"] >= TINY) == [
        2.12  # a ball of 2.1 px, refused at ca4c5a4 too
    ]
    alarms = [
        name(r) for r in rows if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == []
    now = {name(r): r["filmed"]["causes"] for r in rows}
    bouncer = "velocity_dependent_restitution/bouncer/pymunk/4"
    assert was[bouncer]["filmed"]["causes"][1] == "sensor_offset"
    assert now[bouncer] == ["velocity_dependent_restitution", "plane_tilt"]


def test_the_whole_grid_with_deterministic_coding_refuses_fewer_small_balls_and_has_one_alarm() -> (
    None
):
    # The whole grid again at git 53981d9, whose clips are written with x264's macroblock tree
    # off (before, a clip's coding depended on what the process had coded before it). 48 clips
    # refused, all balls under 2 px: four fewer than at 992b068 and none new. The tree coded
    # small balls out of more frames: of 992b068's 52 refused clips, 48 lose a ball from the
    # coded pixels in over a tenth of their frames with it on, 37 with it off; so 37 of the 48
    # refused now are not in the pixels, and 11 are the tracker's misses. One control names a
    # cause: the bouncing ball of pymunk/2 (tracked 0.19 px off, median), an axis rotation of
    # 0.06 degrees, which moves positions by 2.1 mm against a stated 1.2 mm; with two of the four
    # samples beside its floor bounces left out (either pair tried), it names nothing
    # (docs/video.md).
    rerun = json.loads((FOLDER / "rerun_53981d9" / "results.json").read_text())
    rows = rerun["rows"]
    assert rerun["code"] == "git 53981d9" and {name(r) for r in rows} == {name(r) for r in ROWS}
    refused = {name(r) for r in rows if "filmed_failure" in r}
    assert len(refused) == 48 and all(r["body_px"] < TINY for r in rows if name(r) in refused)
    before = json.loads((FOLDER / "rerun_992b068" / "results.json").read_text())["rows"]
    then = {name(r) for r in before if "filmed_failure" in r}
    assert refused < then and len(then - refused) == 4
    seen = {}
    for kind in ("visibility", "visibility_tree_on"):
        vis = json.loads((FOLDER / "rerun_53981d9" / f"{kind}.json").read_text())
        assert vis["summary"]["clips"] == 52
        worst: dict[str, float] = {}
        for v in vis["rows"]:
            worst[v["case"]] = max(worst.get(v["case"], 0.0), v["absent"] / v["in_view"])
        seen[kind] = worst
    on, off = seen["visibility_tree_on"], seen["visibility"]
    assert sum(w > 0.1 for w in on.values()) == 48 and sum(w > 0.1 for w in off.values()) == 37
    assert sum(off[c] > 0.1 for c in refused) == 37
    assert sum(right(r) for r in rows) == 218
    alarms = [
        (name(r), r["filmed"]["causes"])
        for r in rows
        if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == [("control/bouncer/pymunk/2", ["axis_rotation"])]
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (200, 198)
    seconds = [name(r) for r in big if r["effect"] and len(r["filmed"]["causes"] or []) > 1]
    assert seconds == ["velocity_dependent_restitution/drops/box2d/2"]


def test_the_held_out_seeds_with_deterministic_coding_have_every_body_of_2_px_right() -> None:
    # Seeds 3 and 4 again at git 53981d9 (clips coded the same on every call): 150 of 180 right
    # (145 at 992b068), 29 refused, all balls under 2 px (the 2.1 px ball refused before is
    # right), no false alarm, all 134 bodies of 2 px or more right (131 before). Three bouncers
    # and drops name a second cause after the right one (two before).
    rerun = json.loads((FOLDER / "heldout_3_4" / "rerun_53981d9" / "results.json").read_text())
    rows = rerun["rows"]
    assert rerun["code"] == "git 53981d9" and rerun["seeds"] == [3, 4] and len(rows) == 180
    assert sum(right(r) for r in rows) == 150
    refused = [r for r in rows if "filmed_failure" in r]
    assert len(refused) == 29 and all(r["body_px"] < TINY for r in refused)
    alarms = [
        name(r) for r in rows if r["effect"] is None and not right(r) and "filmed_failure" not in r
    ]
    assert alarms == []
    big = [r for r in rows if r["body_px"] >= TINY]
    assert (len(big), sum(right(r) for r in big)) == (134, 134)
    seconds = sorted(name(r) for r in big if r["effect"] and len(r["filmed"]["causes"] or []) > 1)
    assert seconds == [
        "velocity_dependent_restitution/bouncer/box2d/3",
        "velocity_dependent_restitution/bouncer/box2d/4",
        "velocity_dependent_restitution/drops/pymunk/3",
    ]
