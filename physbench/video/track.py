"""Following a scene's bodies through a video: :func:`track_video` -> a recording in metres.

1. **Background**: a plate of the empty scene, or the median of the clip
   (:mod:`~physbench.video.background`).
2. **Light**: each frame's gain and offset against the background are measured away from the
   bodies (:mod:`~physbench.video.photometry`), and the difference to the background is taken in
   that frame's light; the noise threshold is that frame's, and the bodies' contrast (from the
   first frame) follows the gain. A light that drifts, or a first frame brighter than a median
   background, moves no threshold.
3. **Start**: the scene's initial body positions, projected into the first frame through the
   calibration, say where to look; each body in view takes the blob found near its projection. A
   body in view with none is a :class:`BodyNotFoundError` that names the measured cause (too
   little contrast, a blob of its size elsewhere, nothing there) and the fix for it. A body the
   scene puts outside the view may come in later.
4. **Each frame**: every body is predicted from the scene (:mod:`~physbench.video.motion`: gravity
   and the scene's forces for a free body, sliding along the static geometry it touches), searched
   in a window around the prediction within a gate that grows with the body's size and speed and
   with what the prediction cannot know (an unmodelled acceleration over the time since the body
   was last seen: large at low frame rates), and blobs are assigned to bodies optimally
   (:func:`scipy.optimize.linear_sum_assignment`). A body left without a blob whose neighbour's
   blob is too big for one body shares that blob. A disc's centre is fitted to its outline
   (:mod:`~physbench.video.silhouette`: shading and highlights do not move it, nor a rod, a
   shadow or a hand joined to its blob); other bodies are measured by their pixels' centroid on
   the plane. A detection whose size or colour is not the body's is rejected
   (:mod:`~physbench.video.appearance`).
5. **Unseen**: a body not found in a frame where it is in view has no row for that frame (nothing
   is filled in); the summary says from when to when it was lost, and a body unseen in more than
   :data:`~physbench.video.outcome.LOST_SHARE` of the frames where it was in view fails the
   tracking (:class:`TrackLostError`) unless gaps are allowed. A body whose prediction leaves the
   view near where it was last seen is out of view, not lost.
6. **Accuracy**: each track's noise is measured from its fifth differences in time (a smooth
   motion's are near zero), and the recording states ``max(floor, 2 x noise)`` in metres
   (:data:`DISC_ACCURACY_PX` for discs, :data:`ACCURACY_PX` for other bodies) for discover's
   significance floor.

Angles are measured for bodies whose outline shows them (boxes, elongated polygons, a pendulum's
arm), not for discs; a square's angle is known modulo 90 degrees and an elongated body's modulo
180, and the tracker unwraps it by continuity from the scene's initial angle.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from physbench.errors import PhysbenchError, PhysbenchWarning
from physbench.scene import Box, Circle
from physbench.video import compiled, medians
from physbench.video.accuracy import stated_accuracy, stated_angle_accuracy
from physbench.video.appearance import COLOUR_PIXELS, HIDDEN, Appearance, Look, matching
from physbench.video.compiled import jit, pairwise_sum
from physbench.video.contacts import contact_samples
from physbench.video.detect import (
    CROSS,
    Outline,
    PlanePose,
    blob_from_pixels,
    find_blobs,
    plane_points,
    plane_pose,
    split_pixels,
)
from physbench.video.faint import (
    FIXED_TRIES,
    GHOST_FRAMES,
    SHUTTER,
    SIGNIFICANCE,
    Faint,
    FirstFrame,
    find_faint,
    ghost_reach,
    ghosts_of,
    look_elsewhere,
)
from physbench.video.held import COVER, MARGIN
from physbench.video.motion import Motion
from physbench.video.outcome import Spans, TrackSummary
from physbench.video.photometry import DEVIATIONS, Light, LightMeter
from physbench.video.silhouette import (
    DiscFit,
    Rays,
    fit_discs,
    window_edges,
)
from physbench.video.steadiness import MOVED_PX, ShiftMeter
from physbench.video.transfer import Decoder

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.recording import Recording, Track
    from physbench.scene import Body, Scene
    from physbench.video.background import MedianFrames
    from physbench.video.reader import Frame

#: Ratio of a body's principal second moments above which its long axis gives its angle.
ELONGATED = 1.3
#: The acceleration a prediction cannot know (friction, drag, a push, a swing), as a share of the
#: scene's gravity: the gate allows for it over the time since the body was last seen.
UNMODELLED = 0.5
#: How far a body's first move may depart from the scene's initial velocity, as a share of it.
VELOCITY_PRIOR = 0.5
#: The restitution a body is predicted to bounce off static geometry with until it is seen again;
#: the gate covers any restitution from 0 (it stays on the surface) to 1 (elastic).
RESTITUTION = 0.5
#: How far from where the scene says it starts (px) a body not found there is looked for in the
#: first frame (:meth:`Tracker._look_wider`); a blob farther off is named in the error instead.
FIRST_GATE_PX = 24.0
#: A body's appearance is learnt from detections within this factor of the size the scene gives
#: it (until the first, no detection of it is judged by its looks).
PLAUSIBLE = 1.8
#: An edge may be this share of the foreground threshold faint.
EDGE_SHARE = 0.75
#: A disc that moves more than this share of its radius in a frame interval is fitted as the
#: stadium its motion blur makes.
SMEAR = 0.2
#: A disc that moves more than this many radii in a frame interval keeps the edges that look like
#: a halo of bled colour in its fit: a long smear's ends fade out over its length (a thrown ball
#: moving 3 radii a frame was measured 0.13 px further from the truth without them; lit
#: spheres moving 0.2-0.7 radii a frame nearer: 0.32 to 0.28 px at the 95th percentile at 13 px).
HALO_MOTION = 1.0
#: A blob within this share of a body's radius, plus :data:`RIM_PX`, of where it was found in
#: the first frame is a fragment of its rim: a clip's median mended where a ball rested
#: (``held.COVER`` and ``held.MARGIN``, the same reach) left 4 px of its edge apart from its
#: blob, nearer the scene's start than the ball, and a 36 px ball was refused as "not clear".
RIM, RIM_PX = COVER, MARGIN
#: Frames this many intervals apart or more (the median's, which a scout tracks,
#: :mod:`~physbench.video.held`) give a disc no direction of smear: its velocity is the mean
#: over the gap, which bounces turn, so a stadium along it fits worse than the circle, and the
#: stadium's every direction was tried (18 ms of a 5 s clip's 0.8 s on the rack of
#: ``benchmarks/track_speed.py``). The circle's centre is the smear's middle.
SPARSE = 1.5
#: A disc of a smaller radius (px) has too few pixels of outline for rays: its centroid is
#: taken where no outline fits.
SMALL_DISC = 5.0
#: A small disc missing from the blobs is first looked for this many of its recent prediction
#: errors (RMS, px; times the frames since it was seen) from its prediction, a pixel more, where
#: a matched filter's peak needs less significance than in its whole gate (fewer places for the
#: noise to reach it): a 2 px ball in flight, predicted within 2 px, whose gate had grown to
#: 40-90 px with its speed, stood 5.7-7.8 robust deviations high where 8.5-9.7 were asked.
NEAR = 3.0
#: The least significance (robust deviations) a detection near the prediction needs.
NEAR_SIGNIFICANCE = 5.0
#: Only a prediction this good is searched near: at most this many frames since the body was
#: seen, and the place within this many of its radii and 2 px (a body lost for 5 frames had a
#: nearby search of 37 px, which took a speck 30 px from it); and only a body with no other
#: expected or found within its gate (two balls flying side by side: the lighter, searched
#: near, took the heavier's disc for 18 frames).
NEAR_MISSED = 1
NEAR_RADII = 3.0
#: The share a new prediction error takes in a body's running RMS.
NEAR_RATE = 0.25
#: Two bodies measured closer than this share of the sum of their radii are one thing measured
#: twice (rigid bodies touch at the sum; this leaves room for a pixel or so of noise on balls
#: of a few pixels).
OVERLAP = 0.75
#: A disc (of :data:`SMALL_DISC` px or more) whose median contrast in the first frame is under
#: this multiple of the noise threshold loses a share of its pixels to it (a mid-grey puck on
#: bricks): the threshold then comes down to what the background's difference measured
#: (:meth:`Tracker._tail_deviations`).
FAINT_DISC = 1.5
#: The quantile of the first frame's difference, away from the bodies, that the noise threshold
#: may come down to for a faint disc, and how far it may come down (robust deviations).
TAIL_QUANTILE = 0.9999
MIN_DEVIATIONS = 3.0
#: A turning body is measured on its pixels down to this share of the frame's threshold that
#: are joined to its blob (its blurred far end).
FAINT_END = 0.5
#: The quantiles of a turning rod's pixels along its axis taken as its ends, and the range of
#: their span (over the quantiles' share) as a fraction of its length in which they are trusted.
ENDS_QUANTILE = 0.01
ENDS_SPAN = (0.9, 1.1)
#: Under this share of its length, a rod's blob is taken as cut short at an end whose
#: background is unknown (see ``Tracker._from_one_end``).
ENDS_WHOLE = 0.97
#: A rod's end this close (px) to pixels whose background is unknown is taken as hidden there.
UNKNOWN_NEAR = 3.0
#: A body lost with a smaller radius (px) is said to be too small for the video's coding: on the
#: field camera at CRF 18-30, balls of 0.8-1.9 px were absent from the coded pixels themselves
#: (benchmarks/field_visibility.py) in more than a tenth of the frames in 46 of 51 refused clips.
TINY = 2.5


class TrackError(PhysbenchError, ValueError):
    """A video that cannot be tracked against a scene: names the body, frame or value."""


class BodyNotFoundError(TrackError):
    """A scene body with no blob near where the scene says it starts."""


class TrackLostError(TrackError):
    """A body lost for more than :data:`~physbench.video.outcome.LOST_SHARE` of the frames where
    it was in view; the tracking's :class:`TrackResult` is ``result``."""

    def __init__(self, message: str, result: TrackResult) -> None:
        super().__init__(message)
        self.result = result


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


def _long_extent(body: Body, offset: float) -> float | None:
    """The length (m) of an elongated body along its long axis (at ``offset`` in its frame), if
    its outline is symmetric under a half turn about its centroid (a box, a rod), so that the
    middle of its two ends is its centre; ``None`` otherwise."""
    if isinstance(body.shape, Circle):
        return None
    pts = np.asarray(body.shape.vertices(), dtype=float)
    pts = pts - _area_centroid(pts)
    scale = float(np.abs(pts).max())
    if scale <= 0 or any(np.hypot(*(pts + p).T).min() > 1e-6 * scale for p in pts):
        return None
    s = pts @ np.array([math.cos(offset), math.sin(offset)])
    return float(s.max() - s.min())


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
    length: float | None  # m along the long axis, where its ends' middle is its centre
    free: bool
    xy: np.ndarray
    v: np.ndarray
    t: float
    angle: float | None
    omega: float = 0.0
    contrast: float = 0.0  # grey levels against the background, from the first frame
    step: float = 0.0  # px moved in the last frame interval
    missed: int = 0  # frames since it was last seen
    seen: int = 0
    last_uv: np.ndarray | None = None
    trail: list[np.ndarray] = field(default_factory=list)  # the last GHOST_FRAMES places
    contact: np.ndarray | None = None  # normal of the static its prediction touches
    bounce: float = 0.0  # m/s: the speed off a surface it hit, unknown until it is seen again
    look: Appearance | None = None
    radius_m: float | None = None  # a disc's radius on the plane, from its outlines so far
    rejected: int = 0  # detections whose appearance was not the body's
    centroids: int = 0  # a disc's frames measured by their centroid (no outline fitted)
    error2: float | None = None  # px^2, running mean square of its one-frame prediction errors
    in_view: int = 0
    unseen: Spans = field(default_factory=Spans)
    out: Spans = field(default_factory=Spans)
    rows: list[tuple[float, float, float, float]] = field(default_factory=list)
    uv_rows: list[tuple[float, float, float]] = field(default_factory=list)

    @property
    def disc(self) -> bool:
        return isinstance(self.body.shape, Circle)

    @property
    def mpp0(self) -> float:
        """Metres per pixel where the body starts."""
        return self.body.shape.extent() / self.radius


@dataclass(frozen=True)
class _Found:
    """One body's measurement in one frame: centre ``xy`` (m) and ``uv`` (px), the pose for its
    angle, what it looks like, and a disc's radius where its outline gave one."""

    xy: np.ndarray
    uv: np.ndarray
    pose: PlanePose
    look: Look
    radius: float | None = None  # m, a disc's radius fitted freely to its outline
    centroid: bool = False  # a disc measured by its centroid, without an outline
    split: bool = False  # a small disc measured on a blob it shares: its velocity is not learnt


@dataclass(frozen=True)
class _Plan:
    """Where to look for a disc's outline in one frame (its rays), the metres per pixel there and
    the area (px) the scene gives it there."""

    rays: Rays
    mpp: float
    expected: float
    known: float | None = None
    pixels: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # its colour's, if shared


@dataclass(frozen=True)
class TrackResult:
    """The :class:`~physbench.recording.Recording` (scene metres, t = 0 at the first frame), the
    :class:`TrackSummary`, each body's image track ``(t, u, v)`` (px) for overlays, and
    ``measured``: the recording with every frame where a body was measured, those whose exposure
    spans a collision included. The recording leaves those out (a blurred pose across a
    collision is no state to fit); where a frame's pixels are split among the bodies
    (:func:`~physbench.video.footage.video_observation`) the measured pose is still the best
    guess, and one interpolated across the collision is not."""

    recording: Recording
    summary: TrackSummary
    pixels: dict[str, np.ndarray]
    measured: Recording
    #: The background tracked against (the clip's median mended where it held a body), where
    #: :func:`track_video` took it from the clip; ``None`` where it was given.
    background: np.ndarray | None = None


class Tracker:
    """Frame-by-frame tracking of ``scene``'s bodies against ``background`` (see the module
    docstring). Call :meth:`update` with each frame in order, then :meth:`result`. ``median``:
    the background is the median of the clip (a first-frame failure says what that implies);
    ``transfer``: how the pixel values encode light (:mod:`~physbench.video.transfer`)."""

    def __init__(
        self,
        scene: Scene,
        calibration: Calibration,
        background: np.ndarray,
        *,
        median: bool = False,
        transfer: str = "linear",
        subsampled: bool = False,
        unknown: np.ndarray | None = None,
        steady: ShiftMeter | None = None,
    ) -> None:
        self.scene, self.cal, self.bg = scene, calibration, background
        self.unknown = unknown  # where the background holds a body that no frame showed off it
        self.subsampled = subsampled  # colour at a lower resolution: discs fitted without halos
        self.linear = Decoder(transfer)  # pixel values to linear light, for the unmixing
        self.h, self.w = background.shape[:2]
        self.g = np.asarray(scene.gravity, dtype=float)
        self.motion = Motion(scene)
        self.meter = LightMeter(background)
        self.light = Light.unchanged()
        self.steady = ShiftMeter(background) if steady is None else steady.anew()
        self.moved = Spans()  # frames whose picture lies MOVED_PX or more off the background's
        self.largest_shift = 0.0  # px
        self.median = median
        self.states: list[_State] = []
        for body in scene.bodies:
            xy = np.asarray(body.position, dtype=float)
            mpp = calibration.metres_per_pixel(calibration.to_image(xy))
            k, offset = _symmetry(body)
            self.states.append(
                _State(
                    body,
                    body.shape.extent() / mpp,
                    body.shape.area() / mpp**2,
                    k,
                    offset,
                    _long_extent(body, offset) if k == 2 else None,
                    self.motion.free[body.name],
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
        self.low = self.high = self.edge_low = 0.0
        self.contrast = 0.0  # the bodies' median contrast in the first frame's light
        self.deviations = DEVIATIONS  # the noise threshold in robust deviations
        self.scale0 = 1.0  # the first frame's gain
        self.brighter = 1.0  # this frame's gain over the first's
        self.max_gate = 0.5 * max(self.h, self.w)
        self.pred_xy = np.zeros((len(self.states), 2))
        self.pred_uv = np.zeros((len(self.states), 2))
        self.t_next = 0.0  # the time of the frame being tracked
        self._mpp_cells: dict[tuple[int, int], float] = {}
        #: The first frame, where a small disc is to be tracked (:meth:`_faint`), and the fixed
        #: spots of the scene it showed (px), which no faint search takes for a body.
        self.first_frame: FirstFrame | None = None
        self.fixed: list[np.ndarray] = []

    # ----------------------------------------------------------------- prediction

    def _predict(self, t: float) -> None:
        """Every body's predicted position at ``t`` (scene metres and pixels), and the static
        each prediction touches."""
        for i, s in enumerate(self.states):
            dt = t - s.t
            kick = self.motion.kick(s.body.name, s.t, dt)
            angle = s.angle if s.angle is not None else s.body.angle
            xy, s.contact = self.motion.slide(s.body, angle, s.xy, s.v * dt + kick.dx)
            self.pred_xy[i] = xy
        self.pred_uv = self.cal.to_image(self.pred_xy)

    def _in_view(self, s: _State, uv: Sequence[float]) -> bool:
        """Whether to look for ``s`` at its prediction ``uv``: it is there (its centre at least
        half its radius inside the image), or it was last seen away from the image's edges (a
        prediction may leave the view while the body is hidden in it)."""
        m = 0.5 * s.radius
        if m - 0.5 <= uv[0] <= self.w - 0.5 - m and m - 0.5 <= uv[1] <= self.h - 0.5 - m:
            return True
        if s.last_uv is None:
            return False
        edge = s.radius + 2 * s.step + 3
        u, v = s.last_uv
        return min(u, v, self.w - 1 - u, self.h - 1 - v) > edge

    def _gates(self, t: float, first: bool) -> tuple[np.ndarray, np.ndarray]:
        """Per body the gate (px: how far from its prediction a detection may be) and the reach
        of its search window (px)."""
        gates = np.empty(len(self.states))
        reach = np.empty(len(self.states))
        g = float(np.hypot(*self.g))
        for i, s in enumerate(self.states):
            if first:
                gates[i] = max(2.0 * s.radius, 12.0)
            else:
                dt = t - s.t
                unknown = UNMODELLED * g * dt * dt / 2  # metres
                if s.seen < 2:  # its velocity is the scene's guess until measured
                    unknown += VELOCITY_PRIOR * float(np.hypot(*s.v)) * dt
                unknown += s.bounce * dt
                gates[i] = (
                    0.75 * s.radius
                    + 3.0
                    + 1.5 * s.step
                    + s.missed * (s.radius + s.step)
                    + unknown / s.mpp0
                )
                if s.seen == 0:
                    gates[i] += max(2.0 * s.radius, 12.0)
            gates[i] = min(gates[i], self.max_gate)
            reach[i] = s.radius + gates[i] + 0.5 * s.step + 3.0
        return gates, reach

    # ----------------------------------------------------------------- light and thresholds

    def _first_contrast(self, image: np.ndarray, visible: list[bool], reach: np.ndarray) -> None:
        """The bodies' contrast in the first frame: the 90th percentile of the difference near
        each prediction (a thin body, an arm, covers little of the square). Where a disc's median
        there is faint for the noise threshold, the threshold comes down to the background's
        measured tail (:meth:`_tail_deviations`)."""
        values, faint = [], False
        for i, s in enumerate(self.states):
            if not visible[i]:
                continue
            r = max(1, int(0.4 * s.radius))
            iu, iv = (round(c) for c in self.pred_uv[i])
            if r <= iu < self.w - r and r <= iv < self.h - r:
                box = (slice(iv - r, iv + r + 1), slice(iu - r, iu + r + 1))
                patch = self.light.difference(image[box], self.bg[box])
                mid, s.contrast = (float(q) for q in np.percentile(patch, [50, 90]))
                values.append(s.contrast)
                # A disc of a few pixels has no inside to take a median over (its box is
                # mostly rim and wall); it is found by its centroid or a matched filter instead.
                outlined = s.disc and s.radius >= SMALL_DISC
                faint |= outlined and mid < FAINT_DISC * self.light.threshold()
        self.contrast = float(np.median(values)) if values else 4 * self.light.threshold()
        for s in self.states:
            s.contrast = s.contrast or self.contrast
        self.scale0 = max(self.light.scale, 1e-3)
        if faint:
            self.deviations = self._tail_deviations(image, reach)

    def _tail_deviations(self, image: np.ndarray, reach: np.ndarray) -> float:
        """Called once, in the first frame, where a disc is faint for the noise threshold: the
        :data:`TAIL_QUANTILE` of the frame's difference away from every body's reach, in robust
        deviations, between :data:`MIN_DEVIATIONS` and :data:`DEVIATIONS`. Six deviations are
        a Gaussian guard; a textured, coded background's own tail is measured instead (on a
        brick wall at CRF 27: 4.3 deviations, against a puck whose median is 6.3)."""
        if self.light.sigma <= 0:
            return DEVIATIONS
        diff = self.light.difference(image, self.bg)
        vv, uu = np.ogrid[: self.h, : self.w]
        away = np.ones((self.h, self.w), dtype=bool)
        for (u, v), r in zip(self.pred_uv, reach, strict=True):
            away &= (uu - u) ** 2 + (vv - v) ** 2 > r * r
        if away.sum() < 1.0 / (1.0 - TAIL_QUANTILE):
            return DEVIATIONS
        tail = float(np.quantile(diff[away], TAIL_QUANTILE))
        return min(DEVIATIONS, max(MIN_DEVIATIONS, tail / self.light.sigma))

    def _thresholds(self) -> None:
        """This frame's thresholds: above its noise, and a share of the bodies' contrast in its
        light."""
        self.brighter = self.light.scale / self.scale0  # contrasts grow with the light
        contrast = self.contrast * self.brighter
        self.low = max(self.light.threshold(deviations=self.deviations), 0.2 * contrast)
        self.high = max(self.low + 1.0, 0.5 * contrast)
        # An edge is placed by its own half-way point, so it may be fainter than what makes a
        # blob: half the threshold, above 3 robust noise deviations (a lit limb nearly as bright
        # as the wall).
        self.edge_low = max(EDGE_SHARE * self.low, 3.0 * self.light.sigma, 8.0)

    def _high(self, group: list[int]) -> float:
        """The threshold a blob of a window holding ``group`` must reach somewhere: half the
        faintest contrast in this frame's light of those of :data:`SMALL_DISC` px or more, where
        that is under the frame's (half the bodies' median): a light puck beside a dark one was
        lost in 7 of 41 frames of its blurred, faintest moments, none of its pixels above the
        dark one's half. A body of a few pixels keeps the frame's: with the lower seed, two
        balls of 1.7-3.5 px at 1280x960 were tracked 50-60 px off (95th percentile) and a
        control named a cause; likely, as a blob of such a body is a pixel or two, noise just
        above the threshold made some (not measured)."""
        sized = [self.states[i].contrast for i in group if self.states[i].radius >= SMALL_DISC]
        if not sized:
            return self.high
        return max(self.low + 1.0, min(self.high, 0.5 * min(sized) * self.brighter))

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
        self.t_next = t
        self._predict(t)
        uvs = self.pred_uv.tolist()
        visible = [self._in_view(s, uv) for s, uv in zip(self.states, uvs, strict=True)]
        gates, reach = self._gates(t, first)
        self.light = self.meter.measure(image, np.column_stack([self.pred_uv, reach]))
        self._steadiness(image, t)
        if first:
            if not any(visible):
                raise BodyNotFoundError(self._none_in_view())
            self._first_contrast(image, visible, reach)
        self._thresholds()
        found = self._measure(image, gates, reach, t, visible)
        if first:
            self._look_wider(image, gates, reach, t, visible, found)
            self._sizes_at_start(image, found)
        self._one_each(found)
        for i in range(len(self.states)):
            if visible[i] and i not in found:
                rivals = [
                    (self.pred_uv[j], float(gates[j]))
                    for j in range(len(self.states))
                    if j != i and visible[j] and j not in found
                ]
                faint = self._faint(i, image, gates[i], found, rivals)
                if faint is not None:
                    found[i] = faint
        if first and any(s.disc and s.radius < SMALL_DISC for s in self.states):
            places = tuple(
                (float(f.uv[0]), float(f.uv[1]), self.states[i].radius + 2.0)
                for i, f in found.items()
            )
            self.first_frame = FirstFrame(image.copy(), self.light, places)
        for i, s in enumerate(self.states):
            if i in found:
                s.in_view += 1
                s.unseen.close()
                s.out.close()
                if s.seen >= 2 and s.missed == 0:
                    (fu, fv), (pu, pv) = found[i].uv.tolist(), self.pred_uv[i].tolist()
                    e2 = (fu - pu) * (fu - pu) + (fv - pv) * (fv - pv)
                    s.error2 = e2 if s.error2 is None else s.error2 + NEAR_RATE * (e2 - s.error2)
                self._accept(s, found[i], t)
                continue
            if first and visible[i]:
                raise BodyNotFoundError(self._not_found(i, image))
            s.missed += 1
            if visible[i]:
                s.in_view += 1
                s.unseen.mark(t)
                s.out.close()
            else:
                s.out.mark(t)
                s.unseen.close()
        self.frames += 1
        self.t_last = t

    def _steadiness(self, image: np.ndarray, t: float) -> None:
        """Whether the camera stayed put in this frame (:mod:`~physbench.video.steadiness`):
        the tracker does not follow a moving camera, but says that it moved."""
        shift = self.steady.measure(image, self.light)
        if shift is None or shift.size < MOVED_PX:
            self.moved.close()
            return
        self.moved.mark(t)
        self.largest_shift = max(self.largest_shift, shift.size)

    def _one_each(self, found: dict[int, _Found]) -> None:
        """Of two discs measured closer than :data:`OVERLAP` of the sum of their radii, the one
        whose prediction is nearer keeps the measurement: the other is unseen in this frame.
        Discs do not overlap so, so it is one thing measured twice (two small balls flying side
        by side, whose blob neither could be split along: each took it whole, and the lighter's
        track went on along the heavier). Other bodies may: arms joined at an elbow."""
        ids = sorted(i for i in found if self.states[i].disc)
        if len(ids) < 2:
            return
        uv = np.array([found[i].uv for i in ids])
        r = np.array([self.states[i].radius for i in ids])
        apart = np.hypot(*(uv[:, None] - uv[None]).transpose(2, 0, 1))
        for a, b in zip(*np.nonzero(np.triu(apart < OVERLAP * (r[:, None] + r), 1)), strict=True):
            i, j = ids[a], ids[b]
            if i in found and j in found:
                off = [float(np.hypot(*(found[k].uv - self.pred_uv[k]))) for k in (i, j)]
                del found[j if off[0] <= off[1] else i]

    def _look_wider(
        self,
        image: np.ndarray,
        gates: np.ndarray,
        reach: np.ndarray,
        t: float,
        visible: list[bool],
        found: dict[int, _Found],
    ) -> None:
        """In the first frame, a body not found near where the scene says it starts is looked
        for again out to :data:`FIRST_GATE_PX`, away
        from the bodies already found: a scene's initial position is a measurement or an
        estimate, and an uncalibrated lens moved a puck near the image's edge by 18-20 px."""
        missing = [v and i not in found for i, v in enumerate(visible)]
        if not any(missing):
            return
        wide = np.maximum(gates, FIRST_GATE_PX)
        more = self._measure(image, wide, reach + (wide - gates), t, missing)
        for i, got in more.items():
            if all(np.hypot(*(got.uv - f.uv)) > self.states[i].radius for f in found.values()):
                found[i] = got

    def _sizes_at_start(self, image: np.ndarray, found: dict[int, _Found]) -> None:
        """In the first frame, a disc found away from where the scene starts it, while a blob of
        another size sits nearer that start, is refused with both: the scene's radius is likely
        wrong, and blobs under a sixth of the area it gives are not taken for the body, so
        something else near by was (a ball toss with the radius 3.5 times too large followed
        the thrower's hand). A blob on the found disc's own rim (within :data:`RIM` of its
        radius and :data:`RIM_PX`) is a fragment of it, not another candidate."""
        for i, got in found.items():
            s = self.states[i]
            u, v = self.pred_uv[i]
            off = float(np.hypot(got.uv[0] - u, got.uv[1] - v))
            if not s.disc or off <= max(s.radius, 2.0):
                continue
            reach = math.ceil(off)
            r0, r1 = max(0, int(v) - reach), min(self.h, int(v) + reach + 1)
            c0, c1 = max(0, int(u) - reach), min(self.w, int(u) + reach + 1)
            crop = (slice(r0, r1), slice(c0, c1))
            diff = self.light.difference(image[crop], self.bg[crop])
            blobs = find_blobs(diff, self.low, self.high, offset=(r0, c0), min_area=2.0)
            rim = RIM * s.radius + RIM_PX
            near = [
                b
                for b, _, _, w in blobs
                if w.max() >= 1.0
                and np.hypot(b.u - u, b.v - v) < 0.5 * off
                and np.hypot(b.u - got.uv[0], b.v - got.uv[1]) > rim
            ]
            for b in sorted(near, key=lambda b: np.hypot(b.u - u, b.v - v)):
                ratio = b.area / s.area
                if 1 / PLAUSIBLE**2 <= ratio <= PLAUSIBLE**2:
                    continue  # a blob of its size: not a question of size
                seen = math.sqrt(b.area / math.pi)
                mpp = self.cal.metres_per_pixel((u, v))
                raise BodyNotFoundError(
                    f"body {s.body.name!r} is not clear in the first frame: where the scene starts "
                    f"it (u={u:.0f}, v={v:.0f}) a blob of about {seen:.1f} px radius sits "
                    f"{np.hypot(b.u - u, b.v - v):.1f} px away, while the scene's radius makes "
                    f"{s.radius:.1f} px there; the nearest blob of that size is {off:.0f} px "
                    f"away (u={got.uv[0]:.0f}, v={got.uv[1]:.0f}). If the blob at the start is "
                    f"the body, its radius is about {seen * mpp:.3g} m, not "
                    f"{s.radius * mpp:.3g} m: correct the scene's radius (scene new --radius) "
                    "or the calibration's scale"
                )

    def _faint(
        self,
        i: int,
        image: np.ndarray,
        gate: float,
        found: dict[int, _Found],
        rivals: Sequence[tuple[np.ndarray, float]] = (),
    ) -> _Found | None:
        """A disc of a few pixels that no blob showed, found by a matched filter
        (:mod:`~physbench.video.faint`): its disc smeared along its predicted motion over the
        exposure, searched within its gate, away from the bodies found in this frame and
        nearer its own prediction than those of ``rivals`` (the others not found yet). Measured
        by its centroid; its looks are not learnt from it (too few, too faint pixels)."""
        s = self.states[i]
        if not s.disc or s.radius >= SMALL_DISC:
            return None
        pred = self.pred_uv[i]
        ahead = self.pred_xy[i] + s.v * (SHUTTER / self.scene.fps)
        smear = self.cal.to_image(ahead[None])[0] - pred
        taken = [f.uv for f in found.values()]

        def search(within: float, level: float) -> Faint | None:
            first = self.first_frame
            for _ in range(FIXED_TRIES):
                got = find_faint(
                    image, self.bg, self.light, pred, within, s.radius, smear, taken, s.trail,
                    significance=level, rivals=rivals, fixed=self.fixed,
                )  # fmt: skip
                if got is None or first is None:
                    return got
                if not first.holds(got.uv, s.radius, smear, self.bg, got.significance):
                    return got
                self.fixed.append(got.uv)
            return None

        got = None
        near = math.inf if s.error2 is None else NEAR * math.sqrt(s.error2) * (s.missed + 1) + 1.0
        others = [q for q, _ in rivals] + taken
        alone = all(float(np.hypot(*(q - pred))) > gate for q in others)
        if alone and s.missed <= NEAR_MISSED and near <= min(gate, NEAR_RADII * s.radius + 2.0):
            got = search(
                near, max(NEAR_SIGNIFICANCE, SIGNIFICANCE * look_elsewhere(near, s.radius))
            )
        if got is None:
            got = search(gate, SIGNIFICANCE)
        if got is None:
            return None
        xy = self.cal.to_scene(got.uv[None])[0]
        look = Look(math.nan, np.zeros(3), 0.0)
        return _Found(xy, got.uv, PlanePose(xy, 0.0, 1.0, 0.0), look, centroid=True)

    def _not_found(self, i: int, image: np.ndarray) -> str:
        from physbench.video.diagnosis import Missing, not_found

        s = self.states[i]
        shape = s.body.shape
        metres = shape.radius if isinstance(shape, Circle) else None
        missing = Missing(
            s.body.name, self.pred_uv[i], s.radius, s.area, s.body.position, metres=metres
        )
        said = not_found(
            missing,
            image,
            self.bg,
            self.light,
            self.low,
            median=self.median,
            deviations=self.deviations,
        )
        if not self.moved.open:
            return said
        where = "the clip's median" if self.median else "the background you gave"
        return (
            f"the first frame's picture lies {self.largest_shift:.1f} px off {where}: the camera "
            f"moved, or was moved, during the clip, and {MOVING}. What else the first frame "
            f"shows: {said}"
        )

    def _none_in_view(self) -> str:
        where = ", ".join(
            f"{s.body.name!r} at pixel (u={u:.0f}, v={v:.0f})"
            for s, (u, v) in zip(self.states, self.pred_uv, strict=True)
        )
        return (
            f"no body of the scene is in the first frame: the scene's initial positions put "
            f"{where}, all outside the {self.w}x{self.h} image; check the calibration (its origin "
            "and scale), the scene's positions, --seed and --start"
        )

    def _accept(self, s: _State, found: _Found, t: float) -> None:
        xy = found.xy
        dt = t - s.t
        if s.seen and dt > 0:
            kick = self.motion.kick(s.body.name, s.t, dt)
            hit = float(s.v @ s.contact) if s.contact is not None else 0.0
            # A split measurement's position leans towards its neighbour: the velocity goes on
            # as predicted.
            if found.split:
                s.v = s.v + kick.dv
            else:
                (x, y), (sx, sy) = xy.tolist(), s.xy.tolist()
                (vx, vy), (ex, ey) = kick.dv.tolist(), kick.dx.tolist()
                s.v = np.array([(x - sx) / dt + vx - ex / dt, (y - sy) / dt + vy - ey / dt])
            s.bounce = 0.0
            if s.contact is not None:
                s.v, s.bounce = _off_surface(s.v, s.contact, hit)
            assert s.last_uv is not None
            (fu, fv), (lu, lv) = found.uv.tolist(), s.last_uv.tolist()
            s.step = float(np.hypot(fu - lu, fv - lv)) / (s.missed + 1)
        angle = self._angle(s, found.pose, t) if s.k else None
        s.missed = 0
        s.seen += 1
        s.xy, s.t, s.last_uv = xy, t, found.uv
        s.trail = [*s.trail[1 - GHOST_FRAMES :], found.uv]
        s.rows.append((t, float(xy[0]), float(xy[1]), math.nan if angle is None else angle))
        s.uv_rows.append((t, float(found.uv[0]), float(found.uv[1])))
        # A body's looks are learnt only from detections of about the size the scene gives it:
        # part of a body that a median background holds, or a body with a hand, would teach it
        # a wrong colour too.
        if 1 / PLAUSIBLE <= found.look.size <= PLAUSIBLE:
            if s.look is None:
                s.look = Appearance.first(found.look)
            else:
                s.look.update(found.look)
        s.centroids += found.centroid
        if found.radius is not None:
            s.radius_m = (
                found.radius if s.radius_m is None else 0.8 * s.radius_m + 0.2 * found.radius
            )

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

    def _windows(self, ids: list[int], reach: np.ndarray) -> list[tuple[list[int], tuple]]:
        """Bodies ``ids`` grouped by overlapping search windows, with each group's window
        ``(r0, r1, c0, c1)``."""
        groups = []
        for i in ids:
            u, v = self.pred_uv[i]
            r = reach[i]
            box = [
                max(0, math.floor(v - r)),
                min(self.h, math.ceil(v + r) + 1),
                max(0, math.floor(u - r)),
                min(self.w, math.ceil(u + r) + 1),
            ]
            if box[0] < box[1] and box[2] < box[3]:
                groups.append(([i], box))
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
        """Pixel weights for body ``i``'s centroid. A body without an angle keeps its coverage.
        A body that turns is weighed by the share of the exposure each pixel saw it
        (:func:`_alpha`): a turning body's motion blur is lopsided (its far end sweeps more), and
        only that weight keeps its centre at the exposure's middle (a swinging arm: 1 cm off with
        the coverage). The unmixing is in linear light (:attr:`linear`)."""
        if not self.states[i].k:
            return coverage
        behind = behind * self.light.gain + self.light.offset
        return _alpha(self.linear(colour), self.linear(behind), diff)

    def _with_faint_end(
        self, window: tuple[np.ndarray, tuple[int, int]], u: np.ndarray, v: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """A blob's pixels ``(u, v)`` and the fainter ones joined to it, down to
        :data:`FAINT_END` of the frame's threshold (above 3 robust noise deviations), but none of
        another blob; with their differences. The blurred far end of a swinging arm falls under
        the threshold, and a centroid without it is pulled towards the pivot: 3.7-3.9 px on two
        field-camera arms, 1.3-2.0 px with it."""
        diff, (r0, c0) = window
        low = max(FAINT_END * self.low, 3.0 * self.light.sigma)
        rows, cols = v.astype(np.intp) - r0, u.astype(np.intp) - c0
        if low >= self.low:
            return u, v, diff[rows, cols]
        labels, _ = ndimage.label(diff > low, CROSS)
        joined = np.isin(labels, np.unique(labels[rows, cols]))
        faint = joined & (diff <= self.low)  # not another blob's pixels
        faint[rows, cols] = True
        fr, fc = np.nonzero(faint)
        return (fc + c0).astype(np.float64), (fr + r0).astype(np.float64), diff[fr, fc]

    def _between_ends(self, i: int, xy: np.ndarray, pose: PlanePose) -> PlanePose:
        """``pose`` with its centre moved along the long axis to the middle of the blob's two
        ends, for an elongated body symmetric under a half turn whose pixels (``xy``, on the
        plane) span its length (:data:`ENDS_SPAN`). A swinging arm's weighted centroid leans
        towards the pivot, where the blob is sharp, by 3-5 mm on field-camera arms of 0.37-0.46
        m; the middle of its ends (each the :data:`ENDS_QUANTILE` of the pixels along the axis)
        by 0.2-0.4 mm."""
        length = self.states[i].length
        if length is None:
            return pose
        axis = np.array([math.cos(pose.axis), math.sin(pose.axis)])
        along = (xy - pose.xy) @ axis
        lo, hi = np.quantile(along, [ENDS_QUANTILE, 1.0 - ENDS_QUANTILE])
        span = (hi - lo) / (1.0 - 2.0 * ENDS_QUANTILE)
        if span / length > ENDS_SPAN[1]:
            return pose  # joined to something: the centroid it is
        if span / length < ENDS_WHOLE:
            one = self._from_one_end(pose, axis, lo, hi, length)
            if one is not None:
                return one
        if span / length < ENDS_SPAN[0]:
            return pose  # an end hidden or cut off: the centroid it is
        return replace(pose, xy=pose.xy + 0.5 * (lo + hi) * axis)

    def _from_one_end(
        self, pose: PlanePose, axis: np.ndarray, lo: float, hi: float, length: float
    ) -> PlanePose | None:
        """Called by :meth:`_between_ends` when a rod's blob is shorter than
        :data:`ENDS_WHOLE` of its ``length``: ``pose`` with its centre half of it from the end
        of the blob (``lo``, ``hi``: the ends' quantiles along ``axis``) that is seen, where the
        other ends at pixels of the background that are :attr:`unknown` (the part of a
        pendulum's arm near its pivot that the clip's median holds in every kept frame: the blob
        stops short there); ``None`` where neither or both end there, or nothing is unknown.
        Measured: on 20 field-camera pendulum clips tracked against their medians, the centre
        error's 95th percentile fell on 5 (8.96 -> 4.34, 5.66 -> 3.65 px) and rose on none."""
        if self.unknown is None:
            return None
        ends = self.cal.to_image(pose.xy + np.outer([lo, hi], axis))
        hidden = [self._unknown_near(u, v) for u, v in ends]
        if hidden[0] == hidden[1]:
            return None
        if hidden == [True, False]:  # the low end hidden: measured from the high one
            return replace(pose, xy=pose.xy + (hi + ENDS_QUANTILE * length - 0.5 * length) * axis)
        return replace(pose, xy=pose.xy + (lo - ENDS_QUANTILE * length + 0.5 * length) * axis)

    def _unknown_near(self, u: float, v: float) -> bool:
        """Whether a pixel of :attr:`unknown` lies within :data:`UNKNOWN_NEAR` px of ``(u, v)``."""
        assert self.unknown is not None
        r = UNKNOWN_NEAR
        r0, r1 = max(0, math.floor(v - r)), min(self.h, math.ceil(v + r) + 1)
        c0, c1 = max(0, math.floor(u - r)), min(self.w, math.ceil(u + r) + 1)
        return bool(r0 < r1 and c0 < c1 and self.unknown[r0:r1, c0:c1].any())

    def _outline(self, i: int) -> Outline:
        """Body ``i``'s outline in the image at its prediction (px, about the predicted pixel):
        its polygon at the predicted angle through the calibration, or a disc."""
        s = self.states[i]
        if s.angle is None or not hasattr(s.body.shape, "vertices"):
            return Outline(s.radius)
        pts = np.asarray(s.body.shape.vertices(), dtype=float)
        pts = pts - _area_centroid(pts)
        a = s.angle + s.omega * (self.t_next - s.t)
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        xy = self.pred_xy[i]
        return Outline(s.radius, self.cal.to_image(xy + pts @ rot.T) - self.pred_uv[i])

    # ----------------------------------------------------------------- measuring

    def _measure(
        self,
        image: np.ndarray,
        gates: np.ndarray,
        reach: np.ndarray,
        t: float,
        visible: list[bool],
    ) -> dict[int, _Found]:
        """Every visible body's measurement in this frame: blobs found in the windows around
        the predictions, assigned to bodies, discs fitted to their outlines (all of the frame's
        at once), each body measured on its blob."""
        ids = [i for i, v in enumerate(visible) if v]
        windows, plans = [], {}
        for group, (r0, r1, c0, c1) in self._windows(ids, reach):
            crop = (slice(r0, r1), slice(c0, c1))
            window = (
                self.light.difference(image[crop], self.bg[crop]),
                (r0, c0),
            )
            small = min(self.states[i].area for i in group)
            blobs = find_blobs(
                window[0], self.low, self._high(group), offset=(r0, c0), min_area=0.15 * small
            )
            if not blobs:
                continue
            colours = _Lazy(self._own_colours, image, blobs, group)
            own = [_Split(colours, c) for c in range(len(blobs))]
            owner, dist = self._assign(group, blobs, gates, own)
            for c, members in owner.items():
                mixed = len(members) > 1 or (
                    len(group) > 1 and _colours_of(own[c], self.states) > 1
                )
                for i in members:
                    if self.states[i].disc:
                        mask = own[c].get(i) if mixed else None
                        plan = self._plan(i, blobs[c], alone=len(members) == 1, own=mask)
                        plans[i] = (plan, window)
            windows.append((group, window, blobs, owner, dist, own))
        fits = self._fit_discs(image, plans)
        found: dict[int, _Found] = {}
        for group, window, blobs, owner, dist, own in windows:
            mine = {i: p for i, (p, _) in plans.items() if i in group}
            taken = set(owner)
            for c, members in owner.items():
                got = self._members(image, blobs[c], members, window, mine, fits, own[c])
                found.update(got)
                for i in members:
                    if i not in got:
                        tries = self._tries(i, group, blobs, c, own, dist[group.index(i)], gates)
                        tries = [a for a in tries if a == c or a not in taken]
                        again = self._again(i, image, window, blobs, c, own, tries)
                        if again is not None:
                            found[i], alt = again
                            taken.add(alt)
        return found

    def _tries(
        self,
        i: int,
        group: list[int],
        blobs: list,
        c: int,
        own: list[_Split],
        dist: np.ndarray,
        gates: np.ndarray,
    ) -> list[int]:
        """Where to look again for body ``i``, rejected on blob ``c``: among the pixels of its
        colour in that blob where the blob is too big for the body alone (it holds something
        else too: another body, or the body's ghost in a median background), then the other
        blobs within its gate, nearest first (``dist``: its prediction's to each blob)."""
        tries = []
        if i in own[c] and blobs[c][0].area > 1.3 * self.states[i].area:
            tries.append(c)
        return tries + [int(a) for a in np.argsort(dist) if int(a) != c and dist[a] <= gates[i]]

    def _again(
        self,
        i: int,
        image: np.ndarray,
        window: tuple[np.ndarray, tuple[int, int]],
        blobs: list,
        c: int,
        own: list[_Split],
        tries: list[int],
    ) -> tuple[_Found, int] | None:
        """Body ``i`` measured on the first blob of ``tries`` where it looks like itself (on
        blob ``c``, where it was rejected, among its colour's pixels only), and that blob."""
        for alt in tries:
            blob = blobs[alt]
            mask = own[alt].get(i) if alt == c else None
            disc = self.states[i].disc
            plan = {i: self._plan(i, blob, alone=mask is None, own=mask)} if disc else {}
            fit = self._fit_discs(image, {j: (p, window) for j, p in plan.items()})
            again = self._members(image, blob, [i], window, plan, fit, own[alt])
            if i in again:
                return again[i], alt
        return None

    def _assign(
        self, ids: list[int], blobs: list, gates: np.ndarray, own: list[_Split]
    ) -> tuple[dict[int, list[int]], np.ndarray]:
        """Blobs to bodies ``ids``: each blob's owners, and the distance of each body's prediction
        to each blob's centre (px). ``own``: per blob, the pixels of each body's colour."""
        if len(ids) == 1 and len(blobs) == 1:  # most windows: as the general case gives it
            (pu, pv), blob = self.pred_uv[ids[0]].tolist(), blobs[0][0]
            dist = np.array([[np.hypot(pu - blob.u, pv - blob.v)]])
            self._ghosts(ids, np.array([[blob.u, blob.v]]), dist)
            if dist[0, 0] <= gates[ids[0]]:
                return {0: list(ids)}, dist
        from scipy.optimize import linear_sum_assignment

        preds = self.pred_uv[ids]
        centres = np.array([b[0].centre for b in blobs])
        dist = np.hypot(*(preds[:, None, :] - centres[None]).transpose(2, 0, 1))
        self._ghosts(ids, centres, dist)
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
                if dist[j, c] == np.inf:
                    continue  # its ghost
                if np.hypot(u - preds[j, 0], v - preds[j, 1]).min() > gates[i]:
                    continue  # the prediction is not on this blob
                taken = owner.get(int(c), [])
                expected = sum(self.states[k].area for k in taken) + self.states[i].area
                if blobs[c][0].area > 0.6 * expected:
                    owner.setdefault(int(c), []).append(i)
                    break
        self._by_colour(ids, blobs, gates, own, owner, dist)
        return owner, dist

    def _ghosts(self, ids: list[int], centres: np.ndarray, dist: np.ndarray) -> None:
        """Blobs that are a small disc's ghost (:func:`~physbench.video.faint.ghosts_of`: its
        imprint where it was seen in its last frames, kept by a lossy codec's skipped blocks,
        now that its prediction has moved on) are not that disc's: their distance in ``dist``
        (bodies ``ids`` by blobs, centres ``centres``) becomes infinite. A body that did stay
        there is unseen, which the summary says, rather than followed at its imprint."""
        for j, i in enumerate(ids):
            s = self.states[i]
            if not s.disc or s.radius >= SMALL_DISC:
                continue
            for q in ghosts_of(s.trail, self.pred_uv[i], s.radius):
                dist[j, np.hypot(*(centres - q).T) <= ghost_reach(s.radius)] = np.inf

    def _by_colour(
        self,
        ids: list[int],
        blobs: list,
        gates: np.ndarray,
        own: list[_Split],
        owner: dict[int, list[int]],
        dist: np.ndarray,
    ) -> None:
        """The assignment ``owner`` corrected by the bodies' colours: a blob that holds next to
        none of a body's colour and much of another body's is not that body's (a ghost of a
        body in a median background, or its neighbour, where the body itself is not found:
        it is unseen rather than measured there), and a body left out shares the nearest blob
        on its prediction that holds much of its colour (touching bodies whose blob is smaller
        than two bodies, or a blob given to the neighbour alone). A blob of fewer than
        :data:`~physbench.video.appearance.COLOUR_PIXELS` has no colour to judge: its owners
        stay as the distances gave them."""

        def held(c: int, i: int) -> float:
            return own[c].covered(i) / self.states[i].area if i in own[c] else 0.0

        for c, members in list(owner.items()):
            if blobs[c][0].area < COLOUR_PIXELS:
                continue
            others = [k for k in ids if k not in members and held(c, k) >= HIDDEN]
            for i in [i for i in members if i in own[c] and held(c, i) < 0.1] if others else []:
                members.remove(i)
            if not members:
                del owner[c]
        for j, i in enumerate(ids):
            if self.states[i].look is None or any(i in v for v in owner.values()):
                continue
            for c in np.argsort(dist[j]):
                _, u, v, _ = blobs[c]
                if blobs[c][0].area < COLOUR_PIXELS or dist[j, c] == np.inf:
                    continue
                d2 = (u - self.pred_uv[i, 0]) ** 2 + (v - self.pred_uv[i, 1]) ** 2
                if d2.min() <= gates[i] ** 2 and held(int(c), i) >= HIDDEN:
                    owner.setdefault(int(c), []).append(i)
                    break

    def _own_colours(self, image: np.ndarray, blobs: list, ids: list[int]) -> _Colours:
        """Which pixels of each of a window's blobs are of each body's colour, for the bodies of
        ``ids`` whose looks are known (all the window's blobs in one pass), and their coverage
        (:func:`~physbench.video.appearance.matching`)."""
        known = [i for i in ids if self.states[i].look is not None]
        ends = np.cumsum([len(b[1]) for b in blobs])
        if not known:
            return _Colours({}, np.zeros((0, 0), bool), ends, np.zeros((len(blobs), 0)))
        u = np.concatenate([b[1] for b in blobs])
        v = np.concatenate([b[2] for b in blobs])
        w = np.concatenate([b[3] for b in blobs])
        looks = [self.states[i].look for i in known]
        light = self.light
        masks, owned = matching(looks, image, u, v, w, ends, light.offset, light.gain)  # type: ignore[arg-type]
        return _Colours({i: k for k, i in enumerate(known)}, masks, ends, owned)

    def _members(
        self,
        image: np.ndarray,
        found_blob: tuple,
        members: list[int],
        window: tuple[np.ndarray, tuple[int, int]],
        plans: dict[int, _Plan],
        fits: dict[int, DiscFit | None],
        own: _Split,
    ) -> dict[int, _Found]:
        """Measure ``members`` on one blob (pixels ``u``, ``v``, coverage ``w``): a disc by its
        outline (``fits``), a body alone by its centroid, bodies sharing the blob by its pixels
        split along their predicted outlines; each kept only if it looks like its body."""
        blob, u, v, w = found_blob
        out: dict[int, _Found] = {}
        shared = len(members) > 1
        discs = {
            i: self._disc(i, image, found_blob, plans[i], fits.get(i), alone=not shared)
            for i in members
            if i in plans
        }
        for i, got in discs.items():
            look = self.states[i].look
            hidden = plans[i].pixels is not None  # among its colour's pixels: part may be hidden
            if shared and got is not None and look and look.mismatch(got.look, hidden=hidden):
                discs[i] = None  # an outline of another body: try the body's share of the blob
        if any(i not in discs or (discs[i] is None and shared) for i in members):
            diff, (r0, c0) = window
            rows, cols = v.astype(np.intp), u.astype(np.intp)
            d = diff[rows - r0, cols - c0]
            img, bg = image[rows, cols], self.bg[rows, cols]
            if shared:
                outlines = [self._outline(i) for i in members]
                centres, split, inside = split_pixels(u, v, w, self.pred_uv[members], outlines)
        for j, i in enumerate(members):
            s = self.states[i]
            if i in discs and (discs[i] is not None or not shared):
                got = discs[i]
            elif not shared and s.k and not s.disc:
                # A turning body's far end sweeps more of the frame over the exposure, so it
                # is fainter: measured on its fainter pixels too (see _with_faint_end).
                gu, gv, gd = self._with_faint_end(window, u, v)
                rows_g, cols_g = gv.astype(np.intp), gu.astype(np.intp)
                weights = self._weights(i, gd, gd, image[rows_g, cols_g], self.bg[rows_g, cols_g])
                points = plane_points(gu, gv, self.cal)
                pose = plane_pose(gu, gv, weights, self.cal, points)
                pose = self._between_ends(i, points[0], pose)
                got = _Found(pose.xy, blob.centre, pose, self._look(i, blob.area, img, w))
            elif not shared:
                pose = plane_pose(u, v, self._weights(i, w, d, img, bg), self.cal)
                got = _Found(pose.xy, blob.centre, pose, self._look(i, blob.area, img, w))
            else:
                # A disc whose outline is hidden by its neighbours, or another body: its share
                # of the blob's pixels, those of its colour where the blob holds several.
                mine, fit = split == j, (split == j) & inside
                if i in own and len(own) > 1 and own.covered(i) >= 0.2 * s.area:
                    mine = fit = own[i]
                    centres[j] = blob_from_pixels(u[mine], v[mine], w[mine]).centre
                part = blob_from_pixels(u[mine], v[mine], w[mine])
                if part is None or not fit.any():
                    continue
                # Centre from the pixels inside the outline, axes from all the body owns.
                # Weighed over its own pixels only: a shared blob holds other bodies'
                # colours, which would spoil the hue a turning body is unmixed with.
                wi = np.zeros_like(w)
                wi[mine] = self._weights(i, w[mine], d[mine], img[mine], bg[mine])
                centre = plane_pose(u[fit], v[fit], wi[fit], self.cal)
                axes = plane_pose(u[mine], v[mine], wi[mine], self.cal)
                look = self._look(i, part.area, img[mine], w[mine], at=part.centre)
                got = _Found(centre.xy, centres[j], replace(axes, xy=centre.xy), look)
            if got is None:
                continue
            hidden = i in plans and plans[i].pixels is not None
            if s.look and s.look.mismatch(got.look, hidden=hidden) is not None:
                s.rejected += 1
                continue
            if shared and s.disc and s.radius < SMALL_DISC:
                # A blob of a few pixels holds no outline to split along: the split centres
                # lean towards each other (a ball of 1 px came out 2.5 px towards the one it
                # touched, and the velocity from that carried its prediction onto the other).
                got = replace(got, split=True)
            out[i] = got
        return out

    def _plan(
        self,
        i: int,
        found_blob: tuple,
        *,
        alone: bool,
        own: np.ndarray | None = None,
    ) -> _Plan:
        """Where to look for disc ``i``'s outline on a blob: from the blob's centroid where the
        blob is its alone and of its size, else from a mean shift over the blob's pixels within
        its radius, from the pixel nearest its prediction (its own part of a blob shared with a
        rod, a hand or another ball), over the pixels of its colour (``own``, given for a blob
        that holds other bodies' colours too) where it has one (a ball struck into a rack of
        others, two balls of different colours touching)."""
        blob, u, v, w = found_blob
        s = self.states[i]
        pred = self.pred_uv[i]
        mpp = self._mpp(pred)
        r = s.body.shape.extent() / mpp
        expected = s.body.shape.area() / mpp**2
        if alone and own is None and 0.6 * expected <= blob.area <= 1.6 * expected:
            c = blob.centre
        else:
            pixels = None
            if own is not None and w[own].sum() >= 0.2 * expected:
                u, v, w = pixels = u[own], v[own], w[own]
            c = _mean_shift(u, v, w, pred, r)
            rays = Rays(c, r, 1.25 * r + 0.5 * s.step + 3.0)
            return _Plan(rays, mpp, expected, s.radius_m, pixels)
        return _Plan(Rays(c, r, 1.25 * r + 0.5 * s.step + 3.0), mpp, expected, s.radius_m)

    def _fit_discs(
        self,
        image: np.ndarray,
        plans: dict[int, tuple[_Plan, tuple[np.ndarray, tuple[int, int]]]],
    ) -> dict[int, DiscFit | None]:
        """Each planned disc fitted to its outline (:func:`~physbench.video.silhouette.fit_discs`,
        all at once): the rays of those inside their search window on its difference, the
        others on crops of their own; a fit far from where its rays started is fitted again
        from its centre."""
        inside, outside, found = [], [], []
        for i, (plan, (diff, (r0, c0))) in plans.items():
            c, m = plan.rays.centre, plan.rays.reach + 2.0
            h, w = diff.shape
            ok = c[1] - m >= r0 and c[0] - m >= c0 and c[1] + m <= r0 + h - 1
            (inside if ok and c[0] + m <= c0 + w - 1 else outside).append(i)
        by_window: dict[int, list[int]] = {}
        for i in inside:
            by_window.setdefault(id(plans[i][1][0]), []).append(i)
        for members in by_window.values():
            diff, origin = plans[members[0]][1]
            found.append((diff, origin, [plans[i][0].rays for i in members]))
        order = [i for members in by_window.values() for i in members]
        fits: dict[int, DiscFit | None] = {}
        if order:
            mine = [plans[i][0] for i in order]
            along, halos = [self._smeared(i) for i in order], [self._halos(i) for i in order]
            got = self._fit_on(found, mine, along, halos)
            fits.update(zip(order, got, strict=True))
        own = self._fit_own(
            image, [plans[i][0] for i in outside], [self._halos(i) for i in outside]
        )
        fits.update(zip(outside, own, strict=True))
        again = {}
        for i, fit in fits.items():
            rays = plans[i][0].rays
            if fit is not None and float(np.hypot(*(fit.uv - rays.centre))) > 0.25 * rays.radius:
                again[i] = replace(plans[i][0], rays=replace(rays, centre=fit.uv))
        own = self._fit_own(image, list(again.values()), [self._halos(i) for i in again])
        fits.update(zip(again, own, strict=True))
        return fits

    def _smeared(self, i: int) -> np.ndarray | None:
        """The unit direction of body ``i``'s motion on the plane where one frame interval of it
        is more than :data:`SMEAR` of its radius (an exposure of half the interval smears it into
        a stadium), else ``None``."""
        s = self.states[i]
        speed = float(np.hypot(*s.v))
        if s.seen < 2 or speed / self.scene.fps < SMEAR * s.body.shape.extent():
            return None
        if self.t_next - self.t_last > SPARSE / self.scene.fps:
            return None
        return s.v / speed

    def _halos(self, i: int) -> bool:
        """Whether body ``i``'s outline is fitted without its halos of bled colour
        (:func:`~physbench.video.silhouette.fit_discs`): in video whose colour is subsampled,
        unless it moves more than :data:`HALO_MOTION` of its radius in a frame interval."""
        s = self.states[i]
        if not self.subsampled:
            return False
        speed = float(np.hypot(*s.v)) if s.seen >= 2 else 0.0
        return speed / self.scene.fps <= HALO_MOTION * s.body.shape.extent()

    def _fit_own(
        self, image: np.ndarray, plans: list[_Plan], halos: list[bool]
    ) -> list[DiscFit | None]:
        """Each disc's outline fit on a crop of its own (all in one pass)."""
        crops, fitted = [], []
        for k, plan in enumerate(plans):
            rays = plan.rays
            c, m = rays.centre, rays.reach + 2.0
            r0, r1 = max(0, math.floor(c[1] - m)), min(self.h, math.ceil(c[1] + m) + 1)
            c0, c1 = max(0, math.floor(c[0] - m)), min(self.w, math.ceil(c[0] + m) + 1)
            if r1 - r0 < 3 or c1 - c0 < 3:
                continue
            box = (slice(r0, r1), slice(c0, c1))
            diff = self.light.difference(image[box], self.bg[box])
            crops.append((diff, (r0, c0), [rays]))
            fitted.append(k)
        fits: list[DiscFit | None] = [None] * len(plans)
        if fitted:
            got = self._fit_on(crops, [plans[k] for k in fitted], None, [halos[k] for k in fitted])
            for k, fit in zip(fitted, got, strict=True):
                fits[k] = fit
        return fits

    def _fit_on(
        self,
        windows: list[tuple[np.ndarray, tuple[int, int], list[Rays]]],
        plans: list[_Plan],
        along: list[np.ndarray | None] | None = None,
        halos: list[bool] | None = None,
    ) -> list[DiscFit | None]:
        """The discs of ``plans`` fitted to the edges their rays find on ``windows`` (each a
        difference, its origin and its rays, in the plans' order), in one call."""
        return fit_discs(
            window_edges(windows, self.edge_low),
            [p.rays.radius for p in plans],
            self.cal,
            [p.mpp for p in plans],
            [p.known for p in plans],
            along,
            halos=halos or False,
        )

    def _disc(
        self,
        i: int,
        image: np.ndarray,
        found_blob: tuple,
        plan: _Plan,
        fit: DiscFit | None,
        *,
        alone: bool,
    ) -> _Found | None:
        """Disc ``i``'s measurement on a blob from its outline ``fit``. Without one, a blob that
        is the body's alone and of its size gives its centroid; otherwise the disc is unseen."""
        blob, u, v, w = found_blob
        if fit is None:
            # Without an outline, the centroid of a blob that is the body's alone and of a
            # disc's area (counted: shading can move it): a disc of a few pixels, one smeared
            # into a streak (whose faint parts fall under the threshold), one whose outline is
            # too faint. Neither a disc's outline nor its area: something else.
            small = plan.rays.radius < SMALL_DISC or blob.elongation > 4.0
            if not alone or not (0.3 if small else 0.5) <= blob.area / plan.expected <= 1.6:
                return None
            colours = image[v.astype(np.intp), u.astype(np.intp)]
            look = self._look(i, blob.area, colours, w, mpp=plan.mpp)
            pose = plane_pose(u, v, w, self.cal)
            return _Found(pose.xy, blob.centre, pose, look, centroid=True)
        if plan.pixels is not None:  # its own colour's pixels of a shared blob
            u, v, w = plan.pixels
        area, raw = _disc_pixels(image, u, v, w, fit.uv[0], fit.uv[1], fit.radius / plan.mpp)
        look = self._look(i, area, raw, None, mpp=plan.mpp, median=True)
        radius = None if fit.fixed else fit.radius
        return _Found(fit.xy, fit.uv, PlanePose(fit.xy, 0.0, 1.0, 0.0), look, radius)

    def _mpp(self, uv: np.ndarray) -> float:
        """Metres per pixel near ``uv``, from a cache of 16 px cells."""
        u, v = uv.tolist()
        key = (int(u) >> 4, int(v) >> 4)
        mpp = self._mpp_cells.get(key)
        if mpp is None:
            cell = (np.array(key, dtype=float) + 0.5) * 16
            mpp = self._mpp_cells[key] = self.cal.metres_per_pixel(cell)
        return mpp

    def _look(
        self,
        i: int,
        area: float,
        colours: np.ndarray,
        weights: np.ndarray | None,
        *,
        mpp: float | None = None,
        at: np.ndarray | None = None,
        median: bool = False,
    ) -> Look:
        """What body ``i``'s detection looks like: its covered ``area`` (px) over the scene's
        area for the body (``mpp`` metres per pixel, or at pixel ``at``, or at its prediction),
        and the median colour of ``colours`` (``(n, 3)``; with ``weights``, of the best covered
        quarter, which motion blur mixes least with the wall; every 4th of many; ``median``:
        ``colours`` is that median already) in the background's light."""
        if mpp is None:
            mpp = self._mpp(self.pred_uv[i] if at is None else at)
        expected = self.states[i].body.shape.area() / mpp**2
        if median:
            raw = colours
        else:
            if weights is not None and len(colours) > 3:
                colours = colours[weights >= np.percentile(weights, 75)]
            if len(colours) > 64:
                colours = colours[::4]
            raw = medians.median(colours, axis=0) if len(colours) else np.zeros(3)
        colour = (raw - self.light.offset) / np.maximum(self.light.gain, 1e-3)
        return Look(area / max(expected, 1e-9), colour, expected)

    # ----------------------------------------------------------------- result

    def result(self, calibration_error: float | None = None, fps: float = 0.0) -> TrackResult:
        """The recording, summary and image tracks of the frames seen so far. A body never found
        is a :class:`TrackError` that says where the scene put it."""
        from physbench.recording import Recording

        if self.frames == 0:
            raise TrackError("no frames were tracked: the video (or its --start/--end) is empty")
        for s in self.states:
            if not s.rows:
                raise BodyNotFoundError(self._never_seen(s))
        pixels = {s.body.name: np.array(s.uv_rows, dtype=float) for s in self.states}
        accuracy_px = {
            s.body.name: stated_accuracy(pixels[s.body.name], disc=s.disc) for s in self.states
        }
        mpp = {name: self._coarsest(tuv) for name, tuv in pixels.items()}
        accuracy_m = {name: accuracy_px[name] * mpp[name] for name in accuracy_px}
        tracks, measured = {}, {}
        contacts: dict[str, int] = {}
        for s in self.states:
            rows = np.array(s.rows, dtype=float)
            measured[s.body.name] = _track(rows, turning=bool(s.k))
            if s.free:
                hit = contact_samples(
                    rows[:, 0],
                    rows[:, 1:3],
                    self.g,
                    accuracy_m[s.body.name],
                    self._explained(s.body.name, rows[:, 0]),
                )
                if hit.any():
                    contacts[s.body.name] = int(hit.sum())
                    rows = rows[~hit]
            tracks[s.body.name] = _track(rows, turning=bool(s.k))
        fields = ("x", "y", "angle") if any(t.angle is not None for t in tracks.values()) else None
        angle_accuracy = {
            name: stated_angle_accuracy(
                tr.t, tr.angle, s.body.shape.extent() / max(mpp[name], 1e-12)
            )
            for s in self.states
            if (tr := tracks[name := s.body.name]).angle is not None
        }
        recording = Recording(
            tracks,
            fields=fields,
            source="video",
            meta={},
            accuracy=max(accuracy_m.values()),
            angle_accuracy=max(angle_accuracy.values(), default=0.0),
        )
        names = [s.body.name for s in self.states]
        summary = TrackSummary(
            self.frames,
            self.t_last,
            {s.body.name: s.seen for s in self.states},
            {s.body.name: s.in_view for s in self.states},
            {s.body.name: list(s.unseen.spans) for s in self.states if s.unseen.spans},
            self.cal.reprojection_error if calibration_error is None else calibration_error,
            fps,
            contacts,
            {s.body.name: list(s.out.spans) for s in self.states if s.out.spans},
            {s.body.name: s.rejected for s in self.states if s.rejected},
            {n: round(accuracy_px[n], 3) for n in names},
            {s.body.name: s.centroids for s in self.states if s.centroids},
            {n: round(a, 5) for n, a in angle_accuracy.items()},
            list(self.moved.spans),
            round(self.largest_shift, 2),
        )
        return TrackResult(recording, summary, pixels, replace(recording, tracks=measured))

    def _explained(self, body: str, t: np.ndarray) -> np.ndarray | None:
        """The second differences' accelerations (m/s², ``(n - 2, 2)``) that the scene's
        gravity and forces explain at samples ``t`` of ``body``: None without forces on it."""
        if body not in self.motion.forces or len(t) < 3:
            return None
        out = np.empty((len(t) - 2, 2))
        for k in range(1, len(t) - 1):
            d1, d2 = t[k] - t[k - 1], t[k + 1] - t[k]
            x1 = self.motion.kick(body, t[k - 1], d1).dx
            x2 = self.motion.kick(body, t[k - 1], d1 + d2).dx
            out[k - 1] = 2 * ((x2 - x1) / d2 - x1 / d1) / (d1 + d2)
        return out

    def _never_seen(self, s: _State) -> str:
        u, v = self.cal.to_image(np.asarray(s.body.position, dtype=float))
        if not s.in_view:
            return (
                f"body {s.body.name!r} was never in view: the scene puts it at pixel (u={u:.0f}, "
                f"v={v:.0f}) at t = 0, outside the {self.w}x{self.h} image, and its predicted "
                "path never came into it; check the scene's initial position and velocity, "
                "--seed, --start and the calibration"
            )
        first = s.unseen.spans[0][0] if s.unseen.spans else 0.0
        return (
            f"body {s.body.name!r} was not found in any of the {s.in_view} frames where the "
            f"scene puts it in view (from t = {first:.2f} s); its predicted path enters the image "
            "but nothing of its size and colour was there: check the scene's initial position "
            "and velocity, --seed, --start and the calibration"
        )

    def _coarsest(self, tuv: np.ndarray) -> float:
        """The largest metres per pixel along an image track ``(t, u, v)``."""
        uv = tuv[:, 1:][np.isfinite(tuv[:, 1:]).all(axis=1)]
        points = uv[:: max(1, len(uv) // 16)]
        if not len(points):
            return 0.0
        return max(self.cal.metres_per_pixel(p) for p in points)


def track_frames(
    frames: Iterable[Frame],
    scene: Scene,
    calibration: Calibration,
    background: np.ndarray,
    *,
    median: bool = False,
    allow_gaps: bool = False,
    progress: bool = False,
    transfer: str = "linear",
    subsampled: bool = False,
    held: Sequence[str] = (),
    unknown: np.ndarray | None = None,
    steady: ShiftMeter | None = None,
) -> TrackResult:
    """Track ``scene``'s bodies through decoded ``frames`` against ``background`` (``median``:
    the clip's median; ``held``: the bodies it held, mended, :mod:`~physbench.video.held`;
    ``unknown``: where it holds one in every kept frame, :attr:`~physbench.video.held.Held.unknown`,
    so that a rod's blob ending there is measured from its other end; ``steady``: the camera
    meter of the median before it was mended, :meth:`~physbench.video.steadiness.ShiftMeter.anew`),
    whose pixel values encode light by ``transfer`` (:mod:`~physbench.video.transfer`);
    ``subsampled``: the frames were stored with colour at a lower resolution than brightness
    (4:2:0 or 4:2:2 video, as nearly every camera's), whose coloured rims bleed outwards
    (:data:`~physbench.video.silhouette.HALO`). A body lost in more than
    :data:`~physbench.video.outcome.LOST_SHARE` of the frames where it was in view raises
    :class:`TrackLostError` unless ``allow_gaps``."""
    import sys

    tracker = Tracker(
        scene, calibration, background, median=median, transfer=transfer, subsampled=subsampled,
        unknown=unknown, steady=steady,
    )  # fmt: skip
    if progress:
        _say_compiling()
    tic = _time.perf_counter()
    for fr in frames:
        tracker.update(fr.image, fr.time)
        if progress and tracker.frames % 100 == 0:
            print(f"\r  {tracker.frames} frames", end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    fps = tracker.frames / max(_time.perf_counter() - tic, 1e-9)
    result = tracker.result(fps=fps)
    if median:
        result = replace(result, background=background)
    if held:
        result = replace(result, summary=replace(result.summary, held=list(held)))
    failures = result.summary.failures()
    if failures and not allow_gaps:
        advice = (
            "; the background is the clip's median, which holds a body that stays put for over "
            "half of the clip: film the empty scene and give it as --background"
            if median
            else ""
        )
        camera = result.summary.camera_words()
        raise TrackLostError(
            "; ".join(failures)
            + (f". {camera[0].upper()}{camera[1:]}: {MOVING}" if camera else "")
            + ". A track with such gaps is not the motion; find why in a "
            "--preview (an occluder, too little contrast, a body leaving the view), or pass "
            f"--allow-gaps (allow_gaps=True) to keep the recording with its gaps{advice}"
            f"{_tiny(tracker, result.summary.lost_bodies())}",
            result,
        )
    if result.summary.camera_moved:
        import warnings

        warnings.warn(
            f"{result.summary.camera_words()}: the positions carry its motion; {MOVING}",
            PhysbenchWarning,
            stacklevel=2,
        )
    return result


def _say_compiling() -> None:
    """Say on stderr, before a tracker's first frame, that its loops are about to be compiled,
    where they are not in numba's disk cache yet."""
    import sys

    if not compiled.cached():
        print(
            "  compiling the tracker's loops (once after installing, up to a minute; kept for "
            "the next runs)",
            file=sys.stderr,
            flush=True,
        )


#: What a moving camera means, and the fix.
MOVING = (
    "the tracker finds bodies against a fixed background, and every textured edge of the "
    "background differs from it when the picture moves; film from a tripod, with the phone's "
    "image stabilisation off"
)


def track_video(
    path: str | Path,
    scene: Scene,
    calibration: Calibration | None = None,
    *,
    start: float | None = None,
    end: float | None = None,
    background: np.ndarray | str | Path | None = None,
    allow_gaps: bool = False,
    progress: bool = False,
    transfer: str | None = None,
    capture_fps: float | None = None,
) -> TrackResult:
    """Track ``scene``'s bodies through the video at ``path`` (see the module docstring).

    ``path``: a video file, or a folder of images taken at the scene's frame rate.
    ``calibration``: pixels to metres (default :func:`bounds_calibration`); ``start``/``end``: the
    part of the video to track (s; recording time 0 is the first frame at or after ``start``);
    ``background``: an image of the empty scene (array or file; default: the median of the
    clip, from 15 frames spread over it, mended where it holds a body that stayed put,
    :mod:`~physbench.video.held`); ``allow_gaps``: keep a body lost for more
    than :data:`~physbench.video.outcome.LOST_SHARE` of the frames where it was in view (else
    :class:`TrackLostError`); ``transfer``: the video's transfer function, a name or ``"auto"``
    (default: the video's tag, else :data:`~physbench.video.transfer.DEFAULT`; see
    :func:`~physbench.video.transfer.resolve`); ``capture_fps``: the rate a slow-motion file was
    filmed at (:class:`~physbench.video.reader.VideoReader`; a file playing at under half the
    scene's rate without it is warned of)."""
    from physbench.video.background import load_plate, median_frames
    from physbench.video.reader import VideoError, VideoReader
    from physbench.video.transfer import resolve

    try:
        # A folder of images has no timestamps: its frames come at the scene's rate.
        reader = VideoReader(path, start=start, end=end, fps=scene.fps, capture_fps=capture_fps)
        info = reader.info()
        _check_rate(path, scene, info.rate, reader.images, capture_fps)
        curve, source = resolve(transfer, info.transfer)
        if info.hdr and source == "default":
            _warn_hdr(path, info.hdr)
        if info.interlaced:
            _warn_interlaced(path, info.rate)
        if calibration is None:
            calibration = bounds_calibration(scene, (info.height, info.width))
        if isinstance(background, str | Path):
            background = load_plate(background)
        kept = None
        if background is None:
            kept = median_frames(
                VideoReader(path, start=start, end=end, fps=scene.fps, capture_fps=capture_fps)
            )
            background = kept.image
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
        options = dict(progress=progress, transfer=curve, subsampled=info.subsampled)
        if kept is None:
            return track_frames(
                reader.frames(), scene, calibration, background, allow_gaps=allow_gaps, **options
            )
        return _unheld(
            lambda: VideoReader(
                path, start=start, end=end, fps=scene.fps, capture_fps=capture_fps
            ).frames(),
            kept,
            scene,
            calibration,
            allow_gaps=allow_gaps,
            **options,
        )
    except VideoError as exc:
        raise TrackError(str(exc)) from None


def _unheld(
    frames: Callable[[], Iterable[Frame]],
    kept: MedianFrames,
    scene: Scene,
    calibration: Calibration,
    *,
    allow_gaps: bool,
    progress: bool,
    **options: object,
) -> TrackResult:
    """Track ``frames()`` against the median ``kept``, mended first where it held a body
    (:mod:`~physbench.video.held`). Where the bodies were is found by a scout: the bodies
    tracked through the median's own frames, which are in memory already (15 of the clip's
    frames), so the clip is decoded and tracked once, whatever the median held."""
    import sys
    import warnings

    from physbench.video.held import at_start, still_at_start, unheld
    from physbench.video.reader import Frame

    def scout(background: np.ndarray) -> TrackResult:
        pairs = enumerate(zip(kept.times, kept.frames, strict=True))
        sparse = (Frame(k, float(t), image) for k, (t, image) in pairs)
        if progress:
            _say_compiling()  # the scout's first frame compiles them, before the clip's
        with warnings.catch_warnings():
            # Its frames are far apart: what it says of them (gaps, a fast body lost) is no
            # verdict on the clip, which the full tracking gives.
            warnings.simplefilter("ignore")
            return track_frames(
                sparse, scene, calibration, background, median=True, allow_gaps=True,
                steady=steady, **options,  # type: ignore[arg-type]
            )  # fmt: skip

    # One camera meter for the clip's trackings: the mends differ from the median only on
    # the ghosts of held bodies (ShiftMeter.anew).
    steady = ShiftMeter(kept.image)
    start = None
    try:
        first = scout(kept.image)
    except BodyNotFoundError as exc:
        # A body the median holds where it starts (it stays put from the start over more than
        # half of the clip) is not in the first frame's difference to it; the median's first
        # frame is the clip's.
        start = at_start(kept, scene, calibration)
        if start is None:
            raise _median_holds(exc, still_at_start(kept, scene, calibration)) from None
        if progress:
            print(
                f"  the clip's median holds {', '.join(start.bodies)} where they start: "
                "looking for them against it mended there",
                file=sys.stderr,
                flush=True,
            )
        first = scout(start.background)
    # Mended where a body starts, the median is taken again on top of that mend.
    base = kept if start is None else replace(kept, image=start.background)
    held = unheld(base, first.pixels, scene, calibration, first.measured.tracks)
    if held is not None and any(len(first.pixels[b]) < len(kept.times) for b in held.bodies):
        # Against the median that held them, the scout may have lost the bodies it held (a ball
        # creeping within its own ghost): where they were is found again against the mend.
        second = scout(held.background)
        again = unheld(base, second.pixels, scene, calibration, second.measured.tracks)
        held = again if again is not None else held
    if held is not None and progress:
        print(
            f"  the clip's median holds {', '.join(held.bodies)} where they stayed put: tracking "
            "against it mended there",
            file=sys.stderr,
            flush=True,
        )
    if held is not None:
        _warn_held_turning(scene, held.bodies)
    background = base.image if held is None else held.background
    bodies = list(dict.fromkeys((*(start.bodies if start else ()), *(held.bodies if held else ()))))
    return track_frames(
        frames(), scene, calibration, background, median=True, allow_gaps=allow_gaps,
        progress=progress, held=bodies, unknown=None if held is None else held.unknown,
        steady=steady, **options,  # type: ignore[arg-type]
    )  # fmt: skip


def _median_holds(exc: BodyNotFoundError, still: dict[str, tuple[int, int]]) -> BodyNotFoundError:
    """``exc``, a first frame refused against the clip's median, with what was measured where
    :func:`~physbench.video.held.at_start` mended nothing: in how many of the median's frames
    each body's place looks as in the first frame (``still``)."""
    if not still:
        return exc
    places = "; ".join(
        f"the place of body {name!r} looks as in the first frame in {k} of them"
        for name, (k, _) in still.items()
    )
    n = next(iter(still.values()))[1]
    return BodyNotFoundError(
        f"{exc}. The background is the clip's median, of {n} frames spread over it: {places}, "
        "so what is there in the first frame stays there over most of the clip and is part of "
        "the median. If that is the body, film the empty scene and give it as --background"
    )


def _check_rate(
    path: str | Path, scene: Scene, rate: float, images: list, capture_fps: float | None
) -> None:
    """Warn of a video file that plays at under half the scene's frame rate, with no capture
    rate given: likely slow motion, whose file times are not the real ones."""
    if images or capture_fps is not None or not rate > 0 or scene.fps < 2 * rate:
        return
    import warnings

    from physbench.errors import PhysbenchWarning

    warnings.warn(
        PhysbenchWarning(
            f"{str(path)!r} plays at {rate:g} frames/s and scene {scene.name!r} is at "
            f"{scene.fps:g}: physbench takes the frames' times from the file; if it is slow "
            f"motion filmed at {scene.fps:g} frames/s, give that rate (--capture-fps "
            f"{scene.fps:g}, capture_fps=...)"
        ),
        stacklevel=3,
    )


def _warn_held_turning(scene: Scene, held: Sequence[str]) -> None:
    """Warn where the clip's median held a polygon on a pivot (a pendulum's arm): mended or not, it
    is measured worse than against a plate, and its stated accuracy, from the scatter about a
    smooth fit, does not see that (``results/track/pendulum_median.json``: 48 field-camera arms,
    95th percentiles a median of 3.4 px against the median, 0.6 px against the plate; a double
    pendulum's upper arm 10-21 px off with an accuracy of 0.5-0.57 px stated)."""
    jointed = {name for j in scene.joints for name in (j.a, j.b) if name is not None}
    turning = [
        b.name
        for b in scene.bodies
        if b.name in held and b.name in jointed and hasattr(b.shape, "vertices")
    ]
    if not turning:
        return
    import warnings

    from physbench.errors import PhysbenchWarning

    warnings.warn(
        PhysbenchWarning(
            f"the clip's median holds {', '.join(map(repr, turning))} (an arm on a pivot, which "
            "stays over part of the image through most of the clip near the pivot): tracked "
            "against the median mended there, pendulum arms on physbench's second camera were "
            "3.4 px off at the 95th percentile (the median of 48; a double "
            "pendulum's upper arm 10-21 px), against 0.6 px with a plate, and the accuracy "
            "stated does not show it; film the empty scene and give it (--background)"
        ),
        stacklevel=3,
    )


def _warn_hdr(path: str | Path, curve: str) -> None:
    """Warn that an HDR video (tagged with the ``curve`` PQ or HLG) is read with no HDR curve."""
    import warnings

    from physbench.errors import PhysbenchWarning

    nearest = " (--transfer gamma2.2 is nearest HLG's lower half, a square root)"
    warnings.warn(
        PhysbenchWarning(
            f"{str(path)!r} is HDR video ({curve}): physbench has no {curve} curve and reads its "
            "pixel values as linear light where it unmixes a turning body's blurred pixels"
            f"{nearest if curve == 'HLG' else ''}; discs are tracked on their outlines, which "
            "do not need the curve. For measurements, film with HDR video off (many phones "
            "record HDR by default) or give --transfer"
        ),
        stacklevel=3,
    )


def _warn_interlaced(path: str | Path, rate: float) -> None:
    """Warn that ``path`` is interlaced video, which the tracker reads a frame at a time."""
    import warnings

    twice = f" ({2 * rate:g} frames/s)" if rate > 0 else ""
    warnings.warn(
        PhysbenchWarning(
            f"{str(path)!r} is interlaced video: each frame holds two fields filmed half a frame "
            "apart, so a moving body shows as a comb of both and is measured at their mean, and "
            "a disc's outline does not fit it. Deinterlace it into a frame per field"
            f"{twice}: ffmpeg -i IN -vf yadif=1 OUT.mp4 (or film progressive video, as phones do)"
        ),
        stacklevel=3,
    )


def _tiny(tracker: Tracker, lost: list[str]) -> str:
    """What the size of each ``lost`` body says, where it is under :data:`TINY` px in radius."""
    small = [
        f"{s.body.name!r} is {s.radius:.1f} px in radius"
        for s in tracker.states
        if s.radius < TINY and s.body.name in lost
    ]
    if not small:
        return ""
    return (
        f"; {', '.join(small)}: a lossy video coder leaves a body that small out of many frames "
        "altogether, so film it closer, at a higher resolution or at a higher bitrate"
    )


def _track(rows: np.ndarray, *, turning: bool) -> Track:
    """A body's track from its rows ``(t, x, y, angle)``: with angles where it turns and every
    row has one."""
    from physbench.recording import Track

    angle = rows[:, 3] if turning and not np.isnan(rows[:, 3]).any() else None
    return Track(rows[:, 0], rows[:, 1], rows[:, 2], angle)


def _off_surface(v: np.ndarray, normal: np.ndarray, hit: float) -> tuple[np.ndarray, float]:
    """The velocity ``v`` (m/s, measured over the last frame interval) of a body whose prediction
    touched a surface of ``normal``, and the speed off it that is unknown (m/s). ``hit``: its
    velocity along ``normal`` before, negative where it was moving into the surface. A body
    resting or rolling on it stays on it; one that hit it may have bounced off with any
    restitution, which is predicted as :data:`RESTITUTION` of the speed it came in with: a ball
    that bounced between two frames moved little between them, and predicted to stay on the floor
    it was lost for 6 frames of its rise."""
    into = float(v @ normal)
    if hit >= 0:
        return (v - into * normal if into < 0 else v), 0.0
    out = max(into, -RESTITUTION * hit)
    return v + (out - into) * normal, -max(RESTITUTION, 1 - RESTITUTION) * hit


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
    return np.maximum(alpha, 0.0)


def _project(colour: np.ndarray, behind: np.ndarray, body: np.ndarray) -> np.ndarray:
    """Alpha of each pixel: ``colour - behind`` projected onto ``body - behind``."""
    span = body - behind
    norm = np.einsum("ij,ij->i", span, span)
    return np.einsum("ij,ij->i", colour - behind, span) / np.maximum(norm, 1.0)


@jit
def _mean_shift(u, v, w, pred, r):  # type: ignore[no-untyped-def]
    """The middle of the disc of radius ``r`` (px) nearest ``pred`` among pixels ``(u, v)`` of
    coverage ``w``: a mean shift from the pixel nearest ``pred`` (at most 6 steps, until one
    moves under 0.1 px)."""
    n = len(u)
    if n == 0:
        return pred.copy()
    k, least = 0, np.inf
    for p in range(n):
        d2 = (u[p] - pred[0]) ** 2 + (v[p] - pred[1]) ** 2
        if d2 < least:
            k, least = p, d2
    c = pred.copy() if least <= r * r else np.array([u[k], v[k]])
    ws, us, vs = np.empty(n), np.empty(n), np.empty(n)
    for _ in range(6):
        m = 0
        for p in range(n):
            if (u[p] - c[0]) ** 2 + (v[p] - c[1]) ** 2 <= r * r:
                ws[m], us[m], vs[m] = w[p], u[p], v[p]
                m += 1
        total = pairwise_sum(ws, 0, m)
        if total <= 0:
            break
        new = np.array([np.dot(ws[:m], us[:m]), np.dot(ws[:m], vs[:m])]) / total
        moved = np.hypot(new[0] - c[0], new[1] - c[1])
        c = new
        if moved < 0.1:
            break
    return c


@jit
def _disc_pixels(image, u, v, w, cu, cv, rf):  # type: ignore[no-untyped-def]
    """A disc fitted at ``(cu, cv)`` with radius ``rf`` (px) on pixels ``(u, v)`` of coverage
    ``w``: their coverage within a pixel of its outline, and the median colour (``(3,)``) of
    those within 60 % of its radius (every 4th of over 64), which shading and the rim mix least
    with the wall. (The median by selection, not a sort: 0.08 s over the 4,200 discs of the 20 s
    speed clip's tracking against 0.12 s, the same values.)"""
    n = len(u)
    covered = np.empty(n)
    inner = np.empty(n, np.intp)
    count = kept = 0
    outer2, inner2 = (rf + 1.0) ** 2, (0.6 * rf) ** 2
    for p in range(n):
        near = (u[p] - cu) ** 2 + (v[p] - cv) ** 2
        if near <= outer2:
            covered[count] = w[p]
            count += 1
        if near <= inner2:
            inner[kept] = p
            kept += 1
    step = 4 if kept > 64 else 1
    chosen = (kept + step - 1) // step
    raw = np.zeros(3)
    if chosen:
        values = np.empty(chosen)
        for c in range(3):
            for k in range(chosen):
                p = inner[k * step]
                values[k] = image[int(v[p]), int(u[p]), c]
            raw[c] = np.median(values)
    return pairwise_sum(covered, 0, count), raw


def _colours_of(own: _Split, states: list[_State]) -> int:
    """How many bodies' colours a blob holds much of (a fifth of a body's area or more)."""
    return sum(own.covered(i) >= 0.2 * states[i].area for i in own)


@dataclass(frozen=True)
class _Colours:
    """A window's blobs' pixels of each body's colour (:meth:`Tracker._own_colours`): the
    column of ``masks`` (the blobs' pixels laid end to end, each blob's ending at ``ends``) and
    of ``owned`` (each blob's coverage of those pixels) of each body whose looks are known."""

    column: dict[int, int]
    masks: np.ndarray
    ends: np.ndarray
    owned: np.ndarray


class _Lazy:
    """``split(*args)`` (:meth:`Tracker._own_colours`), computed when first asked for: most
    windows' blobs are one body's alone, which never asks."""

    def __init__(self, split: Callable[..., _Colours], *args: object) -> None:
        self._split, self._args = split, args
        self._colours: _Colours | None = None

    def get(self) -> _Colours:
        if self._colours is None:
            self._colours = self._split(*self._args)
        return self._colours


class _Split(Mapping[int, np.ndarray]):
    """Blob ``c``'s pixels of each body's colour, from its window's :class:`_Lazy` masks."""

    def __init__(self, window: _Lazy, c: int) -> None:
        self._window, self._c = window, c

    def covered(self, i: int) -> float:
        """The blob's coverage (px) of body ``i``'s pixels: ``w[self[i]].sum()``."""
        colours = self._window.get()
        return float(colours.owned[self._c, colours.column[i]])

    def __getitem__(self, i: int) -> np.ndarray:
        colours = self._window.get()
        start = int(colours.ends[self._c - 1]) if self._c else 0
        return colours.masks[start : colours.ends[self._c], colours.column[i]]

    def __contains__(self, i: object) -> bool:
        return i in self._window.get().column

    def __iter__(self) -> Iterator[int]:
        return iter(self._window.get().column)

    def __len__(self) -> int:
        return len(self._window.get().column)
