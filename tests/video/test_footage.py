"""Observations from video: frames picked on the scene's clock, poses read from tracks, a filmed and
encoded clip segmented back into the sharp renderer's masks, and filmed recordings that match the
true motion."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.components import create
from physbench.recording import Recording, Track
from physbench.render.camera import CameraRenderer
from physbench.render.raster import RasterRenderer
from physbench.scenes import resolve_scene
from physbench.video.footage import (
    filmed_observation,
    filmed_recording,
    frame_trajectory,
    motion_view,
    poses_at,
    scene_frames,
    video_observation,
)
from physbench.video.reader import Frame
from physbench.video.segment import SegmentError
from physbench.video.writer import write_clip


def frames_at(times: list[float]) -> list[Frame]:
    return [Frame(i, t, np.full((2, 2, 3), i, np.uint8)) for i, t in enumerate(times)]


def test_scene_frames_pick_the_nearest_frame_of_an_irregular_clock() -> None:
    # A phone's clock: 0.1 s steps with one frame dropped (0.3 missing) and jitter.
    video = frames_at([5.0, 5.1, 5.2, 5.41, 5.5, 5.6])  # times relative to the first frame
    got = [(k, fr.index) for k, fr, _ in scene_frames(video, np.arange(6) * 0.1)]
    assert got == [(0, 0), (1, 1), (2, 2), (3, 2), (4, 3), (5, 4)]


def test_scene_frames_refuse_a_video_shorter_than_the_scene() -> None:
    with pytest.raises(SegmentError, match=r"clip.mp4: has 0.200 s of frames, but the scene needs"):
        list(scene_frames(frames_at([0.0, 0.1, 0.2]), np.arange(10) * 0.1, what="clip.mp4"))
    with pytest.raises(SegmentError, match="has no frames"):
        list(scene_frames([], np.arange(3) * 0.1))
    # Half a frame interval past the last frame is still that frame.
    assert len(list(scene_frames(frames_at([0.0, 0.1, 0.2]), np.array([0.0, 0.1, 0.2, 0.25])))) == 4


def test_poses_interpolate_tracks_and_keep_the_initial_angle_without_one() -> None:
    scene = resolve_scene("three_circles", 0)
    t = np.array([0.0, 1.0])
    rec = Recording({b.name: Track(t, t * 2, t + 1) for b in scene.bodies})
    p = poses_at(rec, scene, 0.25)
    np.testing.assert_allclose(p[:, :2], [[0.5, 1.25]] * len(scene.bodies))
    np.testing.assert_allclose(p[:, 2], [b.angle for b in scene.bodies])


def test_motion_view_frames_where_the_bodies_go_and_resampling_keeps_states() -> None:
    scene = resolve_scene("three_circles", 0)
    traj = create("simulator", "pymunk").simulate(scene)
    xmin, ymin, xmax, ymax = motion_view(scene, traj)
    pos = traj.states[:, :, :2].reshape(-1, 2)
    assert xmin < pos[:, 0].min() and xmax > pos[:, 0].max()
    assert ymin < pos[:, 1].min() and ymax > pos[:, 1].max()
    same = frame_trajectory(traj, traj.times)
    np.testing.assert_allclose(same.states, traj.states)
    half = frame_trajectory(traj, traj.times[:-1] + 0.5 / scene.fps)
    np.testing.assert_allclose(half.states, 0.5 * (traj.states[:-1] + traj.states[1:]))


@pytest.fixture(scope="module")
def circles():
    scene = resolve_scene("three_circles", 2)
    traj = create("simulator", "pymunk").simulate(scene)
    return scene, traj


def test_a_filmed_encoded_clip_segments_into_the_sharp_masks(circles, tmp_path) -> None:
    scene, traj = circles
    cam = CameraRenderer(640, tilt=15.0, seed=1)
    clip = tmp_path / "clip.mp4"
    write_clip(cam, clip, scene, traj)
    before = clip.read_bytes()
    sharp = RasterRenderer(64, "mark")
    marked = [b.name for b in scene.bodies]
    obs = video_observation(
        clip,
        scene,
        sharp,
        calibration=cam.calibration(scene),
        background=cam.plate(scene),
        marked=marked,
    )
    assert clip.read_bytes() == before  # the user's file is only read
    ref = sharp.render(scene, traj)
    assert obs.frames.shape == ref.shape and obs.truth is None
    assert np.mean((obs.frames - ref) ** 2) < 0.02 * np.mean(ref**2)
    for name in marked:
        view = obs.marked[name]
        want = sharp.render(scene, traj, focus=name)
        assert np.mean((view - want) ** 2) < 0.03 * np.mean(want**2), name
        # The marked body's channel holds about all of its area.
        assert view[:, 1].sum() == pytest.approx(want[:, 1].sum(), rel=0.05)


def test_filmed_observation_carries_the_truth_and_matches_the_renderer(circles) -> None:
    scene, _ = circles
    truth = {u.key: float(np.mean([u.low, u.high])) for u in scene.unknowns}
    sim = create("simulator", "pymunk")
    sharp = RasterRenderer(64, "mark")
    obs = filmed_observation(scene, truth, sim, CameraRenderer(640, tilt=10.0, seed=2), sharp)
    ref = sharp.render(scene, sim.simulate(scene, truth))
    assert obs.truth == truth and "filmed by camera" in obs.source
    assert np.mean((obs.frames - ref) ** 2) < 0.02 * np.mean(ref**2)


def test_a_filmed_recording_follows_the_true_motion(circles) -> None:
    scene, traj = circles
    cam = CameraRenderer(640, tilt=12.0, bitrate=2_000_000, seed=3, view=motion_view(scene, traj))
    rec = filmed_recording(scene, traj, cam, fields=("x", "y"), run="r")
    assert rec.fields == ("x", "y") and rec.run == "r"
    for i, b in enumerate(scene.bodies):
        tr = rec.track(b.name)
        k = np.rint(tr.t * scene.fps).astype(int)
        err = np.hypot(tr.x - traj.states[k, i, 0], tr.y - traj.states[k, i, 1])
        radius = b.shape.extent()
        assert np.median(err) < 0.05 * radius, (b.name, np.median(err))


def test_a_frame_left_out_of_the_recording_for_a_collision_is_segmented_where_the_bodies_were(
    tmp_path,
) -> None:  # type: ignore[no-untyped-def]
    """The recording leaves out frames whose exposure spans a collision; their pixels are still
    split among the bodies by the poses measured there. Split by poses interpolated across the
    collision, a ball's view there was 8-14 times its median frame's error."""
    from physbench.video.track import track_video

    scene = resolve_scene("three_circles", 0)
    traj = create("simulator", "pymunk").simulate(scene)
    cam = CameraRenderer(640, tilt=15.0, seed=1, bitrate=2_000_000)
    clip = tmp_path / "clip.mp4"
    write_clip(cam, clip, scene, traj)
    cal, plate = cam.calibration(scene), cam.plate(scene)
    tracked = track_video(clip, scene, cal, background=plate)
    sharp = RasterRenderer(64, "mark")
    names = [b.name for b in scene.bodies]
    obs = video_observation(clip, scene, sharp, calibration=cal, background=plate, marked=names)
    left_out = 0
    for name in names:
        kept = set(np.rint(tracked.recording.track(name).t * scene.fps).astype(int))
        measured = set(np.rint(tracked.measured.track(name).t * scene.fps).astype(int))
        assert kept < measured  # the measured poses hold the collision frames too
        want = sharp.render(scene, traj, focus=name)
        err = ((obs.marked[name] - want) ** 2).mean(axis=(1, 2, 3))
        for k in sorted(measured - kept):
            assert err[k] <= 3.0 * np.median(err), (name, k, err[k] / np.median(err))
            left_out += 1
    assert left_out >= 6
