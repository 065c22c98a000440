"""The real-data loaders, on the copies in benchmarks/data: valid scenes, recordings that line up
with them, and measured values that agree with each data set's provenance."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from physbench.datasets import (
    Case,
    DatasetError,
    data_dir,
    dataset_names,
    load,
    oscillation_centre,
    oscillation_periods,
    swing_peaks,
)
from physbench.datasets.billiards import TABLE, rolling_decelerations
from physbench.effects import QuadraticDrag
from physbench.errors import UnknownNameError
from physbench.recording import Recording, Track
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator


def check_case(case: Case) -> None:
    case.scene.validate()
    rec = case.recording
    assert set(rec.bodies) <= set(case.scene.body_names)
    assert rec.frames_for(case.scene.fps) <= case.scene.frames  # the scene covers the recording
    assert rec.fields is not None and case.expected_effects


def early(rec: Recording, body: str, until: float) -> Recording:
    tr = rec.track(body)
    m = tr.t <= until
    return Recording(
        {body: Track(tr.t[m], tr.x[m], tr.y[m], None if tr.angle is None else tr.angle[m])},
        fields=rec.fields,
    )


def test_registry_and_data_folder_errors(tmp_path):
    assert dataset_names() == ["ball_drops", "billiards", "pendulum_benard", "pendulum_kaheman"]
    with pytest.raises(UnknownNameError, match="'bouncing'"):
        load("bouncing")
    with pytest.raises(DatasetError, match="PHYSBENCH_DATA"):
        data_dir("billiards_dogan", root=tmp_path)
    for folder in ("ball_drops_desilva", "billiards_dogan", "pendulum_benard", "pendulum_kaheman"):
        assert (data_dir(folder) / "PROVENANCE.md").is_file()


# --------------------------------------------------------------------------- ball drops


@pytest.fixture(scope="module")
def drops() -> dict[str, Case]:
    return {c.name: c for c in load("ball_drops")}


def test_ball_drops_are_47_m_falls_clipped_like_the_authors(drops):
    assert len(drops) == 22
    for case in drops.values():
        check_case(case)
        tr = case.recording.track("ball")
        assert 45.5 < case.scene.bodies[0].position[1] < 49.6 and 45.5 < tr.y[0] < 49.6
        assert case.recording.fields == ("y",)
        if case.name != "bowling_ball/1":
            assert 2.7 < tr.t[-1] < 3.9 and 10.5 < tr.y[-1] < 15.0 and len(tr) >= 40
    assert len(drops["bowling_ball/1"].recording.track("ball")) == 14  # the provenance's count
    golf = drops["golf_ball/1"]
    assert golf.notes["mass_kg"] == pytest.approx(1.62 * 0.0283495)
    assert golf.scene.bodies[0].shape.radius == pytest.approx(0.138 / (2 * math.pi))
    assert drops["volleyball/1"].notes["mass_and_size_assumed"]


def test_ball_drops_show_drag_that_grows_for_light_balls(drops):
    def apparent_g(case: Case) -> float:
        tr = case.recording.track("ball")
        return -2 * np.polyfit(tr.t, tr.y, 2)[0]

    for name in ("golf_ball/1", "baseball/1", "bowling_ball/2"):
        assert 9.0 < apparent_g(drops[name]) < 9.8
    for name in (
        "whiffle_ball_1/1",
        "whiffle_ball_2/2",
        "yellow_whiffle_ball/1",
        "orange_whiffle_ball/2",
    ):
        assert 2.9 < apparent_g(drops[name]) < 4.7


def test_quadratic_drag_explains_the_whiffle_ball_drop(drops):
    case = drops["whiffle_ball_2/1"]
    sim = PymunkSimulator()
    plain = case.recording.rms(sim.simulate(case.scene))["y"]
    drag = QuadraticDrag(c=0.05 * case.notes["mass_kg"])  # k ≈ 0.05 1/m (provenance: 0.04-0.065)
    drag.setup(case.scene, {})
    with_drag = case.recording.rms(sim.simulate(case.scene, effects=[drag]))["y"]
    assert plain > 8.0 and with_drag < plain / 5  # the start state was fitted without drag


# --------------------------------------------------------------------------- billiards


@pytest.fixture(scope="module")
def shots() -> list[Case]:
    return load("billiards")


def test_billiards_shots_are_top_down_tables_with_a_cue_strike(shots):
    assert len(shots) == 182
    for case in shots:
        check_case(case)
        s = case.scene
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
        assert case.notes["cue"] in ("white", "yellow")
        assert (
            len(s.forces) == 1
            and s.forces[0].kind == "impulse"
            and s.forces[0].body == case.notes["cue"]
        )
        assert 0.5 < case.notes["strike"]["speed_mps"] < 8.0
        assert 1.0 < case.recording.t_end < 17.0


def test_billiards_rolling_deceleration_is_about_0_045(shots):
    dec = np.concatenate([rolling_decelerations(c.recording) for c in shots])
    assert dec.size > 300
    assert 0.035 < np.median(dec) < 0.055  # provenance: 0.047 m/s² on its 54 hand-picked segments
    q1, q3 = np.percentile(dec, [25, 75])
    assert q3 - q1 < 0.015


@pytest.mark.parametrize("sim", [PymunkSimulator, Box2DSimulator])
def test_billiards_scene_lines_up_with_the_tracks(shots, sim):
    case = shots[0]
    traj = sim().simulate(replace(case.scene, frames=11))  # 0.2 s: until sliding friction matters
    res = early(case.recording, case.notes["cue"], 0.2).residuals(traj)
    assert np.abs(res).max() < 0.02


# --------------------------------------------------------------------------- pendulums


def test_kaheman_single_pendulum_period_and_damping():
    (case,) = load("pendulum_kaheman")
    check_case(case)
    tr = case.recording.track("arm1")
    assert len(tr) == 5501 and tr.t[-1] == pytest.approx(55.0)
    periods = oscillation_periods(tr.t, tr.angle)
    assert 0.90 < periods[0] < 0.95 and 0.77 < periods[-1] < 0.80  # amplitude-dependent period
    _, amp = swing_peaks(tr.t, tr.angle)
    assert 1.5 < amp[0] < 1.7 and 0.2 < amp[-1] < 0.3
    per_cycle = -np.diff(amp[::2])
    assert per_cycle[:3].mean() > 2.5 * per_cycle[-5:].mean()  # not purely viscous
    assert abs(oscillation_centre(tr.t, tr.angle)) < 0.01
    # the plain model with the authors' geometry follows the first swings
    traj = PymunkSimulator().simulate(replace(case.scene, frames=201))
    assert early(case.recording, "arm1", 2.0).rms(traj)["angle"] < 0.1


def test_kaheman_double_pendulum_windows_are_chained_arms():
    cases = load("pendulum_kaheman", arms=2, duration=2.0, windows=3)
    assert [c.name for c in cases] == ["2arm/0s", "2arm/2s", "2arm/4s"]
    for case in cases:
        check_case(case)
        s = case.scene
        assert [(j.a, j.b) for j in s.joints] == [("arm1", None), ("arm2", "arm1")]
        traj = PymunkSimulator().simulate(replace(s, frames=2))
        # frame 0 reproduces the recorded first sample exactly: angles and implied positions
        first = Recording(
            {
                b: Track(tr.t[:1], tr.x[:1], tr.y[:1], tr.angle[:1])
                for b, tr in case.recording.tracks.items()
            }
        )
        np.testing.assert_allclose(
            first.residuals(traj, fields=["x", "y", "angle"]), 0.0, atol=1e-9
        )


def test_benard_rod_pendulum_starts_at_the_first_extreme():
    cases = load("pendulum_benard")
    assert [c.name for c in cases] == ["free_swing_01", "free_swing_02", "free_swing_03"]
    for case, start_deg in zip(cases, (136, 157, 64), strict=True):
        check_case(case)
        tr = case.recording.track("rod")
        assert abs(math.degrees(tr.angle[0])) == pytest.approx(start_deg, abs=1.5)  # provenance
        assert case.scene.bodies[0].angular_velocity == 0.0
        periods = oscillation_periods(tr.t, tr.angle)
        assert 0.55 < periods[-1] < 0.65  # ≈ 2π·sqrt(2L/3g) = 0.59 s at small amplitude
        assert periods[0] > periods[-1]
    # The lossless rod model swings at the recorded period where losses are small (the 64° file);
    # from 136° and 157° the real rod loses a third of its amplitude in the first swing.
    case = cases[2]
    tr = case.recording.track("rod")
    sim_periods = oscillation_periods(
        *_angle(PymunkSimulator().simulate(replace(case.scene, frames=301)))
    )
    assert sim_periods[0] == pytest.approx(oscillation_periods(tr.t, tr.angle)[0], rel=0.08)


def _angle(traj) -> tuple[np.ndarray, np.ndarray]:
    return traj.times, traj.field("angle")[:, 0]
