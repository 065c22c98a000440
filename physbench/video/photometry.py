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

from physbench.video.medians import median
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

    def difference(
        self, image: np.ndarray, plate: np.ndarray, index: np.ndarray | None = None
    ) -> np.ndarray:
        """The largest absolute difference over the colour channels between ``image`` and
        ``plate`` in this frame's light (both ``(h, w, 3)`` uint8 crops), uint8 ``(h, w)``.
        ``index``: the plate's :func:`plate_index` crop, if at hand (a table look-up in uint8
        is several times faster than the same in floating point)."""
        if self.unchanged_levels:
            return difference(image, plate)
        if index is None:
            index = plate_index(plate)
        return difference(image, self.lut.ravel().take(index, mode="clip"))  # no bounds check


def plate_index(plate: np.ndarray) -> np.ndarray:
    """``(..., 3)`` uint16 indices into a flattened ``(3, 256)`` table for the uint8 background
    ``plate``: its values plus 256 times the channel."""
    return plate.astype(np.uint16) + np.array([0, 256, 512], dtype=np.uint16)


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
        y = image.reshape(-1, 3)[self.flat].T  # (3, n): a channel a row
        keep = self.usable & (np.maximum(np.maximum(y[0], y[1]), y[2]) < 254)
        if len(avoid):
            b = np.asarray(avoid, dtype=float)
            near = (self.u[:, None] - b[:, 0]) ** 2 + (self.v[:, None] - b[:, 1]) ** 2
            keep &= (near > b[:, 2] ** 2).all(axis=1)
        if keep.sum() < 30:
            return Light.unchanged()
        return _fit(self.bg[:, keep], y[:, keep].astype(np.float64))


def _fit(x: np.ndarray, y: np.ndarray) -> Light:
    """``y ≈ gain * x + offset`` per channel (rows of ``(3, n)``), by iteratively reweighted
    least squares with Tukey's biweight from the median ratio (the scale from its residuals):
    foreground the meter did not know of (a hand, a shadow) gets weight 0."""
    gain = median(y / np.maximum(x, 1.0), axis=1)[:, None]
    r = y - gain * x
    scale = TUKEY * np.maximum(1.4826 * median(np.abs(r), axis=1), 0.5)[:, None]
    spread = x.std(axis=1) >= MIN_SPREAD
    offset = np.zeros((3, 1))
    w = np.ones_like(x)
    for _ in range(2):
        z = r / scale
        w = np.maximum(1 - z * z, 0.0) ** 2
        # Weighted sums of 1, x, y, xx and xy per channel, at once.
        wx = w * x
        sw, sx, sy = w.sum(axis=1), wx.sum(axis=1), (w * y).sum(axis=1)
        sxx, sxy = (wx * x).sum(axis=1), (wx * y).sum(axis=1)
        det = sw * sxx - sx * sx
        sloped = (sw * sxy - sx * sy) / np.maximum(det, 1e-9)
        g = np.where(spread, sloped, sxy / np.maximum(sxx, 1e-9))
        o = np.where(spread, (sy - g * sx) / np.maximum(sw, 1e-9), 0.0)
        gain, offset = g[:, None], o[:, None]
        r = y - gain * x - offset
    r = np.abs(r)
    sigma = 1.4826 * float(median(np.maximum(np.maximum(r[0], r[1]), r[2])))
    return Light(gain[:, 0], offset[:, 0], sigma, int((w > 0).all(axis=0).sum()))
