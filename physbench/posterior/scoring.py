"""Scoring posteriors against truths: is an estimator as sure as it should be?

Per run and unknown (:func:`score`): whether the truth lies in the central 50/80/90/95 %
intervals, its SBC rank (the share of samples below it), the 90 % interval's width as a share of
the range, and the truth's negative log density. Over many runs (:func:`summarize`): the observed
coverage of each interval with a binomial interval, a test that the ranks are uniform, the mean
width and the mean negative log density. A calibrated posterior covers the truth at the nominal
rate and gives uniform ranks when the truth is drawn from the prior, which is what a sweep does
(each unknown uniform on its range). Called by the sweep's tables
(:mod:`physbench.bench.tables`) and plots.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    from physbench.posterior.samples import Posterior

#: The central intervals whose coverage is measured.
LEVELS = (0.5, 0.8, 0.9, 0.95)
#: The interval whose width is reported.
WIDTH_LEVEL = 0.9
#: The smallest kernel width of the density estimate, as a share of the range: a posterior whose
#: samples are (nearly) all equal still has a finite density everywhere.
MIN_BANDWIDTH = 1e-3
#: Confidence of the binomial interval around an observed coverage.
CONFIDENCE = 0.95


def level_name(level: float) -> str:
    """``0.9`` -> ``"in90"``: the field saying whether the truth is in the ``level`` interval."""
    return f"in{round(100 * level)}"


@dataclass(frozen=True)
class Score:
    """One unknown of one run: ``inside[i]`` for ``LEVELS[i]``; ``rank`` in [0, 1];
    ``width90`` the 90 % interval over the range; ``nld`` the truth's negative log density in
    unit-range units (0: as likely as under the uniform prior, negative: more)."""

    inside: tuple[bool, ...]
    rank: float
    width90: float
    nld: float

    def to_dict(self) -> dict[str, bool | float]:
        return {
            **{level_name(lv): b for lv, b in zip(LEVELS, self.inside, strict=True)},
            "rank": self.rank,
            "width90": self.width90,
            "nld": self.nld,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, bool | float]) -> Score:
        return cls(
            inside=tuple(bool(d[level_name(lv)]) for lv in LEVELS),
            rank=float(d["rank"]),
            width90=float(d["width90"]),
            nld=float(d["nld"]),
        )


def _neg_log_density(unit: np.ndarray, t: float) -> float:
    """``-log p(t)`` under a Gaussian KDE of ``unit`` (samples on the unit range), reflected at 0
    and 1 so that mass the kernels would put outside the range stays inside (a flat posterior
    then gives about 0, not ``log 2`` at the ends). The kernel width is
    :class:`scipy.stats.gaussian_kde`'s (Scott's rule), at least :data:`MIN_BANDWIDTH`; the sum
    is evaluated here because gaussian_kde refuses equal samples (a singular covariance) and
    whitens the whole sample on every call (slow for one point)."""
    from scipy.special import logsumexp
    from scipy.stats import norm

    n = unit.size
    h = max(float(unit.std(ddof=1)) * n**-0.2, MIN_BANDWIDTH)
    at = np.array([t, -t, 2.0 - t])
    logp = norm.logpdf(at[:, None], loc=unit[None, :], scale=h)
    return -float(logsumexp(logp) - math.log(n))


def score(posterior: Posterior, truth: Mapping[str, float]) -> dict[str, Score]:
    """Each unknown of ``posterior`` scored against ``truth`` (which must hold every key);
    called per finished cell when its table rows are made."""
    missing = [k for k in posterior.keys if k not in truth]
    if missing:
        raise PhysbenchError(
            f"truth lacks {', '.join(missing)}: a posterior over {list(posterior.keys)} needs a "
            "truth value for each of its unknowns"
        )
    intervals = {lv: posterior.interval(lv) for lv in LEVELS}
    out = {}
    for j, k in enumerate(posterior.keys):
        s, t = posterior.samples[:, j], float(truth[k])
        lo, hi = posterior.low[j], posterior.high[j]
        span = hi - lo
        w_lo, w_hi = posterior.interval(WIDTH_LEVEL)[k]
        # ties (samples clipped to a bound the truth sits on) count half: mid-rank
        rank = (np.count_nonzero(s < t) + 0.5 * np.count_nonzero(s == t)) / s.size
        out[k] = Score(
            inside=tuple(intervals[lv][k][0] <= t <= intervals[lv][k][1] for lv in LEVELS),
            rank=float(rank),
            width90=(w_hi - w_lo) / span if span > 0 else 0.0,
            nld=_neg_log_density((s - lo) / span, (t - lo) / span) if span > 0 else math.nan,
        )
    return out


@dataclass(frozen=True)
class Coverage:
    """How often the truth was inside the central ``level`` interval: ``inside`` of ``n``."""

    level: float
    inside: int
    n: int

    @property
    def observed(self) -> float:
        return self.inside / self.n if self.n else math.nan

    def ci(self, confidence: float = CONFIDENCE) -> tuple[float, float]:
        """Clopper-Pearson (exact binomial) interval of the coverage; NaNs for no runs."""
        if not self.n:
            return math.nan, math.nan
        from scipy.stats import binomtest

        ci = binomtest(self.inside, self.n).proportion_ci(confidence, method="exact")
        return float(ci.low), float(ci.high)


def coverage(scores: Iterable[Score]) -> list[Coverage]:
    """The coverage of each of :data:`LEVELS` over ``scores``."""
    inside = np.array([s.inside for s in scores], dtype=bool).reshape(-1, len(LEVELS))
    return [Coverage(lv, int(inside[:, i].sum()), inside.shape[0]) for i, lv in enumerate(LEVELS)]


def sbc_pvalue(ranks: Sequence[float]) -> float:
    """p-value of "the ranks are uniform on [0, 1]" (simulation-based calibration).

    A Kolmogorov-Smirnov test rather than a chi-square on a rank histogram: a sweep has tens of
    ranks per row, too few to fill histogram bins, and KS needs no choice of bins and is exact
    for small samples. Ranks are multiples of 1/samples, a negligible discreteness at the
    hundreds of samples a posterior carries. A too-narrow posterior piles ranks at 0 and 1, a
    biased one to one side, a too-wide one in the middle: all depart from uniform. NaN for no
    ranks."""
    r = np.asarray(ranks, dtype=float)
    if r.size == 0:
        return math.nan
    from scipy.stats import kstest

    return float(kstest(r, "uniform").pvalue)


def summarize(scores: Sequence[Score]) -> dict[str, float]:
    """The calibration of many runs: ``coverage50`` ... ``coverage95``, ``sbc_p``, mean
    ``width90`` and mean ``nld`` (NaN without scores), and ``scored``, their number. Scores of
    several unknowns of one run are pooled as if independent, which they need not be: the
    binomial intervals and the p-value are then somewhat optimistic."""
    cov = coverage(scores)
    return {
        **{f"coverage{round(100 * c.level)}": c.observed for c in cov},
        "sbc_p": sbc_pvalue([s.rank for s in scores]),
        "width90": float(np.mean([s.width90 for s in scores])) if scores else math.nan,
        "nld": float(np.mean([s.nld for s in scores])) if scores else math.nan,
        "scored": len(scores),
    }
