"""Whether the camera stayed put: each frame's shift against the background.

The tracker finds bodies as what differs from a background, so it needs a fixed camera. A phone
held in the hand, a tripod knocked during the clip, or a phone's image stabilisation moves the
whole picture by a pixel or more; every textured edge of the wall then differs from the
background, the bodies' blobs drown in that, and a lost body would be blamed on contrast or an
occluder (measured: a toss filmed with a 0.3 px-per-frame random walk of the camera, 2.5 px at
most, was refused as lost in 21 % of its frames, with no word of the camera).

:class:`ShiftMeter` measures the shift instead, in grey, on the background's most textured pixels
(the steepest of each cell of a grid, each a 3 x 3 box, where a shift shows most), in the light
that fits each shift best (a gain and an offset: the light meter's, fitted at no shift, is off
where the picture moved): the whole-pixel shift where frame and background agree best (the last
frame's, while it agrees as well as the clip's frames did; else a walk downhill over 3 x 3 shifts,
and a search of every shift up to :data:`SEARCH` px where the walk ends in a false dip of a
periodic wall, bricks), then a Lucas-Kanade step between pixels with the light fitted with it. It
costs 0.15-0.3 ms a 640x480 frame (0.29 on the noisy, flickering rack of the tracking speed
benchmark, where the search runs in half the frames). Measured on tiled walls in another light:
within 0.08 px of shifts up to 4 px; on a toss whose camera shook 0.3 px a frame (2.5 px at most),
within 0.15 px. A background with no texture shows no shift, and none is needed: moving a plain
wall changes no pixel.

The tracker does not follow the camera; it says that it moved, and when. Moving each frame back
onto the background was tried (with the shifts of an earlier meter, which took the light meter's
light and was a pixel off now and then) on a toss before a brick wall at 320x240, knocked by 0.6-4
px a third of the way through: alone, a shift measured a pixel off now and then made a false
detection 20 px from the ball where the tracker without it refused the clip; kept only where the
moved frame then agreed with the background as steady frames do (and with the median taken over
frames moved onto the first), it made no false detection, but of 8 knocked runs (4 knocks, plate
and median) only one more was tracked in full. Tried again with this meter: against a plate, a toss
whose camera shook a pixel a frame was followed in 25 of 28 frames (13 without), within 0.9 px
(median); against the clip's median, a 0.3 px-a-frame shake made a false detection 17 px from the
ball. Following the camera needs a background in the first frame's view that this does not yet
build.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from physbench.video.photometry import Light

#: Side (px) of the box a sample averages.
BOX = 3
#: Grid cell (px) from which the steepest background pixel is sampled.
CELL = 24
#: The background's gradient (grey levels per px) below which a pixel shows no shift.
MIN_GRADIENT = 6.0
#: The largest shift searched everywhere (px, each axis); the walk downhill may go further.
SEARCH = 4
#: Steps the walk downhill takes at most.
STEPS = 12
#: The walk steps only where a neighbour agrees better by this factor: against a blurred
#: background (the median of a clip whose camera shook) agreement is flat, and a walk without it
#: drifts on the noise (measured: 11 px for a 2.5 px shake).
STEEP = 0.97
#: A camera that moved less than this (px) stayed put, as far as the tracker is concerned.
MOVED_PX = 0.5
#: Residuals over this many of the frame's noise are clipped in the agreement (bodies, a hand).
CLIP = 3.0
#: The walk's best is trusted while it agrees within this factor of the best agreement so far
#: (a shift between whole pixels agrees worse than the best frames: up to half a pixel of
#: every edge's contrast).
WORSE = 2.0
#: A shift the search found far from the walk's replaces it where it agrees better by this
#: factor (a periodic wall agrees in part at a period's shift).
BETTER = 0.7
#: Fewest textured samples a shift is measured on.
MIN_SAMPLES = 20
#: The search of every shift ranks them on every this-many-th sample, and compares the
#: :data:`FEW` best on all: on a noisy, flickering clip its last shift agrees 1-5 times worse
#: than its best frame in frames where nothing moved, so the search runs in about half of them.
COARSE = 4
FEW = 3


@dataclass(frozen=True)
class Shift:
    """How far a frame's picture lies from the background's: ``(du, dv)`` px (``u`` right, ``v``
    down)."""

    du: float
    dv: float

    @property
    def size(self) -> float:
        return float(np.hypot(self.du, self.dv))


class ShiftMeter:
    """Measures each frame's :class:`Shift` against ``background`` (``(H, W, 3)`` uint8)."""

    def __init__(self, background: np.ndarray) -> None:
        from scipy import ndimage

        # Compared in grey over 3 x 3 boxes: grain a pixel wide agrees at no shift but its own,
        # so it narrows the dip a walk must find; edges of tiles, bricks or planks widen it.
        # Kept in float16 (a tenth of a grey level at worst) with its gradients: 6 bytes a pixel.
        h, w = background.shape[:2]
        grey = np.zeros((h, w), np.float32)
        for k in range(3):
            grey += ndimage.uniform_filter(background[..., k].astype(np.float32), BOX)
        grey /= np.float32(3.0)
        self.grey = grey.ravel().astype(np.float16)
        gv, gu = np.gradient(grey)
        del grey
        self.gu, self.gv = gu.astype(np.float16).ravel(), gv.astype(np.float16).ravel()
        steep = np.hypot(gu, gv)
        del gu, gv
        rows, cols = [], []
        for r0 in range(BOX, h - BOX, CELL):
            for c0 in range(BOX, w - BOX, CELL):
                cell = steep[r0 : min(r0 + CELL, h - BOX), c0 : min(c0 + CELL, w - BOX)]
                r, c = divmod(int(np.argmax(cell)), cell.shape[1])
                if cell[r, c] >= MIN_GRADIENT:
                    rows.append(r0 + r)
                    cols.append(c0 + c)
        self.rows, self.cols = np.array(rows, dtype=np.intp), np.array(cols, dtype=np.intp)
        self.h, self.w = h, w
        self.flat = self.rows * w + self.cols
        box = np.arange(BOX) - BOX // 2
        box = (box[:, None] * w + box[None, :]).ravel()
        self.at = 3 * (self.flat[:, None] + box[None]).ravel()  # each box's pixels' red bytes
        self.best = np.inf  # the best agreement of a frame so far
        self.last = (0, 0)  # the last frame's whole-pixel shift: the walk starts there
        self.noise = np.inf  # the least noise of a frame so far (grey levels)

    @property
    def usable(self) -> bool:
        """Whether the background has texture enough to show a shift."""
        return len(self.rows) >= MIN_SAMPLES

    def measure(self, image: np.ndarray, light: Light) -> Shift | None:
        """Called by the tracker once per frame, after the frame's light is measured: the shift
        of ``image`` against the background (``None`` where the background has too little
        texture to tell). Bodies need not be left out: their few samples are clipped, and
        clipped alike at every shift."""
        if not self.usable:
            return None
        flat = image.reshape(-1)
        seen = sum(flat.take(self.at + k).astype(np.float32) for k in range(3))
        seen = seen.reshape(len(self.flat), -1).mean(axis=1) / np.float32(3.0)
        # The frame's noise as the light meter measured it is inflated where the picture moved
        # (every edge disagrees): the least of the clip's frames is its noise.
        if light.samples:
            self.noise = min(self.noise, light.sigma)
        noise = light.sigma if np.isinf(self.noise) else self.noise
        clip2 = np.float32(CLIP * max(noise, 2.0)) ** 2

        def residuals(shifts: list[tuple[int, int]], nth: int = 1) -> tuple[np.ndarray, np.ndarray]:
            """Per whole-pixel shift, the background's samples there (every ``nth``) in the
            frame's light (a gain and an offset fitted at that shift: the light meter's, fitted
            at none, is off where the picture moved) less the frame's (a picture moved by +du
            shows at u what was at u - du), and where they are read."""
            du = np.array([s[0] for s in shifts])[:, None]
            dv = np.array([s[1] for s in shifts])[:, None]
            rows, cols = self.rows[None, ::nth], self.cols[None, ::nth]
            where = (rows - dv) * self.w + (cols - du)
            if np.abs(du).max() >= BOX or np.abs(dv).max() >= BOX:  # may leave the picture
                r = np.minimum(np.maximum(rows - dv, 0), self.h - 1)
                c = np.minimum(np.maximum(cols - du, 0), self.w - 1)
                where = r * self.w + c
            e = self.grey.take(where).astype(np.float32)
            mine = seen[::nth]
            return _in_light(e, mine) - mine, where

        def cost(shifts: list[tuple[int, int]], nth: int = 1) -> np.ndarray:
            """The clipped mean squared disagreement at each shift (on every ``nth`` sample)."""
            d = residuals(shifts, nth)[0]
            return np.minimum(d * d, clip2).mean(axis=1)

        centre = self.last
        at_last = residuals([centre])
        here = float(np.minimum(at_last[0] ** 2, clip2).mean())
        if not np.isfinite(self.best) or here > WORSE * self.best:  # off the last frame's shift
            centre, here = self._walk(centre, cost)
        if np.isfinite(self.best) and here > WORSE * self.best:
            every = _around((0, 0), SEARCH)
            few = [every[k] for k in np.argsort(cost(every, COARSE), kind="stable")[:FEW]]
            agree = cost(few)
            k = int(np.argmin(agree))
            if agree[k] < BETTER * here:
                centre, here = self._walk(few[k], cost)
        self.best = min(self.best, here)
        # A step of over half a pixel moves to the next whole pixel and steps again from there;
        # back at a pixel already stepped from, it ends at the shortest step taken.
        steps: dict[tuple[int, int], tuple[float, float]] = {}
        while centre not in steps and len(steps) < 3:
            d, where = at_last if centre == self.last else residuals([centre])
            got = self._between(d[0], where[0], seen, clip2)
            steps[centre] = (0.0, 0.0) if got is None else got
            if got is None or (abs(got[0]) <= 0.5 and abs(got[1]) <= 0.5):
                break
            centre = (centre[0] + round(got[0]), centre[1] + round(got[1]))
        centre = min(steps, key=lambda c: math.hypot(*steps[c]))
        self.last = centre
        return Shift(centre[0] + steps[centre][0], centre[1] + steps[centre][1])

    def _between(
        self, d: np.ndarray, where: np.ndarray, seen: np.ndarray, clip2: np.float32
    ) -> tuple[float, float] | None:
        """The shift between whole pixels from the residuals ``d`` at a whole-pixel shift, read
        at ``where``: a Lucas-Kanade step with the light fitted with it (frame = gain
        background(u - s) + offset, linear in the gain, the offset and gain times s), on the
        samples that agree (clipped ones left out), each axis within a pixel; ``None`` where
        the samples' edges run one way only."""
        spread = 1.4826 * float(np.median(np.abs(d)))  # what is left of the noise, and any body
        ok = d * d < min(float(clip2), (CLIP * max(spread, 1.0)) ** 2)
        if ok.sum() < MIN_SAMPLES:
            return None
        where = where[ok]
        e = self.grey.take(where).astype(np.float64)
        gu = self.gu.take(where).astype(np.float64)
        gv = self.gv.take(where).astype(np.float64)
        uu, uv, vv = float(gu @ gu), float(gu @ gv), float(gv @ gv)
        if not uu * vv - uv * uv > 1e-6 * (uu + vv) ** 2:
            return None  # edges of one direction only
        a = np.column_stack([e, np.ones_like(e), -gu, -gv])
        try:
            gain, _, pu, pv = np.linalg.solve(a.T @ a, a.T @ seen[ok].astype(np.float64))
        except np.linalg.LinAlgError:
            return None
        if not gain > 0.1:
            return None
        return min(max(pu / gain, -1.0), 1.0), min(max(pv / gain, -1.0), 1.0)

    @staticmethod
    def _walk(
        centre: tuple[int, int], cost: Callable[[list[tuple[int, int]]], np.ndarray]
    ) -> tuple[tuple[int, int], float]:
        """Downhill from ``centre`` over whole-pixel shifts, a 3 x 3 neighbourhood at a time, to
        where no neighbour agrees better by :data:`STEEP`; that shift and its cost."""
        costs = np.zeros(9)
        for _ in range(STEPS):
            costs = cost(_around(centre, 1))
            k = int(np.argmin(costs))
            if k == 4 or costs[k] > STEEP * costs[4]:
                break
            centre = (centre[0] + k % 3 - 1, centre[1] + k // 3 - 1)
        else:
            costs = cost(_around(centre, 1))
        return centre, float(costs[4])


def _around(centre: tuple[int, int], radius: int) -> list[tuple[int, int]]:
    """The whole-pixel shifts within ``radius`` of ``centre``, row-major over (dv, du)."""
    return [
        (centre[0] + du, centre[1] + dv)
        for dv in range(-radius, radius + 1)
        for du in range(-radius, radius + 1)
    ]


def _in_light(e: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """Each row of background samples ``e`` ``(K, n)`` in the light that fits ``seen`` ``(n,)``
    best: ``gain e + offset`` by least squares, per row."""
    em, sm = e.mean(axis=1, keepdims=True), seen.mean()
    de = e - em
    gain = (de * (seen - sm)).sum(axis=1, keepdims=True) / np.maximum(
        (de * de).sum(axis=1, keepdims=True), 1e-6
    )
    return gain * de + sm
