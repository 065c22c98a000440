"""Following a scene's bodies through a video: :func:`track_video` -> a recording in metres.

1. **Background**: a plate of the empty scene, or the median of the clip
   (:mod:`~physbench.video.background`).
2. **Start**: the scene's initial body positions, projected into the first frame through the
   calibration, say where to look; each body takes the blob found near its projection (a body with
   none is a :class:`TrackError` that names it and the pixel where it was expected). The bodies'
   contrast there sets the thresholds (:mod:`~physbench.video.detect`).
3. **Each frame**: a :class:`Tracker` predicts every body (constant velocity plus the scene's
   gravity for a free body, in scene metres), looks only in a window around each prediction (one
   window for bodies whose windows overlap), gates candidates by a radius that grows with the
   body's size and speed, and assigns blobs to bodies optimally
   (:func:`scipy.optimize.linear_sum_assignment`). A body left without a blob whose neighbour's blob
   is too big for one body shares that blob (:func:`~physbench.video.detect.split_blob`).
4. **Gaps**: a body not seen in a frame has no row for that frame (the gap is left, not filled);
   its prediction coasts and its window widens. A body unseen for longer than ``max_gap`` seconds
   is reported as lost in the :class:`TrackSummary`.

Angles are measured for bodies whose outline shows them (boxes, elongated polygons, a pendulum's
arm), not for discs; a square's angle is known modulo 90 degrees and an elongated body's modulo
180, and the tracker unwraps it by continuity from the scene's initial angle.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError, counted
from physbench.scene import Box, Circle
from physbench.video.contacts import contact_samples
from physbench.video.detect import (
    Blob,
    Outline,
    PlanePose,
    blob_from_pixels,
    find_blobs,
    plane_pose,
    split_pixels,
)
from physbench.video.segment import difference, noise_threshold

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.recording import Recording
    from physbench.scene import Body, Scene
    from physbench.video.reader import Frame

#: Ratio of a body's principal second moments above which its long axis gives its angle.
ELONGATED = 1.3
#: Seconds a body may go unseen before it is reported lost (default of :func:`track_video`).
MAX_GAP = 0.5
#: The tracker's systematic accuracy (px), stated on its recordings in metres: what lighting,
#: lossy coding and the arc a turning body sweeps in one exposure leave in a centre (measured:
#: 95 % of ball centres within 0.3 px, a swinging arm 0.4-0.5 px RMS along its length;
#: ``benchmarks/track_accuracy.py``, ``tests/video/test_track.py``).
ACCURACY_PX = 0.5


class TrackError(PhysbenchError, ValueError):
    """A video that cannot be tracked against a scene: names the body, frame or value."""


class BodyNotFoundError(TrackError):
    """A scene body with no blob near where the scene says it starts."""


def bounds_calibration(scene: Scene, image_shape: tuple[int, int]) -> Calibration:
    """The calibration of a camera square-on to the plane with ``scene.bounds`` filling an image
    of ``image_shape = (H, W)`` px: the scene's aspect is kept, so the bounds touch two opposite
    edges and are centred between the other two; ``y`` up."""
    from physbench.calibration import Calibration

    h, w = image_shape
    xmin, ymin, xmax, ymax = scene.bounds
    s = max((xmax - xmin) / w, (ymax - ymin) / h)  # metres per pixel
    uc, vc = (w - 1) / 2, (h - 1) / 2
    xc, yc = (xmin + xmax) / 2, (ymin + ymax) / 2
    return Calibration.from_scale(s, (uc - xc / s, vc + yc / s), source="scene bounds")


def _symmetry(body: Body) -> tuple[int, float]:
    """``(k, offset)``: the body's angle is measurable modulo ``2 pi / k`` (0: not at all), and its
    long axis lies at ``offset`` from its body-frame x axis."""
    shape = body.shape
    if isinstance(shape, Circle):
        return 0, 0.0
    pts = np.asarray(shape.vertices(), dtype=float)
    pts = pts - pts.mean(axis=0)
    m = pts.T @ pts
    vals, vecs = np.linalg.eigh(m)
    if vals[1] > ELONGATED * max(vals[0], 1e-12):
        return 2, math.atan2(vecs[1, 1], vecs[0, 1]) % math.pi
    if isinstance(shape, Box):
        return 4, 0.0
    return 0, 0.0


def _area_centroid(pts: np.ndarray) -> np.ndarray:
    """The centroid of the polygon ``pts`` ``(K, 2)``'s area (its vertex mean if degenerate)."""
    q = np.roll(pts, -1, axis=0)
    cross = pts[:, 0] * q[:, 1] - q[:, 0] * pts[:, 1]
    a = cross.sum() / 2
    if abs(a) < 1e-15:
        return pts.mean(axis=0)
    return np.array(
        [((pts[:, 0] + q[:, 0]) * cross).sum(), ((pts[:, 1] + q[:, 1]) * cross).sum()]
    ) / (6 * a)


@dataclass
class _State:
    """What the tracker knows of one body."""

    body: Body
    radius: float  # px, outline (extent) at the start
    area: float  # px, expected covered area at the start
    k: int
    offset: float
    free: bool
    xy: np.ndarray
    v: np.ndarray
    t: float
    angle: float | None
    omega: float = 0.0
    contrast: float = 0.0  # grey levels against the background, from the first frame
    step: float = 0.0  # px moved in the last frame interval
    missed: int = 0
    gap_start: float | None = None
    rows: list[tuple[float, float, float, float]] = field(default_factory=list)
    uv_rows: list[tuple[float, float, float]] = field(default_factory=list)
    gaps: int = 0
    lost: list[tuple[float, float]] = field(default_factory=list)


@dataclass(frozen=True)
class TrackSummary:
    """How tracking went: ``frames`` read over ``duration`` s, per body the ``detections``
    (frames with a measurement), ``gaps`` (runs of frames without one) and ``lost`` (gaps longer
    than the limit, as ``(from, to)`` s), the calibration's reprojection error (px) and the
    processing speed (frames/s)."""

    frames: int
    duration: float
    detections: dict[str, int]
    gaps: dict[str, int]
    lost: dict[str, list[tuple[float, float]]]
    reprojection_error: float
    fps: float = 0.0
    #: Per body, the samples left out because their exposure spans a collision
    #: (:mod:`physbench.video.contacts`).
    contacts: dict[str, int] = field(default_factory=dict)

    def format(self) -> str:
        """A few lines for a person."""
        lines = [
            f"tracked {counted(len(self.detections), 'body')} over "
            f"{counted(self.frames, 'frame')} "
            f"({self.duration:.2f} s) at {self.fps:.0f} frames/s; calibration reprojection "
            f"error {self.reprojection_error:.2f} px"
        ]
        for name, n in self.detections.items():
            gone = self.lost.get(name, [])
            tail = "; lost " + ", ".join(f"{a:.2f}-{b:.2f} s" for a, b in gone) if gone else ""
            if self.contacts.get(name):
                tail += (
                    f"; {counted(self.contacts[name], 'collision frame')} left out (the exposure "
                    "spans the collision)"
                )
            lines.append(
                f"  {name:>8}: seen in {n}/{self.frames} frames, "
                f"{counted(self.gaps[name], 'gap')}{tail}"
            )
        return "\n".join(lines)


@dataclass(frozen=True)
class TrackResult:
    """The :class:`~physbench.recording.Recording` (scene metres, t = 0 at the first frame), the
    :class:`TrackSummary`, and each body's image track ``(t, u, v)`` (px) for overlays."""

    recording: Recording
    summary: TrackSummary
    pixels: dict[str, np.ndarray]


class Tracker:
    """Frame-by-frame tracking of ``scene``'s bodies against ``background`` (see the module
    docstring). Call :meth:`update` with each frame in order, then :meth:`result`."""

    def __init__(
        self,
        scene: Scene,
        calibration: Calibration,
        background: np.ndarray,
        *,
        max_gap: float = MAX_GAP,
    ) -> None:
        self.scene, self.cal, self.bg = scene, calibration, background
        self.h, self.w = background.shape[:2]
        self.g = np.asarray(scene.gravity, dtype=float)
        self.max_gap = max_gap
        jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b}
        self.states: list[_State] = []
        for body in scene.bodies:
            xy = np.asarray(body.position, dtype=float)
            uv = calibration.to_image(xy)
            mpp = calibration.metres_per_pixel(uv)
            k, offset = _symmetry(body)
            self.states.append(
                _State(
                    body,
                    body.shape.extent() / mpp,
                    body.shape.area() / mpp**2,
                    k,
                    offset,
                    body.name not in jointed,
                    xy,
                    np.asarray(body.velocity, dtype=float),
                    0.0,
                    body.angle if k else None,
                    body.angular_velocity,
                )
            )
        self.frames = 0
        self.t0: float | None = None
        self.t_last = 0.0
        self.low = self.high = 0.0

    # ----------------------------------------------------------------- prediction

    def _predict(self, s: _State, t: float) -> np.ndarray:
        dt = t - s.t
        a = self.g if s.free else 0.0
        return s.xy + s.v * dt + 0.5 * a * dt * dt

    def _thresholds(self, image: np.ndarray, preds: np.ndarray) -> None:
        """Noise floor and the bodies' contrast from the first frame."""
        floor = noise_threshold(image, self.bg)
        diff = difference(image, self.bg)
        values = []
        for (u, v), s in zip(preds, self.states, strict=True):
            r = max(1, int(0.4 * s.radius))
            iu, iv = round(u), round(v)
            if r <= iu < self.w - r and r <= iv < self.h - r:
                # The 90th percentile: a thin body (an arm) covers little of the square.
                patch = diff[iv - r : iv + r + 1, iu - r : iu + r + 1]
                s.contrast = float(np.percentile(patch, 90))
                values.append(s.contrast)
        contrast = float(np.median(values)) if values else 4 * floor
        for s in self.states:
            s.contrast = s.contrast or contrast
        self.low = max(floor, 0.2 * contrast)
        self.high = max(self.low + 1.0, 0.5 * contrast)

    # ----------------------------------------------------------------- one frame

    def update(self, image: np.ndarray, t: float) -> None:
        """Track the bodies in one frame ``(H, W, 3)`` uint8 at time ``t`` (s, increasing)."""
        if image.shape != self.bg.shape:
            raise TrackError(
                f"frame {self.frames} is {image.shape[1]}x{image.shape[0]} px; the background is "
                f"{self.bg.shape[1]}x{self.bg.shape[0]} px: give a plate of this camera's view"
            )
        first = self.t0 is None
        if first:
            self.t0 = t
        t = t - self.t0  # type: ignore[operator]
        preds_xy = np.array([self._predict(s, t) for s in self.states])
        preds = self.cal.to_image(preds_xy)
        if first:
            self._thresholds(image, preds)
        gates = np.empty(len(self.states))
        reach = np.empty(len(self.states))
        for i, s in enumerate(self.states):
            if first:
                gates[i] = max(2.0 * s.radius, 12.0)
            else:
                gates[i] = 0.75 * s.radius + 3.0 + 1.5 * s.step + s.missed * (s.radius + s.step)
            reach[i] = s.radius + gates[i] + 0.5 * s.step + 3.0
        found = self._measure(image, preds, gates, reach, t)
        for i, s in enumerate(self.states):
            blob = found.get(i)
            if blob is None:
                if first:
                    u, v = preds[i]
                    raise BodyNotFoundError(
                        f"body {s.body.name!r} is not in the first frame: expected near pixel "
                        f"(u={u:.0f}, v={v:.0f}) of the {self.w}x{self.h} image (its initial "
                        f"position {tuple(round(c, 3) for c in s.body.position)} m through the "
                        "calibration); check the scene, --seed, --start and the calibration"
                    )
                if s.missed == 0:
                    s.gap_start = s.t
                s.missed += 1
                continue
            self._accept(s, *blob, t)
        self.frames += 1
        self.t_last = t

    def _accept(self, s: _State, blob: Blob, pose: PlanePose, t: float) -> None:
        xy = pose.xy
        dt = t - s.t
        if s.rows and dt > 0:
            a = self.g if s.free else 0.0
            s.v = (xy - s.xy) / dt + 0.5 * a * dt
            s.step = float(np.hypot(*(blob.centre - self.cal.to_image(s.xy)))) / max(
                1, s.missed + 1
            )
        angle = self._angle(s, pose, t) if s.k else None
        if s.missed:
            s.gaps += 1
            if s.gap_start is not None and t - s.gap_start > self.max_gap:
                s.lost.append((s.gap_start, t))
        s.missed, s.gap_start = 0, None
        s.xy, s.t = xy, t
        s.rows.append((t, float(xy[0]), float(xy[1]), math.nan if angle is None else angle))
        s.uv_rows.append((t, blob.u, blob.v))

    def _angle(self, s: _State, pose: PlanePose, t: float) -> float | None:
        assert s.angle is not None
        if s.k == 2:
            if pose.elongation < 0.5 * (1 + ELONGATED):
                return None  # too round in this frame (motion blur along the short axis)
            axis = pose.axis - s.offset
        else:
            axis = pose.square - s.offset
        period = 2 * math.pi / s.k
        guess = s.angle + s.omega * (t - s.t)
        angle = guess + ((axis - guess + period / 2) % period - period / 2)
        if t > s.t:
            s.omega = (angle - s.angle) / (t - s.t)
        s.angle = angle
        return angle

    def _windows(self, preds: np.ndarray, reach: np.ndarray) -> list[tuple[list[int], tuple]]:
        """Bodies grouped by overlapping search windows, with each group's window
        ``(r0, r1, c0, c1)``."""
        boxes = []
        for (u, v), r in zip(preds, reach, strict=True):
            boxes.append(
                [
                    max(0, math.floor(v - r)),
                    min(self.h, math.ceil(v + r) + 1),
                    max(0, math.floor(u - r)),
                    min(self.w, math.ceil(u + r) + 1),
                ]
            )
        groups = [([i], b) for i, b in enumerate(boxes) if b[0] < b[1] and b[2] < b[3]]
        merged = True
        while merged:
            merged = False
            for a in range(len(groups)):
                for b in range(a + 1, len(groups)):
                    ba, bb = groups[a][1], groups[b][1]
                    if ba[0] < bb[1] and bb[0] < ba[1] and ba[2] < bb[3] and bb[2] < ba[3]:
                        box = [min(ba[0], bb[0]), max(ba[1], bb[1])]
                        box += [min(ba[2], bb[2]), max(ba[3], bb[3])]
                        groups[a] = (groups[a][0] + groups[b][0], box)
                        del groups[b]
                        merged = True
                        break
                if merged:
                    break
        return [(ids, tuple(box)) for ids, box in groups]

    def _weights(
        self,
        i: int,
        coverage: np.ndarray,
        diff: np.ndarray,
        colour: np.ndarray,
        behind: np.ndarray,
    ) -> np.ndarray:
        """Pixel weights for body ``i``'s pose. A disc keeps its coverage (saturated from half
        its contrast up, so its shading does not pull the centre). A body that turns is weighed
        by the share of the exposure each pixel saw it (:func:`_alpha`): a turning body's motion
        blur is lopsided (its far end sweeps more), and only that weight keeps its centre at the
        exposure's middle (a swinging arm: 1 cm off with the coverage)."""
        if not self.states[i].k:
            return coverage
        return _alpha(colour, behind, diff)

    def _outline(self, i: int, uv: np.ndarray, t: float) -> Outline:
        """Body ``i``'s outline in the image at its prediction ``uv`` (px) for time ``t``: its
        polygon at the predicted angle through the calibration, or a disc."""
        s = self.states[i]
        if s.angle is None or not hasattr(s.body.shape, "vertices"):
            return Outline(s.radius)
        pts = np.asarray(s.body.shape.vertices(), dtype=float)
        pts = pts - _area_centroid(pts)
        a = s.angle + s.omega * (t - s.t)
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        xy = self._predict(s, t)
        return Outline(s.radius, self.cal.to_image(xy + pts @ rot.T) - uv)

    def _measure(
        self,
        image: np.ndarray,
        preds: np.ndarray,
        gates: np.ndarray,
        reach: np.ndarray,
        t: float,
    ) -> dict[int, tuple[Blob, PlanePose]]:
        from scipy.optimize import linear_sum_assignment

        found: dict[int, tuple[Blob, PlanePose]] = {}
        for ids, (r0, r1, c0, c1) in self._windows(preds, reach):
            diff = difference(image[r0:r1, c0:c1], self.bg[r0:r1, c0:c1])
            small = min(self.states[i].area for i in ids)
            blobs = find_blobs(diff, self.low, self.high, offset=(r0, c0), min_area=0.15 * small)
            if not blobs:
                continue
            centres = np.array([b[0].centre for b in blobs])
            dist = np.hypot(*(preds[ids][:, None, :] - centres[None]).transpose(2, 0, 1))
            big = 1e9
            cost = np.where(dist <= gates[ids][:, None], dist, big)
            rows, cols = linear_sum_assignment(cost)
            owner: dict[int, list[int]] = {}
            for r, c in zip(rows, cols, strict=True):
                if cost[r, c] < big:
                    owner.setdefault(int(c), []).append(ids[r])
            # A body left out whose nearest blob holds more than one body's area shares it.
            for j, i in enumerate(ids):
                if any(i in v for v in owner.values()):
                    continue
                for c in np.argsort(dist[j]):
                    _, u, v, _ = blobs[c]
                    if np.hypot(u - preds[i, 0], v - preds[i, 1]).min() > gates[i]:
                        continue  # the prediction is not on this blob
                    taken = owner.get(int(c), [])
                    expected = sum(self.states[k].area for k in taken) + self.states[i].area
                    if blobs[c][0].area > 0.6 * expected:
                        owner.setdefault(int(c), []).append(i)
                        break
            for c, members in owner.items():
                blob, u, v, w = blobs[c]
                rows, cols = v.astype(np.intp), u.astype(np.intp)
                d = diff[rows - r0, cols - c0]
                img, bg = image[rows, cols], self.bg[rows, cols]
                if len(members) == 1:
                    i = members[0]
                    found[i] = (
                        blob,
                        plane_pose(u, v, self._weights(i, w, d, img, bg), self.cal),
                    )
                    continue
                outlines = [self._outline(i, preds[i], t) for i in members]
                centres, owner, inside = split_pixels(u, v, w, preds[members], outlines)
                for j, i in enumerate(members):
                    mine = owner == j
                    part = blob_from_pixels(u[mine], v[mine], w[mine])
                    fit = mine & inside
                    if part is None or not fit.any():
                        continue
                    part = replace(part, u=float(centres[j, 0]), v=float(centres[j, 1]))
                    # Centre from the pixels inside the outline, axes from all the body owns.
                    # Weighed over its own pixels only: a shared blob holds other bodies'
                    # colours, which would spoil the hue a turning body is unmixed with.
                    wi = np.zeros_like(w)
                    wi[mine] = self._weights(i, w[mine], d[mine], img[mine], bg[mine])
                    centre = plane_pose(u[fit], v[fit], wi[fit], self.cal)
                    axes = plane_pose(u[mine], v[mine], wi[mine], self.cal)
                    found[i] = (part, replace(axes, xy=centre.xy))
        return found

    # ----------------------------------------------------------------- result

    def result(self, calibration_error: float | None = None, fps: float = 0.0) -> TrackResult:
        """The recording, summary and image tracks of the frames seen so far."""
        from physbench.recording import Recording, Track

        if self.frames == 0:
            raise TrackError("no frames were tracked: the video (or its --start/--end) is empty")
        tracks, pixels = {}, {}
        lost: dict[str, list[tuple[float, float]]] = {}
        for s in self.states:
            pixels[s.body.name] = np.array(s.uv_rows, dtype=float)
        accuracy = self._accuracy(pixels)
        contacts: dict[str, int] = {}
        for s in self.states:
            rows = np.array(s.rows, dtype=float)
            if s.free:
                hit = contact_samples(rows[:, 0], rows[:, 1:3], self.g, accuracy)
                if hit.any():
                    contacts[s.body.name] = int(hit.sum())
                    rows = rows[~hit]
            angle = rows[:, 3] if s.k and not np.isnan(rows[:, 3]).any() else None
            tracks[s.body.name] = Track(rows[:, 0], rows[:, 1], rows[:, 2], angle)
            gone = list(s.lost)
            if s.missed and s.gap_start is not None and self.t_last - s.gap_start > self.max_gap:
                gone.append((s.gap_start, self.t_last))
            if gone:
                lost[s.body.name] = gone
        fields = ("x", "y", "angle") if any(t.angle is not None for t in tracks.values()) else None
        recording = Recording(tracks, fields=fields, source="video", meta={}, accuracy=accuracy)
        summary = TrackSummary(
            self.frames,
            self.t_last,
            {s.body.name: len(s.rows) for s in self.states},
            {s.body.name: s.gaps + (1 if s.missed else 0) for s in self.states},
            lost,
            self.cal.reprojection_error if calibration_error is None else calibration_error,
            fps,
            contacts,
        )
        return TrackResult(recording, summary, pixels)

    def _accuracy(self, pixels: Mapping[str, np.ndarray]) -> float:
        """:data:`ACCURACY_PX` in metres where the scene's scale is coarsest along the tracks."""
        seen = [tuv[:, 1:][np.isfinite(tuv[:, 1:]).all(axis=1)] for tuv in pixels.values()]
        points = np.concatenate([uv[:: max(1, len(uv) // 16)] for uv in seen if len(uv)])
        if not len(points):
            return 0.0
        return ACCURACY_PX * max(self.cal.metres_per_pixel(p) for p in points)


def track_frames(
    frames: Iterable[Frame],
    scene: Scene,
    calibration: Calibration,
    background: np.ndarray,
    *,
    max_gap: float = MAX_GAP,
    progress: bool = False,
) -> TrackResult:
    """Track ``scene``'s bodies through decoded ``frames`` against ``background``."""
    import sys

    tracker = Tracker(scene, calibration, background, max_gap=max_gap)
    tic = _time.perf_counter()
    for fr in frames:
        tracker.update(fr.image, fr.time)
        if progress and tracker.frames % 100 == 0:
            print(f"\r  {tracker.frames} frames", end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    fps = tracker.frames / max(_time.perf_counter() - tic, 1e-9)
    return tracker.result(fps=fps)


def track_video(
    path: str | Path,
    scene: Scene,
    calibration: Calibration | None = None,
    *,
    start: float | None = None,
    end: float | None = None,
    background: np.ndarray | str | Path | None = None,
    max_gap: float = MAX_GAP,
    progress: bool = False,
) -> TrackResult:
    """Track ``scene``'s bodies through the video at ``path`` (see the module docstring).

    ``path``: a video file, or a folder of images taken at the scene's frame rate.
    ``calibration``: pixels to metres (default :func:`bounds_calibration`); ``start``/``end``: the
    part of the video to track (s; recording time 0 is the first frame at or after ``start``);
    ``background``: an image of the empty scene (array or file; default: the median of the
    clip, which costs a second pass over the video)."""
    from physbench.video.background import load_plate, median_background
    from physbench.video.reader import VideoError, VideoReader

    try:
        # A folder of images has no timestamps: its frames come at the scene's rate.
        reader = VideoReader(path, start=start, end=end, fps=scene.fps)
        info = reader.info()
        if calibration is None:
            calibration = bounds_calibration(scene, (info.height, info.width))
        if isinstance(background, str | Path):
            background = load_plate(background)
        median = None
        if background is None:
            background = median = median_background(
                VideoReader(path, start=start, end=end, fps=scene.fps)
            )
        background = np.asarray(background)
        if background.ndim != 3 or background.shape[2] != 3 or background.dtype != np.uint8:
            raise TrackError(
                f"background has shape {background.shape} and dtype {background.dtype}; expected "
                "an (H, W, 3) uint8 RGB image"
            )
        if background.shape[:2] != (info.height, info.width):
            raise TrackError(
                f"background is {background.shape[1]}x{background.shape[0]} px; the video "
                f"{str(path)!r} is {info.width}x{info.height} px: give a plate of this camera's "
                "view"
            )
        try:
            return track_frames(
                reader.frames(), scene, calibration, background, max_gap=max_gap, progress=progress
            )
        except BodyNotFoundError as exc:
            if median is None:
                raise
            raise BodyNotFoundError(
                f"{exc}; the background is the median of the clip, which holds a body that stays "
                "put for most of it: film the empty scene and give it as the background"
            ) from None
    except VideoError as exc:
        raise TrackError(str(exc)) from None


def _alpha(colour: np.ndarray, behind: np.ndarray, diff: np.ndarray) -> np.ndarray:
    """The share of the exposure each pixel saw an opaque body, from its colour ``(n, 3)`` and
    the background's there ``(n, 3)``. A pixel is the mix ``alpha * shade * body + (1 - alpha)
    * background``: the body's hue is known (its most contrasted pixels), its brightness
    ``shade`` is not (light and shading change along a long body), so the colour difference is
    unmixed per pixel into the body's hue and the background's, two unknowns from three
    channels. Unlike a contrast ratio this holds on a textured wall and under uneven light.
    Where the background has nearly the body's hue the two cannot be told apart, and the
    difference is projected on a constant body colour instead."""
    c = colour.astype(np.float64)
    g = behind.astype(np.float64)
    n = len(c)
    if n < 4:
        return np.ones(n)
    hue = np.median(c[diff >= np.percentile(diff, 80)], axis=0)
    d = c - g
    bb = float(hue @ hue)
    bg = g @ hue
    gg = np.einsum("ij,ij->i", g, g)
    det = bb * gg - bg * bg
    alpha = (bg * (d @ hue) - bb * np.einsum("ij,ij->i", g, d)) / np.maximum(det, 1e-9)
    flat = det < 0.05 * bb * gg  # hues too alike to unmix
    if flat.any():
        alpha[flat] = _project(c[flat], g[flat], np.broadcast_to(hue, c[flat].shape))
    return np.clip(alpha, 0.0, None)


def _project(colour: np.ndarray, behind: np.ndarray, body: np.ndarray) -> np.ndarray:
    """Alpha of each pixel: ``colour - behind`` projected onto ``body - behind``."""
    span = body - behind
    norm = np.einsum("ij,ij->i", span, span)
    return np.einsum("ij,ij->i", colour - behind, span) / np.maximum(norm, 1.0)
