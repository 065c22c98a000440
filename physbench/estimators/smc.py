"""``smc``: a posterior for any scene without training, by sequential Monte Carlo on the image
likelihood (:mod:`physbench.posterior.likelihood`).

A population of particles starts as draws from the prior (each unknown uniform on its range).
The likelihood is switched on gradually, ``L**beta`` with ``beta`` rising from 0 to 1 as fast as
the particles allow (each step keeps an effective sample size of half the population); after each
step the particles are resampled and moved by random-walk Metropolis with a proposal shaped like
their spread. Tempering from the prior, rather than climbing from one guess, keeps every mode the
data allow. Every likelihood evaluation is one simulation, so one loop iteration = one particle
move, and the iteration budget is the sampler's. When it runs out before ``beta`` reaches 1 the
posterior says so (``complete=False``).

The noise level is the observation model's when the run states it (a simulated observation,
``Task.noise``), else the ``noise`` option, else a rough estimate from the frames. Observation
blur that the model renderer does not apply makes the likelihood wrong: its intervals are then
not to be trusted.
"""

from __future__ import annotations

import math
from collections.abc import Generator
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator
from physbench.estimators.options import float_option, int_option
from physbench.hookspecs import hookimpl

if TYPE_CHECKING:
    from physbench.estimators.base import Step, Task
    from physbench.posterior.samples import Posterior
    from physbench.unknowns import Params, ParamSpace

#: Effective sample size kept per tempering step, as a share of the population.
ESS_SHARE = 0.5
#: Metropolis sweeps after each tempering step: enough for this chance that a particle never
#: moved, capped at MAX_MOVES.
STUCK = 0.05
MAX_MOVES = 8


def _ess(logw: np.ndarray) -> float:
    w = np.exp(logw - logw.max())
    return float(w.sum() ** 2 / np.square(w).sum())


def next_beta(loglik: np.ndarray, beta: float, share: float = ESS_SHARE) -> float:
    """The largest ``beta' <= 1`` whose incremental weights ``L**(beta' - beta)`` keep an effective
    sample size of ``share`` of the population (bisection)."""
    n = loglik.size
    if _ess((1.0 - beta) * loglik) >= share * n:
        return 1.0
    lo, hi = 0.0, 1.0 - beta
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _ess(mid * loglik) >= share * n:
            lo = mid
        else:
            hi = mid
    return beta + max(lo, 1e-12)


def systematic_resample(logw: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Indices of a systematic resample with weights ``exp(logw)``."""
    w = np.exp(logw - logw.max())
    c = np.cumsum(w / w.sum())
    c[-1] = 1.0
    n = logw.size
    return np.searchsorted(c, (rng.random() + np.arange(n)) / n)


class SMCEstimator(CorrectionEstimator):
    """Tempered sequential Monte Carlo on the image likelihood; see the module docstring.

    Options: ``particles`` (population size, default 64), ``noise`` (pixel noise sigma when the
    run does not state it; default: estimated from the frames).
    """

    name: ClassVar[str] = "smc"

    def __init__(self, particles: int = 64, noise: float | None = None) -> None:
        particles = int_option(self.name, "particles", particles, low=8)
        if noise is not None:
            noise = float_option(self.name, "noise", noise, low=0.0, high=1.0)
        self.options: dict[str, Any] = {"particles": particles, "noise": noise}
        self.space: ParamSpace | None = None
        self._gen: Generator[np.ndarray, float, None] | None = None
        self._first = True

    def start(self, task: Task, *, seed: int) -> None:
        """Called once per run: set up the likelihood and a fresh population."""
        from physbench.posterior.likelihood import PixelLikelihood, estimate_noise

        self.space = task.space
        if task.noise is not None and task.noise > 0:
            sigma, self.noise_source = float(task.noise), "stated by the observation model"
        elif self.options["noise"] is not None:
            sigma, self.noise_source = float(self.options["noise"]), "the noise option"
        else:
            sigma, self.noise_source = estimate_noise(task.observation), "estimated from the frames"
        self.sigma = sigma
        self.likelihood = PixelLikelihood(task.observation, sigma)
        self.rng = np.random.default_rng(seed)
        n, d = self.options["particles"], len(task.space)
        self.units = self.rng.random((n, d))
        self.loglik = np.full(n, -np.inf)
        self.beta = 0.0
        self.stages = 0
        self.moved_at_one = False
        self.evaluations = 0
        self.converged_at = 0
        # Particle sets after each sweep at beta = 1, once the first moves there are done: every
        # one is a sample of the posterior. Pooled, they give its quantiles from thousands of
        # (correlated) draws instead of 64; a central 90 % interval between order statistics of
        # 64 draws holds only about 87 % of the posterior.
        self.pool: list[np.ndarray] = []
        self._gen = self._run()
        self._first = True

    def propose(self, step: Step) -> Params:
        """Called after every simulation: score it, advance the sampler, return its next
        particle."""
        if self._gen is None or self.space is None:
            raise PhysbenchError(f"estimator {self.name!r}: propose() called before start()")
        if self._first:  # the loop's initial guess is not a particle
            self._first = False
            u = next(self._gen)
        else:
            ll = self.likelihood(step.frames) if step.trajectory is not None else -np.inf
            self.evaluations += 1
            u = self._gen.send(ll)
        return self.space.from_unit(u)

    def _run(self) -> Generator[np.ndarray, float, None]:
        n, d = self.units.shape
        for i in range(n):
            self.loglik[i] = yield self.units[i].copy()
        scale = 2.38**2 / d
        while True:
            beta = next_beta(self.loglik, self.beta) if self.beta < 1 else 1.0
            idx = systematic_resample((beta - self.beta) * self.loglik, self.rng)
            self.units, self.loglik = self.units[idx].copy(), self.loglik[idx].copy()
            self.beta = beta
            self.stages += 1
            cov = np.atleast_2d(np.cov(self.units.T)) + 1e-12 * np.eye(d)
            moves, sweep = MAX_MOVES, 0
            while sweep < moves:
                chol = np.linalg.cholesky(scale * cov)
                accepted = 0
                for i in range(n):
                    prop = self.units[i] + chol @ self.rng.standard_normal(d)
                    if np.any(prop < 0) or np.any(prop > 1):
                        continue  # zero prior density: rejected without a simulation
                    ll = yield prop
                    if math.log(self.rng.random()) < beta * (ll - self.loglik[i]):
                        self.units[i], self.loglik[i] = prop, ll
                        accepted += 1
                # A proposal outside the range is a rejection too. Counting only the simulated
                # ones, a flat likelihood accepts all of them, the proposal grows until nearly
                # every one falls outside, and sweeps that cost no simulation repeat the same
                # particles into the pool (1,247,552 samples from 6,000 simulations).
                rate = accepted / n
                # Keep the acceptance near 0.25: shrink or grow the proposal.
                scale *= math.exp(rate - 0.25)
                if sweep == 0:
                    moves = (
                        MAX_MOVES
                        if rate <= 0
                        else min(
                            MAX_MOVES,
                            max(1, math.ceil(math.log(STUCK) / math.log1p(-min(rate, 0.99)))),
                        )
                    )
                sweep += 1
                if self.moved_at_one and accepted:  # a sweep where nothing moved adds nothing
                    self.pool.append(self.units.copy())
            if self.beta >= 1 and not self.moved_at_one:
                self.moved_at_one = True
                self.converged_at = self.evaluations
                self.pool.append(self.units.copy())

    def posterior(self) -> Posterior | None:
        """Called once after the run: the particles of every sweep since the likelihood was fully
        on; or, marked incomplete with the reason, the current ones when the budget ran out
        before, or the first population's particles simulated so far, tempered as far as they
        allow, when it ran out before that population was complete."""
        from physbench.posterior.samples import Posterior

        if self.space is None or self.evaluations < 2:
            return None
        n = self.options["particles"]
        if self.evaluations < n:
            return self._first_population()
        complete = self.beta >= 1 and self.moved_at_one
        if complete:
            note = ""
        elif self.beta >= 1:
            note = (
                f"the budget ran out after {self.evaluations} simulations, during the moves that "
                "follow the last resampling: the samples repeat one another; give more iterations"
            )
        else:
            note = (
                f"the budget ran out at tempering beta = {self.beta:.3g} of 1 after "
                f"{self.evaluations} simulations: the intervals are too wide; give more "
                "iterations"
            )
        return Posterior.from_unit(
            self.space,
            np.concatenate(self.pool) if self.pool else self.units,
            self.name,
            complete=complete,
            note=note,
            extra=self._extra(self.beta),
        )

    def _first_population(self) -> Posterior:
        """The particles simulated before the budget ran out, resampled at the largest
        tempering ``beta`` they support: between the prior and the posterior, marked
        incomplete with the number of iterations the first population needs."""
        from physbench.posterior.samples import Posterior

        m, n = self.evaluations, self.options["particles"]
        loglik = self.loglik[:m]
        if np.isfinite(loglik).any():
            beta = next_beta(loglik, 0.0)
            idx = systematic_resample(beta * loglik, np.random.default_rng([m, 31]))
        else:  # every simulation failed: nothing to weight them by
            beta, idx = 0.0, np.arange(m)
        weighted = (
            "weighted by their likelihood"
            if beta >= 1
            else f"tempered only to beta = {beta:.3g} of 1, so the intervals are too wide"
        )
        note = (
            f"too few iterations for {n} particles: {m} of the first population were simulated "
            f"({weighted}), too few to trust the intervals. smc needs at "
            f"least {n + 1} iterations (the initial guess and one simulation per particle) to "
            "finish its first population, and thousands to reach the posterior (about 5,000 on "
            f"three_circles mass): give --iterations {n + 1} or more, or fewer particles than "
            "iterations (-o particles=N, N >= 8)"
        )
        return Posterior.from_unit(
            self.space,
            self.units[:m][idx],
            self.name,
            complete=False,
            note=note,
            extra=self._extra(beta),
        )

    def _extra(self, beta: float) -> dict[str, float]:
        return {
            "noise": self.sigma,
            "beta": beta,
            "stages": float(self.stages),
            "simulations_to_posterior": float(self.converged_at),
        }


@hookimpl
def register_estimators() -> list[type]:
    return [SMCEstimator]
