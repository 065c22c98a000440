"""Hidden-effect cases (:mod:`physbench.discover.synthetic`) filmed by the second, independent
camera (:mod:`physbench.testing.field_camera`) and tracked: what ``benchmarks/video_discover.py
--camera field`` and its test subset run.

:func:`film_case` films a case's true motion with a :class:`FieldCamera` whose domain is drawn
from the case (:func:`camera_seed`: every clip its own light, texture, pose, lens and codec),
framing where the bodies go, tracks the clip with a four-point calibration (the corners of the
framed rectangle, as a person would click them, with the camera's lens) against the camera's
plate, and returns the run with the tracked recording, with what happened on the way
(:class:`Filmed`): frames seen, bodies lost, and the centre errors against the truth in pixels,
of the tracked metres (``centre_px``) and of the blobs' image centres (``blob_px``).
"""

from __future__ import annotations

import tempfile
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from physbench.discover.data import Run
    from physbench.discover.synthetic import SyntheticRun
    from physbench.recording import Recording
    from physbench.scene import Scene
    from physbench.testing.field_camera import FieldCamera
    from physbench.trajectory import Trajectory


@dataclass
class Filmed:
    """A filmed case: the run with its tracked recording (``None`` when the tracker refused the
    clip, ``failure`` says why), and what the camera and the tracker did."""

    run: Run | None
    domain: dict[str, Any]
    body_px: float  # the smallest body's radius in the image
    failure: str | None = None
    frames: int = 0
    seen: dict[str, int] = field(default_factory=dict)
    lost: dict[str, list[list[float]]] = field(default_factory=dict)
    contacts: dict[str, int] = field(default_factory=dict)
    centre_px: dict[str, dict[str, float]] = field(default_factory=dict)
    blob_px: dict[str, dict[str, float]] = field(default_factory=dict)

    def info(self) -> dict[str, Any]:
        """Everything but the run, for a results file."""
        out = {k: v for k, v in self.__dict__.items() if k not in ("run", "body_px")}
        return {k: v for k, v in out.items() if v is not None}


def camera_seed(name: str) -> int:
    """The field camera's seed for the case named ``name`` (e.g. ``linear_drag/puck/pymunk/0``)."""
    return zlib.crc32(name.encode())


def film_case(
    case: SyntheticRun, cam_seed: int, resolution: int = 640, *, allow_gaps: bool = False
) -> Filmed:
    """Film ``case``'s true motion with the field camera of ``cam_seed``, ``resolution`` pixels
    wide (4:3), and track it (see the module docstring); ``allow_gaps``: keep a track lost in
    more than :data:`~physbench.video.track.LOST_SHARE` of its frames (``track --allow-gaps``)
    instead of refusing the clip."""
    from physbench.calibration import Calibration
    from physbench.testing.field_camera import FieldCamera
    from physbench.video.footage import frame_trajectory, motion_view
    from physbench.video.track import track_video
    from physbench.video.writer import write_clip

    run, rec = case.run, case.run.recording
    if case.trajectory is None or rec is None:
        raise ValueError(f"case {case.name!r} has no true trajectory to film")
    sc = run.scene
    traj = frame_trajectory(case.trajectory, np.arange(sc.frames) / sc.fps)
    cam = FieldCamera(resolution, seed=cam_seed, view=motion_view(sc, traj))
    assert cam.view is not None
    x0, y0, x1, y1 = cam.view
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    cal = Calibration.from_points(
        cam.image_points(sc, corners), corners, lens=cam.calibration(sc).lens
    )
    size = min(
        b.shape.extent() / cal.metres_per_pixel(cal.to_image(np.asarray(b.position)))
        for b in sc.bodies
    )
    out = Filmed(None, cam.describe(), round(float(size), 2))
    with tempfile.TemporaryDirectory(prefix="physbench-field-") as tmp:
        clip = Path(tmp) / "run.mp4"
        write_clip(cam, clip, sc, traj)
        try:
            result = track_video(clip, sc, cal, background=cam.plate(sc), allow_gaps=allow_gaps)
        except Exception as exc:  # a refused clip is a result to report
            out.failure = f"{type(exc).__name__}: {exc}"
            return out
    s = result.summary
    out.frames, out.seen, out.contacts = s.frames, dict(s.detections), dict(s.contacts)
    out.lost = {b: [list(p) for p in v] for b, v in s.lost.items()}
    out.centre_px = centre_errors(cam, sc, traj, result.recording)
    out.blob_px = blob_errors(cam, sc, traj, result.pixels)
    filmed = replace(result.recording, fields=rec.fields, run=rec.run, source="field camera")
    out.run = replace(run, recording=filmed, source="filmed")
    return out


def _stats(d: np.ndarray) -> dict[str, float]:
    return {
        "median": round(float(np.median(d)), 3),
        "p95": round(float(np.percentile(d, 95)), 3),
        "max": round(float(d.max()), 3),
    }


def centre_errors(
    cam: FieldCamera, scene: Scene, traj: Trajectory, recording: Recording
) -> dict[str, dict[str, float]]:
    """Per body: median, 95th percentile and largest distance (px) between the tracked centre and
    the true one at that time, both in metres projected into the image (a long body's blob
    centre is not its projected centre under perspective: the metres are what counts)."""
    out = {}
    times = np.asarray(traj.times)
    states = np.asarray(traj.states)
    for i, name in enumerate(scene.body_names):
        if name not in recording.tracks:
            continue
        tr = recording.track(name)
        true = np.column_stack([np.interp(tr.t, times, states[:, i, c]) for c in (0, 1)])
        got = np.column_stack([tr.x, tr.y])
        out[name] = _stats(
            np.hypot(*(cam.image_points(scene, got) - cam.image_points(scene, true)).T)
        )
    return out


def blob_errors(
    cam: FieldCamera, scene: Scene, traj: Trajectory, pixels: dict[str, np.ndarray]
) -> dict[str, dict[str, float]]:
    """Per body: the same for the blob centres the tracker measured in the image (``track``'s
    pixel file) against the projected true centre; a ball's, not an arm's (see
    :func:`centre_errors`)."""
    out = {}
    times = np.asarray(traj.times)
    states = np.asarray(traj.states)
    for i, name in enumerate(scene.body_names):
        tuv = pixels.get(name)
        if tuv is None or not len(tuv):
            continue
        xy = np.column_stack([np.interp(tuv[:, 0], times, states[:, i, c]) for c in (0, 1)])
        out[name] = _stats(np.hypot(*(cam.image_points(scene, xy) - tuv[:, 1:3]).T))
    return out
