"""Observation models applied to rendered frames, for robustness experiments: camera blur and
pixel noise. Both take and return ``(..., H, W)`` float32 arrays."""

from __future__ import annotations

import numpy as np


def gaussian_blur(frames: np.ndarray, sigma: float) -> np.ndarray:
    """Blur over the last two axes (H, W) only, with a Gaussian of ``sigma`` pixels.

    Outside the image counts as empty, so the total intensity is kept for content away from the
    borders and leaks out only at them. Returns a new array; ``sigma == 0`` returns a copy.
    """
    if not sigma >= 0:
        raise ValueError(f"sigma = {sigma!r}: expected a number >= 0")
    frames = np.asarray(frames, dtype=np.float32)
    if sigma == 0:
        return frames.copy()
    from scipy.ndimage import gaussian_filter1d

    out = gaussian_filter1d(frames, sigma, axis=-1, mode="constant", cval=0.0)
    return gaussian_filter1d(out, sigma, axis=-2, mode="constant", cval=0.0, output=out)


def add_noise(frames: np.ndarray, sigma: float, rng: np.random.Generator) -> np.ndarray:
    """Add Gaussian pixel noise of standard deviation ``sigma`` drawn from ``rng``, then clip to
    [0, 1]. Returns a new float32 array."""
    if not sigma >= 0:
        raise ValueError(f"sigma = {sigma!r}: expected a number >= 0")
    out = np.array(frames, dtype=np.float32)
    if sigma > 0:
        out += rng.standard_normal(out.shape, dtype=np.float32) * np.float32(sigma)
        np.clip(out, 0.0, 1.0, out=out)
    return out
