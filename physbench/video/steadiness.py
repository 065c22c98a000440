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
costs 0.25 ms a 640x480 frame on the noisy, flickering rack of the tracking speed benchmark,
where the search runs in half the frames (its loops compiled; 1.1 ms in NumPy, on a machine that
decodes the clip at 600-700 frames/s). Measured on tiled walls in another light:
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

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from physbench.video.compiled import jit, pairwise_sum, solve
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
#: The background's values at each sample are kept for every shift up to this (px, each axis):
#: the search's and its walks' first steps. Read in a row each, not scattered over the picture.
BANK = SEARCH + 1


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
        # The compiled loops read float16 by its bits (numba has no float16): one array of them.
        self.planes = np.empty((3, h * w), np.uint16)
        self.grey, self.gu, self.gv = (plane.view(np.float16) for plane in self.planes)
        self.grey[:] = grey.ravel().astype(np.float16)
        gv, gu = np.gradient(grey)
        del grey
        self.gu[:], self.gv[:] = gu.astype(np.float16).ravel(), gv.astype(np.float16).ravel()
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
        # Each plane's values (float32) at each sample for each shift up to BANK px (row-major
        # over (dv, du)): (3, (2 BANK + 1)^2, samples), 1452 bytes a sample.
        reach = np.arange(-BANK, BANK + 1)
        r = np.clip(self.rows[None, None] - reach[:, None, None], 0, h - 1)
        c = np.clip(self.cols[None, None] - reach[None, :, None], 0, w - 1)
        where = (r * w + c).reshape(len(reach) ** 2, -1)
        self.bank = np.stack([a[where].astype(np.float32) for a in (self.grey, self.gu, self.gv)])
        self.best = np.inf  # the best agreement of a frame so far
        self.last = (0, 0)  # the last frame's whole-pixel shift: the walk starts there
        self.noise = np.inf  # the least noise of a frame so far (grey levels)

    def anew(self) -> ShiftMeter:
        """Called by the tracker when it is given a meter (one clip tracked against its median
        and against the median mended where it held a body, :mod:`~physbench.video.held`): this
        meter's samples, with a fresh clip's state. A mend changes only the samples on a held
        body's ghost, which then disagree with the frames at every shift and are clipped, as a
        body's are; building a meter takes 12 ms at 640x480."""
        other = copy.copy(self)
        other.best, other.last, other.noise = np.inf, (0, 0), np.inf
        return other

    @property
    def usable(self) -> bool:
        """Whether the background has texture enough to show a shift."""
        return len(self.rows) >= MIN_SAMPLES

    def measure(self, image: np.ndarray, light: Light) -> Shift | None:
        """Called by the tracker once per frame, after the frame's light is measured: the shift
        of ``image`` (``(H, W, 3)`` uint8, as the background) against the background (``None``
        where the background has too little texture to tell). Bodies need not be left out:
        their few samples are clipped, and clipped alike at every shift."""
        if not self.usable:
            return None
        seen = _box_means(image.reshape(-1), self.at, len(self.flat))
        # The frame's noise as the light meter measured it is inflated where the picture moved
        # (every edge disagrees): the least of the clip's frames is its noise.
        if light.samples:
            self.noise = min(self.noise, light.sigma)
        noise = light.sigma if np.isinf(self.noise) else self.noise
        clip2 = np.float32(CLIP * max(noise, 2.0)) ** 2

        def residuals(
            centre: tuple[int, int], around: np.ndarray, nth: int = 1, full: bool = False
        ) -> tuple[np.ndarray, np.ndarray]:
            """Per whole-pixel shift (``centre`` plus each of ``around``), the background's
            samples there (every ``nth``) in the frame's light (a gain and an offset fitted at
            that shift: the light meter's, fitted at none, is off where the picture moved) less
            the frame's (a picture moved by +du shows at u what was at u - du), where ``full``
            (else none), and the clipped mean squared disagreement."""
            return _residuals(
                self.bank, self.planes, self.rows, self.cols, self.h, self.w, seen, *centre,
                around, nth, clip2, full,
            )  # fmt: skip

        def cost(centre: tuple[int, int], around: np.ndarray, nth: int = 1) -> np.ndarray:
            """The clipped mean squared disagreement at each shift (on every ``nth`` sample)."""
            return residuals(centre, around, nth)[1]

        centre = self.last
        at_last = residuals(centre, _HERE, full=True)
        here = float(at_last[1][0])
        if not np.isfinite(self.best) or here > WORSE * self.best:  # off the last frame's shift
            centre, here = self._walk(centre, cost)
        if np.isfinite(self.best) and here > WORSE * self.best:
            few = _SEARCH[np.argsort(cost((0, 0), _SEARCH, COARSE), kind="stable")[:FEW]]
            agree = cost((0, 0), few)
            k = int(np.argmin(agree))
            if agree[k] < BETTER * here:
                centre, here = self._walk((int(few[k, 0]), int(few[k, 1])), cost)
        self.best = min(self.best, here)
        # A step of over half a pixel moves to the next whole pixel and steps again from there;
        # back at a pixel already stepped from, it ends at the shortest step taken.
        steps: dict[tuple[int, int], tuple[float, float]] = {}
        while centre not in steps and len(steps) < 3:
            d = (at_last if centre == self.last else residuals(centre, _HERE, full=True))[0]
            got = self._between(d[0], centre, seen, clip2)
            steps[centre] = (0.0, 0.0) if got is None else got
            if got is None or (abs(got[0]) <= 0.5 and abs(got[1]) <= 0.5):
                break
            centre = (centre[0] + round(got[0]), centre[1] + round(got[1]))
        centre = min(steps, key=lambda c: math.hypot(*steps[c]))
        self.last = centre
        return Shift(centre[0] + steps[centre][0], centre[1] + steps[centre][1])

    def _between(
        self, d: np.ndarray, shift: tuple[int, int], seen: np.ndarray, clip2: np.float32
    ) -> tuple[float, float] | None:
        """The shift between whole pixels from the residuals ``d`` at whole-pixel ``shift``: a
        Lucas-Kanade step with the light fitted with it (frame = gain
        background(u - s) + offset, linear in the gain, the offset and gain times s), on the
        samples that agree (clipped ones left out), each axis within a pixel; ``None`` where
        the samples' edges run one way only."""
        ok, su, sv = _lucas_kanade(
            d, *shift, self.bank, self.planes, self.rows, self.cols, self.h, self.w, seen, clip2
        )
        return (su, sv) if ok else None

    @staticmethod
    def _walk(
        centre: tuple[int, int], cost: Callable[[tuple[int, int], np.ndarray], np.ndarray]
    ) -> tuple[tuple[int, int], float]:
        """Downhill from ``centre`` over whole-pixel shifts, a 3 x 3 neighbourhood at a time, to
        where no neighbour agrees better by :data:`STEEP`; that shift and its cost."""
        costs = np.zeros(9)
        for _ in range(STEPS):
            costs = cost(centre, _NEAR)
            k = int(np.argmin(costs))
            if k == 4 or costs[k] > STEEP * costs[4]:
                break
            centre = (centre[0] + k % 3 - 1, centre[1] + k // 3 - 1)
        else:
            costs = cost(centre, _NEAR)
        return centre, float(costs[4])


def _around(radius: int) -> np.ndarray:
    """The whole-pixel shifts ``(du, dv)`` within ``radius`` of none, row-major over (dv, du)."""
    span = 2 * radius + 1
    return np.column_stack(np.divmod(np.arange(span * span), span)[::-1]) - radius


_HERE, _NEAR, _SEARCH = _around(0), _around(1), _around(SEARCH)


#: A float16's scale by its exponent bits: its 11-bit significand (10 bits and the leading 1,
#: none where the exponent is 0) times this.
_SCALE = np.array([2.0 ** (max(e, 1) - 25) for e in range(32)], np.float32)


@jit
def _box_means(flat, at, n):  # type: ignore[no-untyped-def]
    """The frame's grey over each sample's box: ``flat`` the frame's bytes, ``at`` each box's
    pixels' red bytes ``(n * BOX * BOX,)``, row by row; float32 as ``ShiftMeter.measure`` had
    it in NumPy (the channels summed, the mean of each box, a third of it). The sums are of
    whole numbers, so exact in any order: summed as integers, a box's row (``3 BOX`` bytes) at
    a time, each row's first byte read in a pass of their own, whose reads (mostly cache misses
    in the tracker) overlap."""
    first = np.empty(len(at) // BOX, np.int32)
    for j in range(len(first)):
        first[j] = flat[at[j * BOX]]
    seen = np.empty(n, np.float32)
    per = len(first) // n
    for i in range(n):
        total = 0
        for j in range(i * per, (i + 1) * per):
            total += first[j]
            for t in range(1, 3 * BOX):
                total += np.int32(flat[at[j * BOX] + t])
        seen[i] = np.float32(np.float32(np.float64(total) / (per * BOX)) / np.float32(3.0))
    return seen


@jit
def _residuals(  # type: ignore[no-untyped-def]
    bank, planes, rows, cols, h, w, seen, cu, cv, around, nth, clip2, full
):
    """``residuals`` of :meth:`ShiftMeter.measure` at ``(cu, cv)`` plus each of ``around``
    ``(K, 2)``, on every ``nth`` of the samples at ``rows``, ``cols`` (``seen`` the frame's grey
    there): the residuals ``(K, m)`` where ``full`` (else none) and each shift's clipped mean
    squared residual. The background is read from ``bank`` (``ShiftMeter.bank``) where it holds the
    shift, else from ``planes`` at the sample less the shift, clamped to the picture.

    Each row of background samples ``e`` is fitted to the frame's ``s`` by least squares (``gain
    (e - mean e) + mean s``, gain ``sum((e - mean e)(s - mean s)) / max(sum((e - mean e)^2),
    1e-6)``), as NumPy computed it in float32, each sum NumPy's pairwise one (:func:`_total`):
    the results are the same to the bit."""
    m = (len(rows) + nth - 1) // nth
    k = len(around)
    d = np.empty((k if full else 0, m), np.float32)
    cost = np.empty(k, np.float32)
    mine, off = np.empty(m, np.float32), np.empty(m, np.float32)
    de, a, b = np.empty(m, np.float32), np.empty(m, np.float32), np.empty(m, np.float32)

    for i in range(m):
        mine[i] = seen[i * nth]
    sm = np.float32(np.float64(_total(mine, m)) / m)
    for i in range(m):
        off[i] = mine[i] - sm
    floor = np.float32(1e-6)
    got = np.empty(4, np.float32)
    for j in range(k):
        du, dv = cu + around[j, 0], cv + around[j, 1]
        if abs(du) <= BANK and abs(dv) <= BANK:
            row = bank[0, (dv + BANK) * (2 * BANK + 1) + du + BANK]
            for i in range(m):
                de[i] = row[i * nth]
        else:
            for i in range(m):
                r = min(max(rows[i * nth] - dv, 0), h - 1)
                c = min(max(cols[i * nth] - du, 0), w - 1)
                de[i] = _half(planes[0, r * w + c])
        # The shift's four sums, in turn: of e; of (e - mean e)(s - mean s) and (e - mean e)^2;
        # of the clipped squared residuals.
        for q in range(4):
            if q == 1:
                em = np.float32(np.float64(got[0]) / m)
                for i in range(m):
                    de[i] = de[i] - em
                    a[i] = de[i] * off[i]
                    b[i] = de[i] * de[i]
            elif q == 3:
                gain = got[1] / max(got[2], floor)
                for i in range(m):
                    res = (gain * de[i] + sm) - mine[i]
                    if full:
                        d[j, i] = res
                    a[i] = min(res * res, clip2)
            got[q] = _total(de if q == 0 else b if q == 2 else a, m)
        cost[j] = np.float32(np.float64(got[3]) / m)
    return d, cost


@jit
def _total(x, m):  # type: ignore[no-untyped-def]
    """NumPy's ``x[:m].sum()`` of float32 values: ``0 +`` their pairwise sum."""
    return np.float32(0.0) + pairwise_sum(x, 0, m)


@jit
def _lucas_kanade(d, du, dv, bank, planes, rows, cols, h, w, seen, clip2):  # type: ignore[no-untyped-def]
    """:meth:`ShiftMeter._between` as ``(found, du, dv)`` from the residuals ``d`` at whole-pixel
    shift ``(du, dv)`` (the background read as :func:`_residuals` reads it). The median and the
    mask are NumPy's float32 ones. The normal equations are summed in sample order (their
    products, of float16 and float32 values, are exact in float64) and solved as OpenBLAS's
    ``dgesv`` solves them for ``np.linalg.solve``: the same to the bit on the machine measured
    (OpenBLAS 0.3.31, AMD EPYC), where BLAS's sums came out the same; elsewhere to rounding. An
    exactly zero pivot, which LAPACK calls singular, finds nothing."""
    mid = _median_abs(d)
    # Squares as products: Python's ** 2 (libm's pow) is a last bit off for about 0.1 % of
    # values, which moves the float32 bound only where it lies on a float32 rounding boundary.
    bound = CLIP * max(1.4826 * np.float64(mid), 1.0)
    keep = np.float32(min(np.float64(clip2), bound * bound))
    kept, count = _agreeing(d, keep)
    if count < MIN_SAMPLES:
        return False, 0.0, 0.0
    values = _background(kept, count, du, dv, bank, planes, rows, cols, h, w)
    m, rhs = _normal_equations(values, kept, count, seen)
    uu, uv, vv = m[2, 2], m[2, 3], m[3, 3]
    if not uu * vv - uv * uv > 1e-6 * ((uu + vv) * (uu + vv)):
        return False, 0.0, 0.0  # edges of one direction only
    if not solve(m, rhs):
        return False, 0.0, 0.0  # singular: np.linalg.solve's LinAlgError
    gain = rhs[0]
    if not gain > 0.1:
        return False, 0.0, 0.0
    su, sv = rhs[2] / gain, rhs[3] / gain
    su, sv = -1.0 if su < -1.0 else su, -1.0 if sv < -1.0 else sv  # Python's max(s, -1.0)
    su, sv = 1.0 if su > 1.0 else su, 1.0 if sv > 1.0 else sv  # and min(s, 1.0)
    return True, su, sv


@jit
def _median_abs(d):  # type: ignore[no-untyped-def]
    """The median of ``|d|`` (float32) as np.median finds it: the middle one, or the mean of the
    middle two (float32)."""
    # By quickselect: np.partition added 14 s to the compile of the loop that called it.
    n = len(d)
    size = np.abs(d)
    lo, hi, k = 0, n - 1, n // 2
    while lo < hi:
        pivot = size[(lo + hi) // 2]
        i, j = lo, hi
        while i <= j:
            while size[i] < pivot:
                i += 1
            while size[j] > pivot:
                j -= 1
            if i <= j:
                size[i], size[j] = size[j], size[i]
                i, j = i + 1, j - 1
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            break
    mid = size[k]
    if n % 2 == 0:  # every value before the k-th is at most it: the largest is the other
        below = size[0]
        for i in range(1, k):
            below = max(below, size[i])
        mid = np.float32(np.float64(below + mid) / 2)
    return mid


@jit
def _agreeing(d, keep):  # type: ignore[no-untyped-def]
    """The samples that agree, ``d * d < keep``: their indices (the first ``count`` of the
    array) and ``count``."""
    kept = np.empty(len(d), np.intp)
    count = 0
    for i in range(len(d)):
        if d[i] * d[i] < keep:
            kept[count] = i
            count += 1
    return kept, count


@jit
def _half(bits):  # type: ignore[no-untyped-def]
    """The float16 of ``bits`` as a float32."""
    e = (bits >> 10) & 31
    if e == 31:
        v = np.float32(np.inf) if bits & 1023 == 0 else np.float32(np.nan)
    else:
        v = np.float32((bits & 1023) + (1024 if e else 0)) * _SCALE[e]
    return -v if bits & 32768 else v


@jit
def _background(kept, count, du, dv, bank, planes, rows, cols, h, w):  # type: ignore[no-untyped-def]
    """The background's grey and its gradients ``(count, 3)`` float32 at the first ``count``
    samples of ``kept``, shifted by ``(du, dv)``: read from ``bank`` where it holds the shift,
    else from ``planes`` at the sample less the shift, clamped to the picture. Read before any
    sum: each read is independent of the others."""
    values = np.empty((count, 3), np.float32)
    if abs(du) <= BANK and abs(dv) <= BANK:
        row = (dv + BANK) * (2 * BANK + 1) + du + BANK
        for t in range(count):
            for p in range(3):
                values[t, p] = bank[p, row, kept[t]]
    else:
        for t in range(count):
            i = kept[t]
            q = min(max(rows[i] - dv, 0), h - 1) * w + min(max(cols[i] - du, 0), w - 1)
            for p in range(3):
                values[t, p] = _half(planes[p, q])
    return values


@jit
def _normal_equations(values, kept, count, seen):  # type: ignore[no-untyped-def]
    """The normal equations ``(m, rhs)`` of the columns (e, 1, -gu, -gv) of ``values`` against
    the frame's grey ``seen`` at the first ``count`` samples of ``kept``, each sum in sample
    order in float64. The matrix is symmetric (as NumPy's a.T @ a came out), and gu @ gu,
    gu @ gv and gv @ gv are three of its sums."""
    ee = e1 = eu = ev = u1 = v1 = uu = uv = vv = es = s1 = us = vs = 0.0
    for t in range(count):
        e, u, v = np.float64(values[t, 0]), -np.float64(values[t, 1]), -np.float64(values[t, 2])
        s = np.float64(seen[kept[t]])
        ee, e1, eu, ev = ee + e * e, e1 + e, eu + e * u, ev + e * v
        u1, v1, uu, uv, vv = u1 + u, v1 + v, uu + u * u, uv + u * v, vv + v * v
        es, s1, us, vs = es + e * s, s1 + s, us + u * s, vs + v * s
    m = np.array(
        [[ee, e1, eu, ev], [e1, np.float64(count), u1, v1], [eu, u1, uu, uv], [ev, v1, uv, vv]]
    )
    rhs = np.array([es, s1, us, vs])
    return m, rhs
