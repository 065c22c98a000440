"""Does the model reproduce the observation? A posterior predictive check.

A posterior says how sure the estimate is *if the simulator and renderer are right*. When they are
not (another engine made the observation, a blur the model does not apply, an effect it misses),
its intervals are confidently wrong. The check simulates ``K`` draws of the posterior, renders
them and adds the observation model's pixel noise: ``K`` replicates of what the observation would
look like if the model were right. Then it asks whether the observation lies among them.

The statistic is a chi-square against the predictive spread: per pixel, the squared difference
from the replicates' mean over their variance (plus :data:`PIXEL_VARIANCE`, an 8-bit camera's
rounding variance, so that pixels no replicate moves still count), averaged over the frames.
For the observation the mean and variance come from all ``K`` replicates; for replicate ``k``
from the other ``K - 1``. ``p`` is the share of replicates at least as far out as the observation,
``(1 + #) / (K + 1)``. If the observation were one more replicate (the truth a draw of a
calibrated posterior, the noise the stated one) it would be exchangeable with them and ``p``
uniform; the check fails at ``p <=`` :data:`ALPHA`. Weighting by the predictive spread matters:
where draws disagree (the edges of moving bodies) a difference is expected, where they all agree
(a body's path in frames the posterior pins down) it is not. On npe's posteriors for Box2D
observations of three_circles (model pymunk), in an exploratory run with 40 draws, the plain
image MSE to the predictive mean caught 71 % of the runs whose 90 % interval missed the truth,
this statistic 89 %; ``benchmarks/npe_checks.py`` measures the default (97 % of 169 misses).
It is a statistic of the data alone, so it also works for posteriors whose width comes from the
method rather than from pixel noise (``npe`` on noise-free frames). Cost: ``K`` simulations and
renders, with the ``K`` frame sets held in memory up to :data:`MEMORY` bytes; beyond (ball_drop's
26:1 world renders 12.8 million values per draw at 64 px) each draw is simulated a second time
instead. Called by :func:`~physbench.experiment.run_config` after the loop when the estimator
returned a posterior.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.errors import PhysbenchError, SimulationError
from physbench.posterior.likelihood import estimate_noise
from physbench.unknowns import simulate_seen

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.posterior.samples import Posterior
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator

#: Posterior draws simulated by default: with 59, ``p <= ALPHA`` is exactly 3 of the 60 ranks
#: the observation can take, so the check fails on 5 % of runs where the model is right.
DRAWS = 59
#: The check fails at a p-value at or below this.
ALPHA = 0.05
#: The most bytes of simulated frames the check holds; more, and it simulates each draw again
#: for its second pass rather than keeping them.
MEMORY = 256 * 2**20
#: Pixels handled at once (bounds the temporaries of the per-pixel moments).
CHUNK = 2**20
#: Added to each pixel's predictive variance: the variance of an 8-bit camera's rounding,
#: (1/255)^2 / 12.
PIXEL_VARIANCE = (1.0 / 255.0) ** 2 / 12.0


@dataclass(frozen=True)
class PredictiveCheck:
    """The result of :func:`check`: ``p`` (see the module docstring), the ``draws`` simulated and
    how many of them ``failed`` to simulate, the pixel ``noise`` added to the replicates and
    where it came from (``noise_source``), the observation's chi-square ``residual`` and the
    replicates' median (``spread``; see the module docstring), and the seconds it took."""

    p: float
    draws: int
    failed: int
    noise: float
    noise_source: str
    residual: float
    spread: float
    seconds: float = 0.0
    alpha: float = ALPHA

    @property
    def reproduced(self) -> bool:
        """``False`` when the model does not reproduce the observation (``p <= alpha``)."""
        return self.p > self.alpha

    def describe(self) -> str:
        """One line for ``physbench run``: the cost and the verdict."""
        cost = f"{self.draws} simulations of posterior draws"
        if self.reproduced:
            return (
                f"posterior predictive check ({cost}): p = {self.p:.2g}, the model reproduces "
                "the observation"
            )
        return f"{warning(self.p)} (posterior predictive check, {cost})"

    def to_dict(self, *, timings: bool = True) -> dict[str, Any]:
        """JSON-ready; ``timings=False`` leaves out the seconds (they vary between identical
        runs)."""
        d = {**asdict(self), "reproduced": self.reproduced}
        if not timings:
            del d["seconds"]
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PredictiveCheck:
        names = cls.__dataclass_fields__
        return cls(**{k: v for k, v in d.items() if k in names})


def warning(p: float) -> str:
    """The sentence ``physbench run`` prints when the check fails."""
    return (
        f"the model does not reproduce the observation (p = {p:.2g}): these intervals assume it "
        "does"
    )


def _replicate(frames: np.ndarray, sigma: float, rng: np.random.Generator) -> np.ndarray:
    """``frames`` as the observation model would show them: Gaussian pixel noise ``sigma``,
    clipped to [0, 1] (:class:`~physbench.render.sensor.SensorModel`'s noise)."""
    if sigma <= 0:
        return frames
    return np.clip(frames + sigma * rng.standard_normal(frames.shape), 0.0, 1.0)


def _moments(mu: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, the mean and variance of ``clip(mu + sigma Z, 0, 1)``: what the observation
    model makes of frames ``mu``, its noise integrated out rather than sampled (a sampled
    variance would add its own scatter to the statistic)."""
    if sigma <= 0:
        return mu, np.zeros_like(mu)
    from scipy.special import ndtr

    a, b = -mu / sigma, (1.0 - mu) / sigma
    pa, pb = np.exp(-0.5 * a * a) / np.sqrt(2 * np.pi), np.exp(-0.5 * b * b) / np.sqrt(2 * np.pi)
    fa, fb = ndtr(a), ndtr(b)
    # E[X] and E[X^2] of the Gaussian truncated to [0, 1], plus the mass clipped to 1.
    m1 = mu * (fb - fa) + sigma * (pa - pb) + (1.0 - fb)
    m2 = (
        (mu * mu + sigma * sigma) * (fb - fa)
        + 2.0 * mu * sigma * (pa - pb)
        + sigma * sigma * (a * pa - b * pb)
        + (1.0 - fb)
    )
    return m1, np.maximum(m2 - m1 * m1, 0.0)


class _Sums:
    """Per-pixel sums over the draws of the replicates' mean, squared mean and noise variance
    (:func:`_moments`), and the chi-square statistics computed from them, in chunks of
    :data:`CHUNK` pixels."""

    def __init__(self, size: int, sigma: float) -> None:
        self.sigma, self.k = sigma, 0
        self.s1, self.s2, self.sv = np.zeros(size), np.zeros(size), np.zeros(size)

    def add(self, frames: np.ndarray) -> None:
        for c in range(0, frames.size, CHUNK):
            m, v = _moments(frames[c : c + CHUNK].astype(np.float64), self.sigma)
            self.s1[c : c + CHUNK] += m
            self.s2[c : c + CHUNK] += m * m
            self.sv[c : c + CHUNK] += v
        self.k += 1

    def chi(self, x: np.ndarray) -> float:
        """The statistic of ``x`` (the observation) against all draws."""
        k, total = self.k, 0.0
        for c in range(0, x.size, CHUNK):
            s1, s2, sv = self.s1[c : c + CHUNK], self.s2[c : c + CHUNK], self.sv[c : c + CHUNK]
            var = (s2 - s1 * s1 / k) / (k - 1) + sv / k
            total += _chi_sum(x[c : c + CHUNK].astype(np.float64), s1 / k, var)
        return total / x.size

    def chi_without(self, frames: np.ndarray, rng: np.random.Generator) -> float:
        """The statistic of a replicate of ``frames`` (its frames plus the observation model's
        noise) against the other draws."""
        k, total = self.k, 0.0
        for c in range(0, frames.size, CHUNK):
            mu = frames[c : c + CHUNK].astype(np.float64)
            mi, vi = _moments(mu, self.sigma)
            s1, s2, sv = self.s1[c : c + CHUNK], self.s2[c : c + CHUNK], self.sv[c : c + CHUNK]
            m = (s1 - mi) / (k - 1)
            var = (s2 - mi * mi - (k - 1) * m * m) / (k - 2) + (sv - vi) / (k - 1)
            total += _chi_sum(_replicate(mu, self.sigma, rng), m, var)
        return total / frames.size


def _chi_sum(x: np.ndarray, mean: np.ndarray, var: np.ndarray) -> float:
    """Sum over pixels of ``(x - mean)^2 / (var + PIXEL_VARIANCE)``."""
    return float(np.sum(np.square(x - mean) / (np.maximum(var, 0.0) + PIXEL_VARIANCE)))


def _noise(observation: np.ndarray, stated: float | None) -> tuple[float, str]:
    if stated is not None:
        return float(stated), "stated by the observation model"
    return estimate_noise(observation), "estimated from the frames"


def _draws(posterior: Posterior, k: int, rng: np.random.Generator) -> list[dict[str, float]]:
    n = len(posterior)
    rows = rng.choice(n, size=k, replace=k > n)
    return [dict(zip(posterior.keys, map(float, posterior.samples[i]), strict=True)) for i in rows]


def check(
    posterior: Posterior,
    observation: np.ndarray,
    scene: Scene,
    simulator: Simulator,
    renderer: Renderer,
    *,
    noise: float | None = None,
    draws: int = DRAWS,
    seed: int = 0,
    effects: Sequence[Effect] = (),
) -> PredictiveCheck | None:
    """Simulate ``draws`` posterior draws and compare the ``observation`` with them (see the
    module docstring). ``noise``: the observation model's pixel noise when stated (``None``:
    estimated from the frames). ``None`` when fewer than three draws simulate."""
    if isinstance(draws, bool) or not isinstance(draws, int) or draws < 2:
        raise PhysbenchError(f"predictive check draws = {draws!r}: expected a whole number >= 2")
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 29])
    obs = np.asarray(observation, dtype=np.float32).ravel()
    sigma, source = _noise(obs, noise)

    def frames(draw: dict[str, float]) -> np.ndarray | None:
        try:
            seen, traj = simulate_seen(simulator, scene, draw, effects)
        except SimulationError:
            return None
        return np.asarray(renderer.render(seen, traj), dtype=np.float32).ravel()

    picked = _draws(posterior, draws, rng)
    keep = draws * obs.size * 4 <= MEMORY
    sums = _Sums(obs.size, sigma)
    kept, good = [], []
    for draw in picked:  # first pass: the predictive mean and variance
        f = frames(draw)
        if f is None:
            continue
        sums.add(f)
        good.append(draw)
        if keep:
            kept.append(f)
    k = len(good)
    if k < 3:
        return None
    residual = sums.chi(obs)
    spread = np.empty(k)
    for i, draw in enumerate(good):  # second pass: each replicate against the others
        f = kept[i] if keep else frames(draw)
        if f is None:
            raise SimulationError(f"the predictive check's draw {draw} no longer simulates")
        spread[i] = sums.chi_without(f, rng)
    p = (1 + int(np.count_nonzero(spread >= residual))) / (k + 1)
    return PredictiveCheck(
        p=p,
        draws=draws,
        failed=draws - k,
        noise=sigma,
        noise_source=source,
        residual=residual,
        spread=float(np.median(spread)),
        seconds=time.perf_counter() - t0,
    )
