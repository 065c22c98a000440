"""Profile-likelihood intervals for the parameters of the causes a discovery names.

The Jacobian's curvature is a poor guide to the sum of squares in rough scenes (impacts put a
saw-tooth into it, and nearly collinear parameters such as a restitution law's ``e0`` and ``k``
make a long, narrow valley whose width finite differences mismeasure). A profile walks the real
sum of squares instead: the parameter is moved away from its optimum and every other free
parameter refitted, until the sum of squares has grown by as much as the AR(1) sandwich interval
(:mod:`physbench.discover.intervals`) allows. For a linear model with that noise the two
intervals agree; otherwise each end sits where the data say, possibly asymmetric.

:func:`~physbench.discover.pipeline.conclude` calls :func:`profiled` once per chosen cause.
"""

from __future__ import annotations

import math
from dataclasses import replace

from physbench.discover.fit import budget, least_squares
from physbench.discover.results import CandidateResult, FitResult, Scored
from physbench.discover.settings import Settings
from physbench.errors import SimulationError

METHOD = "profile likelihood, AR(1) noise"
#: Refits per end of an interval: each moves the end to where a quadratic through the optimum and
#: the last point reaches the threshold.
STEPS = 2
#: The farthest one step moves an end, as a multiple of the last distance tried.
MAX_STRETCH = 8.0


def threshold(fit: FitResult, key: str) -> float | None:
    """The rise of the sum of squares that ends ``key``'s interval: where a linear model with the
    fit's noise level and correlation would reach the sandwich interval's end (None when the fit
    gives no usable standard error)."""
    se, hw = fit.stderr.get(key, math.nan), fit.half_widths.get(key, math.nan)
    if not (math.isfinite(se) and math.isfinite(hw)) or se <= 0 or hw <= 0 or fit.n <= fit.k:
        return None
    return hw**2 * (fit.ssr / (fit.n - fit.k)) / se**2


def profile_interval(scored: Scored, key: str, settings: Settings) -> tuple[float, float] | None:
    """The profile interval of ``key`` around the optimum of ``scored`` (None when the fit gives
    no threshold); the model itself is not changed."""
    fit = scored.fit
    rise = threshold(fit, key)
    if rise is None:
        return None
    p = scored.model.param(key)
    v0 = fit.values[key]
    others = [k for k in fit.free if k != key]
    ends = []
    for side, limit in ((-1.0, p.low), (1.0, p.high)):
        room = abs(limit - v0)
        d = min(fit.half_widths[key], room)
        for _ in range(STEPS):
            if d <= 0:
                break
            up = _rise(scored, key, v0 + side * d, others, settings) - fit.ssr
            stretch = math.sqrt(rise / up) if up > 0 else MAX_STRETCH
            d = min(d * min(stretch, MAX_STRETCH), room)
        ends.append(v0 + side * d)
    return ends[0], ends[1]


def _rise(scored: Scored, key: str, value: float, others: list[str], settings: Settings) -> float:
    """The sum of squares with ``key`` held at ``value`` and ``others`` refitted (infinite when
    it does not simulate)."""
    model = scored.model.copy()
    fit = scored.fit
    # Start the others where the linearised fit says they go with ``key``: along a narrow valley
    # a local refit from the optimum's values would not find its floor.
    shift = value - fit.values[key]
    start = {}
    for k in fit.free:
        r, se = fit.correlations.get(key, {}).get(k, 0.0), fit.stderr.get(k, math.nan)
        moved = fit.values[k] + shift * r * se / fit.stderr[key] if math.isfinite(se) else math.nan
        p = model.param(k)
        start[k] = min(max(moved, p.low), p.high) if math.isfinite(moved) else fit.values[k]
    model.values = {**model.values, **start, key: value}
    try:
        return least_squares(
            model,
            others,
            max_nfev=settings.max_nfev,
            budget=budget(settings, len(others)),
            diff_step=settings.diff_step,
            uncertainty=False,
        ).ssr
    except SimulationError:
        return math.inf


def profiled(c: CandidateResult, settings: Settings) -> CandidateResult:
    """``c`` with profile intervals for its parameters (those without a usable threshold keep
    their sandwich interval)."""
    if c.scored is None:
        return c
    key = c.effect
    intervals = dict(c.intervals)
    done = False
    for name in c.params:
        got = profile_interval(c.scored, f"{key}.{name}", settings)
        if got is not None:
            intervals[name], done = got, True
    return replace(c, intervals=intervals, interval_method=METHOD) if done else c
