"""Observations from video: what the correction loop compares when it watches a camera.

:func:`video_observation` turns a video file into an
:class:`~physbench.observation.Observation`: track the scene's bodies
(:func:`~physbench.video.track.track_video`), then for each of the scene's frame times take the
nearest video frame and segment it into the model renderer's frames
(:class:`~physbench.video.segment.Segmenter`), once unmarked and once per marked body.
:func:`filmed_observation` does the same to a simulated observation filmed by a camera renderer
and encoded as a real video file: the visual gap between a camera and sharp renders.
:func:`filmed_recording` films a trajectory and tracks it: what a camera and the tracker make of
known motion, for discovery from video.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.video.segment import SegmentError
from physbench.video.writer import write_clip

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.observation import Observation
    from physbench.recording import Recording
    from physbench.render.base import Camera, Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.trajectory import Trajectory
    from physbench.video.reader import Frame


def scene_frames(
    frames: Iterable[Frame], times: np.ndarray, *, what: str = "video"
) -> Iterator[tuple[int, Frame, float]]:
    """For each of ``times`` (s, increasing, from the first frame given), the frame of
    ``frames`` nearest to it, as ``(index into times, frame, frame time from the first frame)``;
    reads the frames once, holding two. A video that ends before the last time is a
    :class:`SegmentError`."""
    k, prev, base, prev_t = 0, None, None, 0.0
    for fr in frames:
        if base is None:
            base = fr.time
        t = fr.time - base
        while k < len(times) and t >= times[k]:
            if prev is None or t - times[k] <= times[k] - prev_t:
                yield k, fr, t
            else:
                yield k, prev, prev_t
            k += 1
        if k == len(times):
            return
        prev, prev_t = fr, t
    # The last frame stands for a time up to half a frame interval after it.
    step = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    while prev is not None and k < len(times) and times[k] - prev_t <= 0.5 * step + 1e-9:
        yield k, prev, prev_t
        k += 1
    if k < len(times):
        have = "no frames" if prev is None else f"{prev_t:.3f} s of frames"
        raise SegmentError(
            f"{what}: has {have}, but the scene needs {len(times)} frames up to "
            f"t = {times[-1]:.3f} s; give a longer video, an earlier --start, or a scene with "
            "fewer frames"
        )


def poses_at(recording: Recording, scene: Scene, t: float) -> np.ndarray:
    """``(N, 3)`` poses of the scene's bodies at time ``t`` from the tracks (linear in time between
    samples, held at the ends); a body without a measured angle keeps its initial angle."""
    out = np.zeros((len(scene.bodies), 3))
    for i, body in enumerate(scene.bodies):
        tr = recording.track(body.name)
        out[i, 0] = np.interp(t, tr.t, tr.x)
        out[i, 1] = np.interp(t, tr.t, tr.y)
        out[i, 2] = body.angle if tr.angle is None else np.interp(t, tr.t, tr.angle)
    return out


def video_observation(
    path: str | Path,
    scene: Scene,
    renderer: Renderer,
    *,
    calibration: Calibration | str | Path | None = None,
    background: np.ndarray | str | Path | None = None,
    start: float | None = None,
    end: float | None = None,
    marked: Iterable[str] = (),
    allow_gaps: bool = False,
    transfer: str | None = None,
    capture_fps: float | None = None,
) -> Observation:
    """The observation of a video file in ``renderer``'s frames (see the module docstring).
    ``calibration``: a :class:`~physbench.calibration.Calibration` or a TOML file (default:
    ``scene.bounds`` fill the frame); ``background``: an image of the empty scene (array or file;
    default: the video's median); ``allow_gaps``: keep tracks where a body was lost for more
    than the tracker's share of the clip (else :class:`~physbench.video.track.TrackLostError`);
    ``transfer``: how the video's pixels encode light, ``capture_fps``: the rate a slow-motion
    file was filmed at (:func:`~physbench.video.track.track_video`)."""
    from physbench.calibration import load_calibration
    from physbench.observation import Observation
    from physbench.video.background import load_plate
    from physbench.video.photometry import LightMeter
    from physbench.video.reader import VideoReader
    from physbench.video.segment import Segmenter, body_threshold, fill_holes
    from physbench.video.track import bounds_calibration, track_video

    reader = VideoReader(path, start=start, end=end, fps=scene.fps, capture_fps=capture_fps)
    info = reader.info()
    if isinstance(calibration, str | Path):
        calibration = load_calibration(calibration)
    if calibration is None:
        calibration = bounds_calibration(scene, (info.height, info.width))
    if isinstance(background, str | Path):
        background = load_plate(background)
    tracked = track_video(
        path,
        scene,
        calibration,
        start=start,
        end=end,
        background=background,
        allow_gaps=allow_gaps,
        transfer=transfer,
        capture_fps=capture_fps,
    )
    recording = tracked.measured  # collision frames too: their pixels are split by the poses
    if background is None:
        background = tracked.background  # the clip's median, mended where it held a body
    expected = tuple(renderer.shape(scene))
    seg = Segmenter(
        scene,
        calibration,
        (info.height, info.width),
        resolution=renderer.resolution,
        mode=renderer.mode,
    )
    if (seg.h, seg.w) != expected[2:]:
        raise SegmentError(
            f"renderer {renderer.name!r} draws {expected[3]}x{expected[2]} px frames; a video is "
            f"segmented into the scene-filling geometry ({seg.w}x{seg.h} px at this resolution)"
        )
    marked = tuple(marked)
    times = np.arange(scene.frames) / scene.fps
    views: dict[str | None, np.ndarray] = {
        b: np.zeros(expected, np.float32) for b in (None, *marked)
    }
    hole = _largest_hole(scene, calibration)
    # Each frame in its own light (a drifting light, a median background): see
    # physbench.video.photometry.
    meter = LightMeter(background)
    reach = [2 * b.shape.extent() for b in scene.bodies]
    for k, fr, t in scene_frames(reader.frames(), times, what=str(path)):
        poses = poses_at(recording, scene, t)
        uv = calibration.to_image(poses[:, :2])
        mpp = calibration.metres_per_pixel(uv[0])
        light = meter.measure(
            fr.image, [(u, v, r / mpp + 5) for (u, v), r in zip(uv, reach, strict=True)]
        )
        diff = light.difference(fr.image, background)
        threshold = body_threshold(diff, uv, light.threshold())
        cov = seg.coverage(fill_holes(diff > threshold, hole).astype(np.float32), poses)
        for b, arr in views.items():
            arr[k] = seg.frame(cov, b)
    frames = views.pop(None)
    return Observation(frames, None, views, source=f"video {path}")  # type: ignore[arg-type]


def _largest_hole(scene: Scene, calibration: Calibration) -> float:
    """Holes in a frame's foreground up to half the smallest body's area (px, at the middle of
    the scene's bounds) are filled: a body is opaque, and a real gap that small is not one."""
    xmin, ymin, xmax, ymax = scene.bounds
    middle = calibration.to_image(np.array([[(xmin + xmax) / 2, (ymin + ymax) / 2]]))[0]
    smallest = min(b.shape.area() for b in scene.bodies)
    return 0.5 * smallest / calibration.metres_per_pixel(middle) ** 2


def filmed_observation(
    scene: Scene,
    truth: Mapping[str, float],
    simulator: Simulator,
    camera: Camera,
    renderer: Renderer,
    *,
    marked: Iterable[str] = (),
) -> Observation:
    """Simulate ``scene`` with the true parameters, film it with ``camera`` into an encoded video
    file, and read that back with :func:`video_observation`: calibrated from the four corners of
    ``scene.bounds`` as a user would click them, with the camera's plate as the background."""
    from physbench.calibration import Calibration

    traj = simulator.simulate(scene, dict(truth))
    xmin, ymin, xmax, ymax = scene.bounds
    corners = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]])
    true = camera.calibration(scene)
    cal = Calibration.from_points(camera.image_points(scene, corners), corners, lens=true.lens)
    with tempfile.TemporaryDirectory(prefix="physbench-film-") as tmp:
        clip = Path(tmp) / "observation.mp4"
        write_clip(camera, clip, scene, traj)
        obs = video_observation(
            clip, scene, renderer, calibration=cal, background=camera.plate(scene), marked=marked
        )
    obs.truth = dict(truth)
    obs.scene, obs.engine = scene.with_params(truth), type(simulator).name
    obs.source = f"simulated ({obs.engine}), filmed by {camera.name}"
    return obs


def motion_view(scene: Scene, traj: Trajectory, *, margin: float = 0.15) -> list[float]:
    """``[xmin, ymin, xmax, ymax]`` (m) around where ``traj``'s bodies go, padded by their size and
    ``margin`` of the extent: the part of a large world a camera should frame (a camera's
    ``view`` option)."""
    pos = np.asarray(traj.states, dtype=float)[:, :, :2].reshape(-1, 2)
    reach = max(b.shape.extent() for b in scene.bodies)
    lo, hi = pos.min(axis=0) - reach, pos.max(axis=0) + reach
    pad = margin * (hi - lo).max()
    return [float(lo[0] - pad), float(lo[1] - pad), float(hi[0] + pad), float(hi[1] + pad)]


def frame_trajectory(traj: Trajectory, times: np.ndarray) -> Trajectory:
    """``traj`` resampled at ``times`` (s; linear in every state column): a trajectory on a
    camera's frame clock when the simulation's differs (a measurement effect that rescales time)."""
    from physbench.trajectory import Trajectory

    src = np.asarray(traj.times, dtype=float)
    states = np.asarray(traj.states, dtype=float)
    out = np.empty((len(times), *states.shape[1:]))
    for i in range(states.shape[1]):
        for c in range(states.shape[2]):
            out[:, i, c] = np.interp(times, src, states[:, i, c])
    return Trajectory(traj.bodies, np.asarray(times, dtype=float), out, traj.engine)


def filmed_recording(
    scene: Scene,
    traj: Trajectory,
    camera: Camera,
    *,
    fields: tuple[str, ...] | None = None,
    run: str = "",
) -> Recording:
    """Film ``traj`` of ``scene`` with ``camera`` into an encoded video file, track it
    (:func:`~physbench.video.track.track_video`) with a calibration through the four corners of the
    camera's view as a user would click them and the camera's plate as the background, and return
    the tracks in the scene's metres; ``fields`` and ``run`` label the recording."""
    from dataclasses import replace

    from physbench.calibration import Calibration
    from physbench.video.track import track_video

    xmin, ymin, xmax, ymax = camera.view if camera.view is not None else scene.bounds
    corners = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]])
    cal = Calibration.from_points(
        camera.image_points(scene, corners), corners, lens=camera.calibration(scene).lens
    )
    with tempfile.TemporaryDirectory(prefix="physbench-film-") as tmp:
        clip = Path(tmp) / "run.mp4"
        write_clip(camera, clip, scene, traj)
        rec = track_video(clip, scene, cal, background=camera.plate(scene)).recording
    return replace(
        rec,
        fields=rec.fields if fields is None else fields,
        run=run or rec.run,
        source=f"filmed by {camera.name}, tracked",
    )
