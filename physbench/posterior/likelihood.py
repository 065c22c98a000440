"""The image likelihood of an observation model with Gaussian pixel noise clipped to [0, 1]
(:class:`~physbench.render.sensor.SensorModel`): how probable the observed frames are if
the simulated frames were the truth.

A pixel observed strictly inside (0, 1) contributes the Gaussian density of its residual; one
observed at 0 or 1 was clipped there, so it contributes the probability of the noise reaching
past that end (a censored Gaussian). Ignoring the clipping would treat a black background as
noise-free and make every posterior too narrow.
"""

from __future__ import annotations

import math

import numpy as np

from physbench.errors import PhysbenchError

#: The smallest pixel noise assumed: an 8-bit camera's quantisation step. Frames without any
#: noise would otherwise give a likelihood that is infinitely sharp.
NOISE_FLOOR = 1.0 / 255.0


def _sigma(value: object) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or not 0 < value <= 1
    ):
        raise PhysbenchError(f"pixel noise {value!r}: expected a number in (0, 1]")
    return float(value)


def estimate_noise(observation: np.ndarray) -> float:
    """A rough pixel-noise level from the observed frames alone, for when the observation model
    does not state it. Assumes most of each frame is empty background (0) whose noise was clipped
    at 0, so the values in (0, 0.5) are the upper half of a zero-mean Gaussian: sigma is their
    root mean square. Edges of objects bias it upwards a little. At least :data:`NOISE_FLOOR`."""
    obs = np.asarray(observation, dtype=np.float32)
    low = obs[(obs > 0) & (obs < 0.5)]
    if low.size < max(100, obs.size // 100):  # hardly any: frames without noise
        return NOISE_FLOOR
    return max(NOISE_FLOOR, float(np.sqrt(np.mean(np.square(low, dtype=np.float64)))))


class PixelLikelihood:
    """The log-likelihood of one observation under pixel noise ``sigma``; built once per run,
    called once per simulation."""

    def __init__(self, observation: np.ndarray, sigma: float) -> None:
        from scipy.special import log_ndtr

        self._log_ndtr = log_ndtr
        self.sigma = _sigma(sigma)
        obs = np.asarray(observation, dtype=np.float32)
        self.shape = obs.shape
        flat = obs.ravel()
        # Flat indices: np.take on them is several times faster than boolean masks.
        self.zero = np.flatnonzero(flat <= 0.0)
        self.one = np.flatnonzero(flat >= 1.0)
        self.mid = np.flatnonzero((flat > 0.0) & (flat < 1.0))
        self.obs_mid = flat[self.mid]
        self._const = -self.mid.size * math.log(self.sigma * math.sqrt(2 * math.pi))

    def __call__(self, frames: np.ndarray) -> float:
        """log p(observation | simulated ``frames``) in nats."""
        mu = np.asarray(frames, dtype=np.float32)
        if mu.shape != self.shape:
            raise PhysbenchError(
                f"simulated frames of shape {mu.shape}: expected the observation's {self.shape}"
            )
        s = self.sigma
        flat = mu.ravel()
        r = self.obs_mid - np.take(flat, self.mid)
        total = self._const - 0.5 * float(np.dot(r, r)) / (s * s)
        # Clipped at 0: P(mu + noise <= 0) = Phi(-mu / s); at 1: Phi((mu - 1) / s). Where the
        # simulation is empty too (most of a frame), that is Phi(0): counted, not computed.
        at0 = np.take(flat, self.zero)
        lit = at0[at0 > 0]
        total += (at0.size - lit.size) * math.log(0.5)
        total += float(np.sum(self._log_ndtr(lit.astype(np.float64) / -s)))
        total += float(np.sum(self._log_ndtr((np.take(flat, self.one).astype(np.float64) - 1) / s)))
        return total
