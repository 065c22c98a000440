"""The light of each frame against the background: a gain and an offset per colour channel.

A camera's light is not the light of its background: mains flicker, a cloud, a phone's automatic
exposure, or a median background taken over a clip whose light drifts. A uniform change of a few
per cent moves every pixel of a mid-grey wall by several grey levels; a threshold from the
difference's spread then rises above the bodies' contrast (measured: frame 0 of a clip 5 %
brighter than its median put the noise threshold at 53-89 grey levels, above a ball 22-93 grey
levels from the wall). :class:`LightMeter` measures the change instead: each frame is fitted as
``gain * background + offset`` per channel, robustly (Tukey's biweight, iteratively reweighted),
on a fixed sparse grid of pixels, leaving out those near a predicted body; the difference to the
background is then taken against the background in that frame's light (:meth:`Light.difference`,
through a look-up table in uint8) and the noise threshold comes from the fit's residuals in that
frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from physbench.video.compiled import jit
from physbench.video.segment import difference

#: Pixels the meter samples per frame (a regular grid over the image): the gain's standard
#: error is then about 0.1 % for the noise of a compressed video (3 grey levels on a mid-grey
#: wall), and the fit costs a few tenths of a millisecond.
SAMPLES = 500
#: Tukey biweight tuning constant (in robust standard deviations).
TUKEY = 4.685
#: Below this spread of the sampled background (grey levels, std) an offset cannot be told from
#: a gain: the fit keeps the offset at 0 (a plain wall).
MIN_SPREAD = 6.0
#: The smallest noise threshold (grey levels): 8-bit rounding and lossy coding.
FLOOR = 12.0
#: The noise threshold, in robust standard deviations of the frame's difference.
DEVIATIONS = 6.0


@dataclass(frozen=True)
class Light:
    """One frame's light against the background: per channel ``frame = gain * background +
    offset`` (grey levels); ``sigma`` is the robust standard deviation of the largest channel
    residual (grey levels) and ``samples`` the pixels the fit kept."""

    gain: np.ndarray
    offset: np.ndarray
    sigma: float
    samples: int

    @staticmethod
    def unchanged() -> Light:
        return Light(np.ones(3), np.zeros(3), 0.0, 0)

    @property
    def change(self) -> float:
        """The frame's brightness against the background, as a fraction (+0.05: 5 % brighter),
        for a mid-grey pixel."""
        return float(np.mean(self.gain - 1.0 + self.offset / 128.0))

    @property
    def scale(self) -> float:
        """How much a contrast against the background grows in this light (the mean gain)."""
        return float(np.mean(self.gain))

    def threshold(self, floor: float = FLOOR, deviations: float = DEVIATIONS) -> float:
        """The noise threshold of this frame's difference: ``deviations`` robust standard
        deviations, at least ``floor`` grey levels."""
        return max(floor, deviations * self.sigma)

    @cached_property
    def lut(self) -> np.ndarray:
        """``(3, 256)`` uint8: each channel's background value in this frame's light, rounded
        (the rounding is under a twentieth of the smallest noise threshold)."""
        levels = np.arange(256.0)[None] * self.gain[:, None] + self.offset[:, None]
        return np.clip(np.rint(levels), 0, 255).astype(np.uint8)

    @cached_property
    def unchanged_levels(self) -> bool:
        """Whether this light maps every background level to itself."""
        return bool((self.lut == np.arange(256)[None]).all())

    def difference(self, image: np.ndarray, plate: np.ndarray) -> np.ndarray:
        """The largest absolute difference over the colour channels between ``image`` and
        ``plate`` in this frame's light (both ``(h, w, 3)`` uint8 crops), uint8 ``(h, w)``: the
        plate relit by :attr:`lut`, a table look-up in uint8 several times faster than the same
        in floating point."""
        if self.unchanged_levels:
            return difference(image, plate)
        return _relit_difference(image, plate, self.lut)


@jit
def _relit_difference(image, plate, lut):  # type: ignore[no-untyped-def]
    """:meth:`Light.difference` where the light changes levels: each pixel's largest absolute
    difference over the channels between ``image`` and ``lut`` at ``plate``, in one pass: NumPy's
    look-up through an index array and then the difference took 0.54 s of the 20 s speed clip's
    tracking, this 0.41 s (this machine, best of 3). The channels' differences are taken in int32
    without a branch: 0.19 s over the 2,736 windows of that clip's tracking against 0.24 s with a
    branch per channel (best of 2)."""
    h, w = image.shape[0], image.shape[1]
    out = np.empty((h, w), np.uint8)
    l0, l1, l2 = lut[0], lut[1], lut[2]
    for y in range(h):
        im, pl, row = image[y], plate[y], out[y]
        for x in range(w):
            d0 = np.int32(im[x, 0]) - np.int32(l0[pl[x, 0]])
            d1 = np.int32(im[x, 1]) - np.int32(l1[pl[x, 1]])
            d2 = np.int32(im[x, 2]) - np.int32(l2[pl[x, 2]])
            row[x] = max(abs(d0), max(abs(d1), abs(d2)))
    return out


class LightMeter:
    """Measures each frame's :class:`Light` against ``background`` (``(H, W, 3)`` uint8) on a
    fixed grid of about ``samples`` pixels."""

    def __init__(self, background: np.ndarray, *, samples: int = SAMPLES) -> None:
        h, w = background.shape[:2]
        step = max(1, int(np.sqrt(h * w / max(samples, 1))))
        rows, cols = np.mgrid[step // 2 : h : step, step // 2 : w : step]
        self.v = rows.ravel().astype(np.float64)
        self.u = cols.ravel().astype(np.float64)
        self.flat = (rows * w + cols).ravel()
        self.bg = np.ascontiguousarray(background.reshape(-1, 3)[self.flat].T, dtype=np.float64)
        # Clipped background pixels say nothing of a gain.
        self.usable = ((self.bg > 2) & (self.bg < 253)).all(axis=0)

    def measure(self, image: np.ndarray, avoid: Sequence[tuple[float, float, float]] = ()) -> Light:
        """Called by the tracker once per frame: the light of ``image`` (``(H, W, 3)`` uint8),
        leaving out the pixels within ``radius`` of each ``(u, v, radius)`` in ``avoid`` (the
        predicted bodies)."""
        bodies = np.asarray(avoid, dtype=np.float64).reshape(-1, 3)
        gain, offset, sigma, samples, kept = _light(
            image.reshape(-1, 3), self.flat, self.u, self.v, self.bg, self.usable, bodies
        )
        if kept < 30:
            return Light.unchanged()
        return Light(gain, offset, sigma, samples)


@jit
def _light(pixels, flat, u, v, bg, usable, bodies):  # type: ignore[no-untyped-def]
    """The light of a frame (``pixels``: its ``(H * W, 3)`` uint8 view) on the meter's grid
    (``flat`` indices, at ``u``, ``v``; background ``bg`` ``(3, n)``, ``usable`` where it is
    not clipped), away from ``bodies`` (rows ``u, v, radius``): gain, offset, sigma, samples
    and the count of pixels kept (the fit is not made under 30).

    Per channel, ``frame ≈ gain * background + offset`` by iteratively reweighted least
    squares with Tukey's biweight from the median ratio (the scale from its residuals):
    foreground the meter did not know of (a hand, a shadow) gets weight 0. The loops repeat
    the NumPy expressions they replaced operation for operation; their sums added in index
    order (``.sum(axis=1)`` of ``(3, kept)`` arrays laid out pixel by pixel, so not
    pairwise), as these do, and a median of the same values is the same by any method."""
    x, y, m = _kept(pixels, flat, u, v, bg, usable, bodies)
    gain, offset = np.ones(3), np.zeros(3)
    if m < 30:
        return gain, offset, 0.0, 0, m
    scale = np.empty(3)
    spread = np.empty(3, np.bool_)
    r = np.empty((3, m))
    w = np.empty((3, m))
    work = np.empty((3, m))  # a median's values in row 0; the other rows its selection's
    for c in range(3):  # the gain's start: the median ratio
        for j in range(m):
            work[0, j] = y[c, j] / max(x[c, j], 1.0)
        spread[c] = _spread(x, c, m)
        gain[c] = _median(work, m)
    for c in range(3):  # the scale: the median magnitude of the residuals
        for j in range(m):
            r[c, j] = y[c, j] - gain[c] * x[c, j]
            work[0, j] = abs(r[c, j])
        scale[c] = TUKEY * max(1.4826 * _median(work, m), 0.5)
    for _ in range(2):
        for c in range(3):
            gain[c], offset[c] = _reweighted(x, y, r, w, c, m, scale[c], spread[c])
    for j in range(m):
        work[0, j] = max(max(abs(r[0, j]), abs(r[1, j])), abs(r[2, j]))
    sigma = 1.4826 * _median(work, m)
    samples = 0
    for j in range(m):
        samples += w[0, j] > 0 and w[1, j] > 0 and w[2, j] > 0
    return gain, offset, sigma, samples, m


@jit
def _kept(pixels, flat, u, v, bg, usable, bodies):  # type: ignore[no-untyped-def]
    """The grid's pixels :func:`_light` fits on: ``(x, y, m)``, the background ``x`` and the
    frame ``y`` (both ``(3, n)``) of the first ``m`` columns, in grid order, at the pixels
    whose background is not clipped, whose frame is under 254 in every channel, and that lie
    outside every body."""
    n = len(flat)
    x = np.empty((3, n))
    y = np.empty((3, n))
    for i in range(n):  # gathered first: the reads do not wait on each other's tests
        for c in range(3):
            y[c, i] = pixels[flat[i], c]
    m = 0
    for i in range(n):
        if not usable[i] or max(y[0, i], y[1, i], y[2, i]) >= 254:
            continue
        clear = True
        for body in range(len(bodies)):
            du, dv = u[i] - bodies[body, 0], v[i] - bodies[body, 1]
            clear &= du * du + dv * dv > bodies[body, 2] * bodies[body, 2]
        if clear:
            for c in range(3):
                x[c, m], y[c, m] = bg[c, i], y[c, i]
            m += 1
    return x, y, m


@jit
def _spread(x, c, m):  # type: ignore[no-untyped-def]
    """Whether the standard deviation of ``x[c, :m]`` (its mean and squared deviations added in
    index order) is at least :data:`MIN_SPREAD`: else the fit keeps the offset at 0."""
    mean = 0.0
    for j in range(m):
        mean += x[c, j]
    mean /= m
    var = 0.0
    for j in range(m):
        d = x[c, j] - mean
        var += d * d
    return np.sqrt(var / m) >= MIN_SPREAD


@jit
def _reweighted(x, y, r, w, c, m, scale, spread):  # type: ignore[no-untyped-def]
    """One step of channel ``c``'s fit: Tukey's biweights ``w[c, :m]`` of the residuals
    ``r[c, :m]`` at ``scale``, the weighted least-squares gain and offset (the offset 0 where
    the background has no ``spread``), and the residuals ``r[c, :m]`` of that fit; returns
    the gain and the offset."""
    # Weighted sums of 1, x, y, xx and xy.
    sw, sx, sy, sxx, sxy = 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(m):
        z = r[c, j] / scale
        t = max(1 - z * z, 0.0)
        w[c, j] = t * t
        wx = w[c, j] * x[c, j]
        sw += w[c, j]
        sx += wx
        sy += w[c, j] * y[c, j]
        sxx += wx * x[c, j]
        sxy += wx * y[c, j]
    if spread:
        det = sw * sxx - sx * sx
        gain = (sw * sxy - sx * sy) / max(det, 1e-9)
        offset = (sy - gain * sx) / max(sw, 1e-9)
    else:
        gain, offset = sxy / max(sxx, 1e-9), 0.0
    for j in range(m):
        r[c, j] = y[c, j] - gain * x[c, j] - offset
    return gain, offset


@jit
def _median(work, m):  # type: ignore[no-untyped-def]
    """The median of ``work[0, :m]`` (``m`` at least 1), the mean of the two middle values where
    ``m`` is even; ``work`` ``(3, m)`` is overwritten."""
    # Quickselect with three-way partitions out of place: each value is written to both other
    # rows, each write index moved on by a comparison (no branch on the data, which a branch
    # predictor cannot learn).
    k, size, cur, below = m // 2, m, 0, -np.inf  # below: the largest value left below
    while True:
        lo, hi = (cur + 1) % 3, (cur + 2) % 3
        p0, p1, p2 = work[cur, 0], work[cur, size // 2], work[cur, size - 1]
        pivot = max(min(p0, p1), min(max(p0, p1), p2))  # the median of three
        less = more = 0
        for j in range(size):
            value = work[cur, j]
            work[lo, less] = value
            less += value < pivot
            work[hi, more] = value
            more += value > pivot
        if k < less:
            cur, size = lo, less
        elif k < size - more:  # the pivot
            break
        else:
            cur, size, k, below = hi, more, k - (size - more), pivot
    middle = pivot
    if m % 2 == 0:  # the mean of the two middle values
        if k == less:
            for j in range(less):
                below = max(below, work[lo, j])
        else:
            below = pivot
        middle = (below + middle) / 2
    return middle
