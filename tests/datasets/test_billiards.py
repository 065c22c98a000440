"""The billiards loader on the shipped copy, and the rolling-segment, cushion and
deceleration measurements on synthetic tracks with known answers."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from physbench.datasets import DatasetRun, load
from physbench.datasets.billiards import (
    BALL_MASS,
    BALL_RADIUS,
    MIN_SEGMENT,
    SEGMENT_SETTLE,
    TABLE,
    cushion_bounces,
    cushions,
    last_ball_contact,
    rolling_decelerations,
    rolling_segment,
    rolling_segments,
    straight_stretches,
)
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator


@pytest.fixture(scope="module")
def shots() -> list[DatasetRun]:
    return load("billiards")


def test_billiards_shots_are_top_down_tables_with_a_cue_strike(shots, check_run):
    assert len(shots) == 182
    for run in shots:
        check_run(run)
        s = run.scene
        assert (
            s.gravity == (0.0, 0.0)
            and len(s.statics) == 4
            and s.body_names == ("white", "yellow", "red")
        )
        for b in s.bodies:
            r = b.shape.radius
            assert (
                r - 1e-9 <= b.position[0] <= TABLE[0] - r + 1e-9
                and r - 1e-9 <= b.position[1] <= TABLE[1] - r + 1e-9
            )
        assert run.notes["cue"] in ("white", "yellow")
        assert (
            len(s.forces) == 1
            and s.forces[0].kind == "impulse"
            and s.forces[0].body == run.notes["cue"]
        )
        assert 0.5 < run.notes["strike"]["speed_mps"] < 8.0
        assert 1.0 < run.recording.t_end < 17.0


def test_billiards_rolling_deceleration_is_about_0_045(shots):
    dec = np.concatenate([rolling_decelerations(r.recording) for r in shots])
    assert dec.size > 300
    assert 0.035 < np.median(dec) < 0.055  # provenance: 0.047 m/s² on its 54 hand-picked segments
    q1, q3 = np.percentile(dec, [25, 75])
    assert q3 - q1 < 0.015


@pytest.mark.parametrize("sim", [PymunkSimulator, Box2DSimulator])
def test_billiards_scene_lines_up_with_the_tracks(shots, sim, early):
    run = shots[0]
    traj = sim().simulate(replace(run.scene, frames=11))  # 0.2 s: until sliding friction matters
    res = early(run.recording, run.notes["cue"], 0.2).residuals(traj)
    assert np.abs(res).max() < 0.02


def test_rolling_segments_of_the_match(shots, check_run):
    segments = rolling_segments(shots[:40], count=6)
    assert len(segments) == 6
    for seg in segments:
        check_run(seg)
        assert seg.scene.body_names == ("ball",) and seg.recording.t_end >= MIN_SEGMENT
        assert [u.key for u in seg.scene.unknowns] == ["ball.elasticity"]


# --------------------------------------------------------------------------- synthetic tracks

V0, DECEL = 0.5, 0.05  # m/s, m/s²
HIT = 0.5  # s: when the red ball starts to move


def synthetic_shot() -> DatasetRun:
    """White rolls along y = 0.7 from x = 0.3 at 0.5 m/s, slowing by 0.05 m/s², sampled at 25 Hz
    for 5.5 s; red, far from its path, rests until it is hit at 0.5 s, then moves for 1 s."""
    t = np.arange(0.0, 5.5 + 1e-9, 0.04)
    white = Track(t, 0.3 + V0 * t - DECEL * t**2 / 2, np.full_like(t, 0.7))
    tr = np.concatenate([[0.0], np.arange(HIT, HIT + 1.0 + 1e-9, 0.04)])
    red = Track(tr, np.full_like(tr, 1.0), 0.9 + 0.3 * np.clip(tr - HIT, 0, None))
    rec = Recording({"white": white, "red": red}, run="1", fields=("x", "y"), source="synthetic")
    bodies = tuple(
        Body(n, Circle(BALL_RADIUS), (float(tr.x[0]), float(tr.y[0])), mass=BALL_MASS)
        for n, tr in rec.tracks.items()
    )
    scene = Scene(
        name="synthetic_shot",
        bodies=bodies,
        bounds=(-0.1, -0.1, TABLE[0] + 0.1, TABLE[1] + 0.1),
        gravity=(0.0, 0.0),
        fps=25.0,
        frames=rec.frames_for(25.0),
        substeps=8,
        statics=cushions(0.9),
    ).validate()
    return DatasetRun("shot_1", scene, rec, ("rolling_resistance",))


def test_last_ball_contact_is_when_the_other_ball_starts_to_move():
    shot = synthetic_shot()
    assert last_ball_contact(shot.recording, "white") == HIT
    # white moves from the start and never comes within 2 radii + 4 cm of red
    assert last_ball_contact(shot.recording, "red") == 0.0


def test_rolling_segment_starts_after_the_contact_and_keeps_the_deceleration(check_run):
    shot = synthetic_shot()
    seg = rolling_segment(shot, "white")
    assert seg is not None
    check_run(seg)
    white = shot.recording.tracks["white"]
    t0 = white.t[white.t >= HIT + SEGMENT_SETTLE][0]  # the first sample after settling
    assert seg.name == "shot_1/white" and seg.notes["start_s"] == t0
    tr = seg.recording.tracks["ball"]
    assert tr.t[0] == 0.0 and tr.t[-1] == pytest.approx(white.t[-1] - t0)
    np.testing.assert_array_equal(tr.x, white.x[white.t >= t0])
    ball = seg.scene.bodies[0]
    assert ball.position == pytest.approx((0.3 + V0 * t0 - DECEL * t0**2 / 2, 0.7))
    # the start velocity: a line through the first 6 samples, the speed at their middle
    assert ball.velocity == pytest.approx((V0 - DECEL * (t0 + 0.1), 0.0), abs=1e-9)
    (stretch,) = straight_stretches(seg.name, tr)
    assert stretch.deceleration == pytest.approx(DECEL)
    assert stretch.speed == pytest.approx(V0 - DECEL * t0)
    assert rolling_segment(shot, "red") is None  # too few samples
    assert [s.name for s in rolling_segments([shot, shot], count=1)] == ["shot_1/white"]


def test_rolling_segment_from_a_speed():
    shot = synthetic_shot()
    seg = rolling_segment(shot, "white", max_speed=0.42)  # 0.5 - 0.05 t < 0.42 from t = 1.6
    assert seg is not None and seg.notes["start_s"] == pytest.approx(1.6)
    assert rolling_segment(shot, "white", max_speed=0.2) is None  # too late: too short


def test_cushion_bounce_measures_the_restitution():
    """A ball at (0.4, 0.5) m/s hits the far long cushion at t = 1 and leaves at (0.36, -0.3)."""
    t = np.arange(0.0, 2.0, 0.04)
    wall = TABLE[1] - BALL_RADIUS
    v_in, v_out = np.array([0.4, 0.5]), np.array([0.36, -0.3])
    p = np.where(t[:, None] <= 1.0, (t[:, None] - 1.0) * v_in, (t[:, None] - 1.0) * v_out)
    p = p + np.array([1.4, wall])
    (b,) = cushion_bounces("r", Track(t, p[:, 0], p[:, 1]))
    assert b.run == "r" and b.t == pytest.approx(1.0)
    assert (b.vn_in, b.vt_in) == pytest.approx((0.5, 0.4))
    assert (b.e_n, b.t_kept) == pytest.approx((0.6, 0.9))
    assert b.speed_kept == pytest.approx(np.hypot(*v_out) / np.hypot(*v_in))
    # the same bounce in a corner: another cushion within the windows, left out
    corner = Track(t, BALL_RADIUS + 0.015 + 0.01 * (t - 1.0), p[:, 1])  # along a short cushion
    assert cushion_bounces("r", corner) == []
