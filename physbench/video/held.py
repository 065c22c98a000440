"""Bodies a median background holds, and the median taken again without them.

The median of a clip is its background only where no body stayed put over half of the frames it
is taken over: a ball that comes to rest, or creeps along a floor, is part of the median there,
and a tracker that finds bodies by their difference to the background loses it (measured: the
6-ball rack of ``benchmarks/track_speed.py``, 5 s, lost a ball creeping along the floor in 64 of
150 frames and measured it up to 9.3 px off in the others; two balls resting against the walls
were up to 4.8 px off). Before the clip is tracked, a scout tracks the bodies through the median's
own frames, which are in memory already. :func:`unheld` then takes the median again, leaving out
of each frame the pixels near where the scout found its bodies (each frame brought to the
median's light first). Where that differs from the median by more than the frames' noise
threshold, the median held a body. The scout then looks again against the median mended there,
since it may have lost a body creeping within its own ghost, and :func:`unheld` is asked again
with what it found. The clip is decoded and tracked once, against the median so mended
(:func:`~physbench.video.track.track_video`). A body held where it starts (still
from the start over more than half of the frames: a ball held, then let go) is not in the first
frame's difference to the median at all, so the scout fails there: :func:`at_start` mends
the median there from the frames that show the wall after it left, and the tracker looks again
(measured: a ball still for 1.2 s of a 2 s clip was refused; now tracked in all 60 frames,
0.21 px off at most).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from physbench.calibration import Calibration
from physbench.recording import Track
from physbench.scene import Body, Scene
from physbench.video.background import MedianFrames
from physbench.video.compiled import jit
from physbench.video.photometry import LightMeter

#: Pixels left out around a tracked body's outline (px): blur, a halo of coding, the
#: track's own error.
MARGIN = 2.0
#: A tracked body's place is left out to this many times its radius (and :data:`MARGIN`): a
#: track against a median that holds a body may be off by a good part of its radius
#: (three_circles: a ball of 31 px radius tracked 10.7 px off; with only the margin, the median
#: taken again kept part of it and a ball was lost in one more frame).
COVER = 1.25
#: Across a gap in a body's track, the straight way between its places either side is covered
#: only where they are within this many of its covering discs' radii of each other. The scout's
#: tracks (:func:`~physbench.video.track.track_video`) come from frames over a second apart on a
#: long clip, where a fast ball is lost in most: the ways between its places covered over nearly
#: the whole image at least a third of the time, and the median taken again over so few frames
#: there took 82 MiB on the 20 s clip of ``benchmarks/track_speed.py`` (50 on the 5 s one).
SPAN = 2.0
#: A body is held where the median, taken without the bodies, differs from the median on at
#: least this share of its area (and on 3 px or more). A body that creeps leaves a ghost of only
#: the part of it that stayed put over half of the frames (measured: 284 px of a 20.7 px ball
#: creeping 60 px in 17 s, a fifth of its area, and it pulled the ball's centre 4.2 px off).
HELD_SHARE = 0.05


@dataclass(frozen=True)
class Held:
    """The median ``background`` mended where it held ``bodies``, and how many ``pixels`` were
    mended; ``unknown``: where it holds one of them in every kept frame, so that no frame showed
    what is behind it (the part of a pendulum's arm near its pivot), or ``None``."""

    background: np.ndarray
    bodies: tuple[str, ...]
    pixels: int
    unknown: np.ndarray | None = None


def unheld(
    median: MedianFrames,
    tracks: Mapping[str, np.ndarray],
    scene: Scene,
    calibration: Calibration,
    poses: Mapping[str, Track] | None = None,
) -> Held | None:
    """Called by :func:`~physbench.video.track.track_video` after tracking the median's own
    frames against the clip's ``median``, with each body's image track ``(t, u, v)`` (s from the
    first frame, px), and ``poses``: the same tracks in scene metres with their angles, by which
    a polygon is covered by its outline where it was measured, not by the disc of its extent (a
    pendulum's arm: that disc covers its pivot in every frame, so the ghost of the arm there was
    never taken out). Returns the median mended where it held a body, or ``None`` where it held
    none (or the frames' times are unknown)."""
    times = median.times
    n, h, w = median.frames.shape[:3]
    if n < 2 or not np.isfinite(times).all():
        return None
    dt = 1.0 / scene.fps
    bodies = [b for b in scene.bodies if b.name in tracks and len(tracks[b.name])]
    if not bodies:
        return None
    covered, close, stays, avoid = _covers(median, bodies, tracks, calibration, dt, poses)
    # The median shows a body only where it was there in over half of the kept frames; a third
    # leaves room for the median's noise. The rest of the frames' pixels are not looked at.
    touched = covered.view(np.uint8).sum(axis=0, dtype=np.uint8 if n < 256 else np.uint16) * 3 >= n
    if not touched.any():
        return None
    meter = LightMeter(median.image)
    lights = [meter.measure(median.frames[k], avoid[k]) for k in range(n)]
    levels = [light.threshold() for light in lights]
    # Each frame is brought to the median's light as the median is taken (raw - offset) / gain.
    offset = np.array([light.offset for light in lights], dtype=np.float32)
    gain = np.array([light.gain for light in lights], dtype=np.float32)
    values = median.frames[:, touched]  # (n, m, 3) uint8
    at = np.flatnonzero(touched)
    again = _median_without(values, covered.reshape(n, -1)[:, at], offset, gain)
    free = np.isfinite(again).all(axis=1)
    if not free.all():
        # Covered in every kept frame: what the frames show just outside the bodies themselves.
        # A ball let go late shows the wall at the edge of where it rested in its last frames
        # only, and there within COVER of it (measured: a ball held 1.6 s of 2 s left a crescent
        # of its ghost there, and a frame rolling over it was 2.6 px off).
        rest = ~free
        near = close.reshape(n, -1)[:, at[rest]]
        again[rest] = _median_without(values[:, rest], near, offset, gain)
        free = np.isfinite(again).all(axis=1)
    before = median.image[touched].astype(np.float32)
    off = np.zeros(len(before), bool)
    off[free] = np.abs(again[free] - before[free]).max(axis=1) > float(np.median(levels))
    # A flagged pixel is the ghost of the body that covered it in most kept frames: the one
    # that stayed there, not one that crossed its ghost (all of them among the touched pixels).
    stayed = stays[:, touched]
    most, anyone = np.argmax(stayed, axis=0), stayed.max(axis=0) > 0
    owner = np.where(off & anyone, most, -1)
    held, mend, kept = [], np.zeros(len(owner), bool), np.zeros(len(bodies), bool)
    for i, b in enumerate(bodies):
        u, v = calibration.to_image(np.asarray(b.position, dtype=float)[None])[0]
        area = b.shape.area() / calibration.metres_per_pixel((u, v)) ** 2
        mine = owner == i
        if mine.sum() >= max(3.0, HELD_SHARE * area):
            held.append(b.name)
            mend |= mine
            kept[i] = True
    if not held:
        return None
    # Never shown behind a held body: no kept frame saw it off there, even by its outline.
    unknown = np.zeros((h, w), bool)
    unknown[touched] = ~free & anyone & kept[most]
    mended = median.image.copy()
    fill = np.where(free[:, None], again, 0.0)[mend]
    rows, cols = np.nonzero(touched)
    mended[rows[mend], cols[mend]] = np.clip(np.rint(fill), 0, 255).astype(np.uint8)
    return Held(mended, tuple(held), int(mend.sum()), unknown if unknown.any() else None)


def _covers(
    median: MedianFrames,
    bodies: list[Body],
    tracks: Mapping[str, np.ndarray],
    calibration: Calibration,
    dt: float,
    poses: Mapping[str, Track] | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[list[tuple[float, float, float]]]]:
    """The pixels of each kept frame within :data:`COVER` of a tracked body (``covered``), within
    :data:`MARGIN` only (``close``), how many kept frames cover each pixel by body (``stays``),
    and the discs each frame's light is measured around (``avoid``)."""
    times = median.times
    n, h, w = median.frames.shape[:3]
    covered = np.zeros((n, h, w), bool)
    close = np.zeros((n, h, w), bool)  # the bodies with MARGIN only, not COVER
    stays = np.zeros((len(bodies), h, w), np.int16)  # how many kept frames cover each pixel
    avoid: list[list[tuple[float, float, float]]] = [[] for _ in range(n)]
    groups: list[tuple[int, int]] = []  # the frame and the body of each set of discs
    local: list[tuple[float, float, float]] = []  # the sets' discs (u, v, r), end to end
    ends: list[int] = []
    for i, b in enumerate(bodies):
        rows = np.asarray(tracks[b.name], dtype=float)
        pose = (poses or {}).get(b.name)
        outlined = pose is not None and pose.angle is not None and hasattr(b.shape, "vertices")
        for k, tau in enumerate(times):
            discs = _places(rows, tau, dt, b.shape.extent(), calibration)
            avoid[k] += discs
            outlines = _outlines(pose, b.shape, tau, dt, calibration) if outlined else None
            if outlines is None:  # drawn with the other discs below
                if discs:
                    groups.append((k, i))
                    local += discs
                    ends.append(len(local))
                continue
            box = _hull_box(outlines, h, w)
            if box is None:
                continue
            (r0, r1), (c0, c1) = box
            here = np.zeros((r1 - r0, c1 - c0), bool)  # the outlines' box only
            near = np.zeros_like(here)
            for pts in outlines:
                pts = pts - (c0, r0)
                centre = pts.mean(axis=0)
                _polygon(here, centre + COVER * (pts - centre))
                _polygon(near, pts)
            covered[k, r0:r1, c0:c1] |= here
            close[k, r0:r1, c0:c1] |= near
            stays[i, r0:r1, c0:c1] += here
    if groups:
        d = np.array(local)
        inner = (d[:, 2] - MARGIN) / COVER + MARGIN
        _draw(
            covered,
            close,
            stays,
            np.array(groups),
            np.array(ends),
            d[:, 0],
            d[:, 1],
            d[:, 2],
            inner,
        )
    return covered, close, stays, avoid


@jit
def _draw(covered, close, stays, groups, ends, u, v, r, inner):  # type: ignore[no-untyped-def]
    """:func:`_disc` of each disc of each set of ``groups`` (rows ``k, i``: the frame and the
    body; the set's discs end at ``ends``) into ``covered[k]`` at radius ``r`` and into
    ``close[k]`` at ``inner``, counted once a set into ``stays[i]``: the same pixels, each set
    over the rows and columns its discs touch (as :func:`_disc` rounds), in one call (NumPy
    calls a disc at a time took about 18 ms over the 15 frames of a 6-ball rack)."""
    h, w = covered.shape[1], covered.shape[2]
    row, across = np.empty(len(u), np.int64), np.empty(len(u))
    start = 0
    for g in range(len(groups)):
        k, i = groups[g]
        lo_u, hi_u, lo_v, hi_v = np.inf, -np.inf, np.inf, -np.inf
        for j in range(start, ends[g]):
            lo_u, hi_u = min(lo_u, u[j] - r[j]), max(hi_u, u[j] + r[j])
            lo_v, hi_v = min(lo_v, v[j] - r[j]), max(hi_v, v[j] + r[j])
        r0, r1 = max(0, math.floor(lo_v)), min(h, math.ceil(hi_v) + 1)
        c0, c1 = max(0, math.floor(lo_u)), min(w, math.ceil(hi_u) + 1)
        for y in range(r0, r1):
            dy = y - r0
            # The discs this row crosses (a row farther than a disc's radius is outside it,
            # and outside its inner disc), and the columns they span.
            count, x0, x1 = 0, c1, c0
            for j in range(start, ends[g]):
                b = dy - (v[j] - r0)
                if b * b <= r[j] * r[j]:
                    row[count], across[count] = j, b * b
                    count += 1
                    x0 = min(x0, max(c0, math.floor(u[j] - r[j])))
                    x1 = max(x1, min(c1, math.ceil(u[j] + r[j]) + 1))
            for x in range(x0, x1):
                dx = x - c0
                here, near = False, False
                for q in range(count):
                    j = row[q]
                    a = dx - (u[j] - c0)
                    d2 = a * a + across[q]
                    here |= d2 <= r[j] * r[j]
                    near |= d2 <= inner[j] * inner[j]
                    if near:  # inside the inner disc: inside the disc too
                        break
                if here:
                    covered[k, y, x] = True
                    stays[i, y, x] += 1
                if near:
                    close[k, y, x] = True
        start = ends[g]


def at_start(median: MedianFrames, scene: Scene, calibration: Calibration) -> Held | None:
    """Called by :func:`~physbench.video.track.track_video` when a body was not found in the
    first frame against the clip's ``median``: the median mended where it holds a body at its
    place in the first frame, or ``None`` where it holds none there.

    A body that stays put from the start over more than half of the kept frames (a ball held
    still, then let go) is part of the median where the scene says it starts, so the first
    frame does not differ from the median there. It is held there if the first kept frame is
    like the median over most of its disc, and at least two other kept frames are unlike it
    there and like each other: the wall after the body left. The disc is mended with their
    median."""
    mended, held, count = median.image.copy(), [], 0
    for place in _starts(median, scene, calibration):
        unlike = place.unlike
        if unlike[0] or unlike.sum() < 2:
            continue
        seen = place.seen[unlike]
        wall = np.median(seen, axis=0)
        near = np.abs(seen - wall).max(axis=2) <= place.level
        agree = near[:, place.core].mean(axis=1) > 0.5
        if agree.sum() < 2:
            continue
        wall = np.median(seen[agree], axis=0)
        mended[place.disc] = np.clip(np.rint(wall), 0, 255).astype(np.uint8)
        held.append(place.name)
        count += int(place.disc.sum())
    if not held:
        return None
    return Held(mended, tuple(held), count)


def still_at_start(
    median: MedianFrames, scene: Scene, calibration: Calibration
) -> dict[str, tuple[int, int]]:
    """Called by :func:`~physbench.video.track.track_video` when a body was not found in the
    first frame against the clip's ``median`` and :func:`at_start` mended nothing: for each body
    whose place in the first frame is like the median, in how many of the median's frames it is
    so (and of how many), for the error to say."""
    out = {}
    for place in _starts(median, scene, calibration):
        if not place.unlike[0]:
            out[place.name] = (int((~place.unlike).sum()), len(place.unlike))
    return out


@dataclass(frozen=True)
class _Start:
    """A body's place in the first frame (``disc``, with :data:`MARGIN`; ``core``: the body's
    own pixels among them), each kept frame's pixels there in the median's light (``seen``),
    whether each is unlike the median over most of the body, and the frames' noise ``level``."""

    name: str
    disc: np.ndarray
    core: np.ndarray
    seen: np.ndarray
    unlike: np.ndarray
    level: float


def _starts(median: MedianFrames, scene: Scene, calibration: Calibration) -> list[_Start]:
    """:class:`_Start` of each body the scene starts in view of the median's frames, the first
    of which is the clip's first (none where the frames' times are unknown)."""
    n, h, w = median.frames.shape[:3]
    if n < 3 or not np.isfinite(median.times).all():
        return []
    places = []
    for b in scene.bodies:
        u, v = calibration.to_image(np.asarray(b.position, dtype=float)[None])[0]
        r = b.shape.extent() / calibration.metres_per_pixel((u, v)) + MARGIN
        if -r < u < w + r and -r < v < h + r:
            places.append((b.name, float(u), float(v), float(r)))
    if not places:
        return []
    meter = LightMeter(median.image)
    avoid = [(u, v, r) for _, u, v, r in places]
    lights = [meter.measure(median.frames[k], avoid) for k in range(n)]
    level = float(np.median([light.threshold() for light in lights]))
    out = []
    for name, u, v, r in places:
        disc, body = np.zeros((h, w), bool), np.zeros((h, w), bool)
        _disc(disc, u, v, r)  # mended: the body with a margin
        _disc(body, u, v, r - MARGIN)  # judged: the body itself
        core = body[disc]
        if core.sum() < 3:
            continue
        before = median.image[disc].astype(np.float32)
        seen = np.stack(
            [
                (median.frames[k][disc] - light.offset.astype(np.float32))
                / light.gain.astype(np.float32)
                for k, light in enumerate(lights)
            ]
        )  # (n, m, 3) in the median's light
        off = np.abs(seen - before).max(axis=2) > level
        out.append(_Start(name, disc, core, seen, off[:, core].mean(axis=1) > 0.5, level))
    return out


def _places(
    rows: np.ndarray, tau: float, dt: float, extent: float, calibration: Calibration
) -> list[tuple[float, float, float]]:
    """Discs ``(u, v, r)`` (px) covering where a body of ``extent`` (m) tracked at ``rows`` was
    over the frame at ``tau`` (s), its exposure and a frame ``dt`` either side: its places
    interpolated then, and where it was not measured in that frame (a gap in its track; the
    track may have been measured in the median's frames only) the straight way between the
    places either side of it, in steps of half its radius, if they are within :data:`SPAN` discs
    of each other (else none: it was on its way, and cannot have stayed put there)."""
    t = rows[:, 0]
    x = np.array([tau - dt, tau, tau + dt])
    pts = list(np.column_stack([np.interp(x, t, rows[:, 1]), np.interp(x, t, rows[:, 2])]))
    j = int(np.searchsorted(t, tau - 0.5 * dt))
    seen = j < len(t) and t[j] <= tau + 0.5 * dt  # measured in this frame
    if not seen and 0 < j < len(t):  # unseen then: anywhere between
        a, b = rows[j - 1, 1:3], rows[j, 1:3]
        r = COVER * extent / calibration.metres_per_pixel(a) + MARGIN
        if float(np.hypot(*(b - a))) > SPAN * r:
            return []
        pts = [a, b]
    out: list[tuple[float, float, float]] = []
    for a, b in itertools.pairwise(pts):
        r = COVER * extent / calibration.metres_per_pixel(a) + MARGIN
        steps = max(1, math.ceil(float(np.hypot(*(b - a))) / max(0.5 * r, 0.5)))
        p = a[None] + np.linspace(0.0, 1.0, steps + 1)[:, None] * (b - a)[None]
        out += [(float(pu), float(pv), r) for pu, pv in p.tolist()]
    return out


def _outlines(
    pose: Track, shape: object, tau: float, dt: float, calibration: Calibration
) -> list[np.ndarray] | None:
    """A polygon body's outlines in the image (``(k, 2)`` px each) where its ``pose`` track
    puts it over the frame at ``tau`` (s), its exposure and a frame ``dt`` either side; ``None``
    where it was not measured in that frame (:func:`_places` covers it then)."""
    t = np.asarray(pose.t, dtype=float)
    j = int(np.searchsorted(t, tau - 0.5 * dt))
    if not (j < len(t) and t[j] <= tau + 0.5 * dt):
        return None
    angle = np.unwrap(np.asarray(pose.angle, dtype=float))
    body = np.asarray(shape.vertices(), dtype=float)  # type: ignore[attr-defined]
    out = []
    for x in (tau - dt, tau, tau + dt):
        a = float(np.interp(x, t, angle))
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        xy = np.array([np.interp(x, t, pose.x), np.interp(x, t, pose.y)])
        out.append(calibration.to_image(xy + body @ rot.T))
    return out


def _hull_box(
    outlines: list[np.ndarray], h: int, w: int
) -> tuple[tuple[int, int], tuple[int, int]] | None:
    """The rows and columns ``((r0, r1), (c0, c1))`` of an ``(h, w)`` image that ``outlines``
    scaled by :data:`COVER` about their centres and widened by :data:`MARGIN` touch, or ``None``
    where they touch none."""
    pts = np.concatenate([o.mean(axis=0) + COVER * (o - o.mean(axis=0)) for o in outlines])
    lo, hi = pts.min(axis=0) - MARGIN, pts.max(axis=0) + MARGIN
    r0, r1 = max(0, math.floor(float(lo[1]))), min(h, math.ceil(float(hi[1])) + 1)
    c0, c1 = max(0, math.floor(float(lo[0]))), min(w, math.ceil(float(hi[0])) + 1)
    if r0 >= r1 or c0 >= c1:
        return None
    return (r0, r1), (c0, c1)


def _polygon(mask: np.ndarray, pts: np.ndarray) -> None:
    """Set the pixels of ``mask`` within :data:`MARGIN` of the convex polygon ``pts`` (``(k,
    2)`` px, either orientation), measured along each edge's normal (a little more than
    MARGIN at the corners)."""
    h, w = mask.shape
    lo, hi = pts.min(axis=0) - MARGIN, pts.max(axis=0) + MARGIN
    r0, r1 = max(0, math.floor(float(lo[1]))), min(h, math.ceil(float(hi[1])) + 1)
    c0, c1 = max(0, math.floor(float(lo[0]))), min(w, math.ceil(float(hi[0])) + 1)
    if r0 >= r1 or c0 >= c1:
        return
    yy, xx = np.ogrid[r0:r1, c0:c1]
    x, y = pts[:, 0], pts[:, 1]
    turn = 1.0 if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0 else -1.0
    outside = np.full((r1 - r0, c1 - c0), -np.inf)
    for (ax, ay), (bx, by) in zip(pts, np.roll(pts, -1, axis=0), strict=True):
        ex, ey = bx - ax, by - ay
        n = math.hypot(ex, ey)
        if n > 0:  # the distance out of the polygon across this edge
            np.maximum(outside, turn * ((xx - ax) * ey - (yy - ay) * ex) / n, out=outside)
    mask[r0:r1, c0:c1] |= outside <= MARGIN


def _median_without(
    values: np.ndarray, left_out: np.ndarray, offset: np.ndarray, gain: np.ndarray
) -> np.ndarray:
    """The median over the frames of ``values`` ``(n, m, 3)`` uint8, each frame ``k`` brought to
    the median's light (``(value - offset[k]) / gain[k]``, float32, per channel), of each
    pixel's channels, leaving out the frames where ``left_out`` ``(n, m)`` says so: ``(m, 3)``
    float32, NaN where every frame is left out; ``np.nanmedian`` of the relit values with those
    frames set to NaN, to the bit (its masked sort took 23 ms on the 5 s clip of
    ``benchmarks/track_speed.py``, a sort along the frames and NumPy's relighting 14 ms, this
    2 ms)."""
    return _medians_without(values, left_out, offset, gain)


@jit
def _medians_without(values, left_out, offset, gain):  # type: ignore[no-untyped-def]
    """:func:`_median_without`'s loops: each pixel's frames kept, relit, sorted by insertion (15
    at most in a median's frames), the middle one or the mean of the middle two."""
    n, m, channels = values.shape
    out = np.empty((m, channels), np.float32)
    kept = np.empty(n, np.float32)
    for j in range(m):
        for c in range(channels):
            count = 0
            for k in range(n):
                if left_out[k, j]:
                    continue
                x = (np.float32(values[k, j, c]) - offset[k, c]) / gain[k, c]
                i = count
                while i > 0 and kept[i - 1] > x:
                    kept[i] = kept[i - 1]
                    i -= 1
                kept[i] = x
                count += 1
            if count == 0:
                out[j, c] = np.nan
            else:
                out[j, c] = (kept[(count - 1) // 2] + kept[count // 2]) / np.float32(2.0)
    return out


def _disc(mask: np.ndarray, u: float, v: float, r: float) -> None:
    """Set the pixels of ``mask`` within ``r`` of ``(u, v)``."""
    h, w = mask.shape
    r0, r1 = max(0, math.floor(v - r)), min(h, math.ceil(v + r) + 1)
    c0, c1 = max(0, math.floor(u - r)), min(w, math.ceil(u + r) + 1)
    if r0 >= r1 or c0 >= c1:
        return
    yy, xx = np.ogrid[r0:r1, c0:c1]
    mask[r0:r1, c0:c1] |= (xx - u) ** 2 + (yy - v) ** 2 <= r * r
