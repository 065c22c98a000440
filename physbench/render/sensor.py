"""How a camera degrades what a renderer draws: the observation model (:class:`SensorModel`)
and its image filters, Gaussian blur and pixel noise (both take and return ``(..., H, W)`` float32
arrays). The framework applies it to observed frames only, whatever renderer made them."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from physbench.limits import MAX_NOISE
from physbench.render.base import RenderError


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


def _nonneg(name: str, value: object) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value < 0
    ):
        raise RenderError(f"{name} = {value!r}: expected a finite number >= 0")
    return float(value)


@dataclass(frozen=True)
class SensorModel:
    """How a camera degrades what a renderer draws: Gaussian blur of ``blur`` pixels, then
    Gaussian pixel noise of standard deviation ``noise`` (drawn from ``seed`` afresh for every
    call, so an observation is a pure function of its inputs), clipped to [0, 1]. Applied to
    observed frames only; the model's frames stay sharp."""

    blur: float = 0.0
    noise: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "blur", _nonneg("blur", self.blur))
        object.__setattr__(self, "noise", _nonneg("noise", self.noise))
        if self.noise > MAX_NOISE:
            raise RenderError(
                f"noise = {self.noise!r}: expected a finite number in [0, {MAX_NOISE:g}] (the "
                "standard deviation of pixel values in [0, 1])"
            )
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer):
            raise RenderError(f"seed = {self.seed!r}: expected a whole number")

    @property
    def identity(self) -> bool:
        return self.blur == 0 and self.noise == 0

    def apply(self, frames: np.ndarray) -> np.ndarray:
        """Called on every observed view: ``frames`` degraded (in place when float32)."""
        if self.identity:
            return frames
        out = np.asarray(frames, dtype=np.float32)
        if self.blur > 0:
            out[...] = gaussian_blur(out, self.blur)
        if self.noise > 0:
            out[...] = add_noise(out, self.noise, np.random.default_rng(int(self.seed)))
        return out

    def to_dict(self) -> dict[str, Any]:
        return {"blur": self.blur, "noise": self.noise, "seed": int(self.seed)}
