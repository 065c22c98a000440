"""A posterior over a run's unknowns: equally weighted samples in parameter units, their
summaries (median, central intervals) and whether the data determined each unknown.

An estimator that can say how sure it is returns a :class:`Posterior` from
:meth:`~physbench.estimators.base.CorrectionEstimator.posterior`; the loop stores it on the
:class:`~physbench.loop.History`. The prior is the uniform range of each unknown (what the
benchmark draws the truth from), so an unknown whose central 90 % interval is nearly as wide as
its range's is *not determined*: the data did not narrow it down.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from physbench.errors import PhysbenchError
from physbench.posterior.domain import TrainingDomain

#: The central intervals a run reports.
LEVELS = (0.5, 0.9)
#: An unknown is not determined when its 90 % interval is at least this share of the prior's
#: 90 % interval (a uniform prior's spans 90 % of the range). A likelihood that is flat in an
#: unknown leaves the ratio near 1 (sampling noise takes it to about 0.95 with 1,000 samples).
UNDETERMINED_RATIO = 0.75
#: At most this many samples go into a history's JSON (the summaries use all of them).
JSON_SAMPLES = 1000


@dataclass(frozen=True)
class Posterior:
    """``samples``: ``(n, d)`` draws in parameter units, column ``j`` for ``keys[j]``;
    ``low``/``high``: each unknown's prior range; ``method``: what made it (e.g. ``"smc"``);
    ``complete``: ``False`` when the method stopped short of its target (e.g. a sampler whose
    budget ran out), with the reason in ``note``; ``extra``: the method's own diagnostics, for
    people reading a run's JSON (smc: its noise level, final beta, stages, simulations to reach
    the posterior); physbench computes nothing from them. ``domain``: for a learned method, how
    far the observation lies from its training data (``None``: not measured)."""

    keys: tuple[str, ...]
    samples: np.ndarray
    low: tuple[float, ...]
    high: tuple[float, ...]
    method: str
    complete: bool = True
    note: str = ""
    extra: Mapping[str, float] = field(default_factory=dict)
    domain: TrainingDomain | None = None

    def __post_init__(self) -> None:
        s = np.asarray(self.samples, dtype=float)
        d = len(self.keys)
        if s.ndim != 2 or s.shape[1] != d or s.shape[0] < 2:
            raise PhysbenchError(
                f"posterior samples of shape {s.shape}: expected (n >= 2, {d}) for keys "
                f"{list(self.keys)}"
            )
        if not np.isfinite(s).all():
            raise PhysbenchError("posterior samples hold NaN or infinity")
        if len(self.low) != d or len(self.high) != d:
            raise PhysbenchError(f"posterior ranges: expected {d} lows and highs")
        object.__setattr__(self, "samples", s)

    @classmethod
    def from_unit(cls, space: Any, unit: np.ndarray, method: str, **kwargs: Any) -> Posterior:
        """From ``(n, d)`` unit-cube samples of a :class:`~physbench.unknowns.ParamSpace`."""
        unit = np.asarray(unit, dtype=float)
        lo, hi = space.low, space.high
        return cls(
            keys=tuple(space.keys),
            samples=lo + np.clip(unit, 0.0, 1.0) * (hi - lo),
            low=tuple(float(v) for v in lo),
            high=tuple(float(v) for v in hi),
            method=method,
            **kwargs,
        )

    def __len__(self) -> int:
        return int(self.samples.shape[0])

    def median(self) -> dict[str, float]:
        return {
            k: float(v) for k, v in zip(self.keys, np.median(self.samples, axis=0), strict=True)
        }

    def quantiles(self, qs: Sequence[float]) -> dict[str, list[float]]:
        """Each unknown's sample quantiles at ``qs`` (in [0, 1])."""
        q = np.quantile(self.samples, np.asarray(qs, dtype=float), axis=0)
        return {k: [float(v) for v in q[:, j]] for j, k in enumerate(self.keys)}

    def interval(self, level: float) -> dict[str, tuple[float, float]]:
        """The central ``level`` interval of each unknown (equal tails)."""
        if not 0 < level < 1:
            raise PhysbenchError(f"interval level {level!r}: expected a number in (0, 1)")
        q = self.quantiles(((1 - level) / 2, (1 + level) / 2))
        return {k: (v[0], v[1]) for k, v in q.items()}

    def width_ratio(self) -> dict[str, float]:
        """The 90 % interval's width over the uniform prior's (0: pinned, about 1: the prior)."""
        iv = self.interval(0.9)
        return {
            k: (iv[k][1] - iv[k][0]) / (0.9 * (hi - lo)) if hi > lo else 0.0
            for k, lo, hi in zip(self.keys, self.low, self.high, strict=True)
        }

    @property
    def outside(self) -> bool:
        """Whether the observation lies outside the method's training data (see ``domain``)."""
        return self.domain is not None and not self.domain.inside

    def undetermined(self) -> tuple[str, ...]:
        """Unknowns the data did not narrow down (see :data:`UNDETERMINED_RATIO`). Only a
        complete posterior from inside its method's training data says that: an incomplete
        one is too wide by construction, and one from outside its training data is wide (or
        narrow) for reasons of its own, not the data's."""
        if not self.complete or self.outside:
            return ()
        return tuple(k for k, r in self.width_ratio().items() if r >= UNDETERMINED_RATIO)

    def to_dict(self, max_samples: int = JSON_SAMPLES) -> dict[str, Any]:
        """JSON-ready: summaries from all samples, at most ``max_samples`` samples (evenly
        thinned)."""
        n = len(self)
        idx = np.linspace(0, n - 1, min(n, max_samples)).round().astype(int)
        qs = (0.05, 0.25, 0.5, 0.75, 0.95)
        return {
            "method": self.method,
            "complete": self.complete,
            "note": self.note,
            "keys": list(self.keys),
            "low": list(self.low),
            "high": list(self.high),
            "n": n,
            "quantile_levels": list(qs),
            "quantiles": self.quantiles(qs),
            "undetermined": list(self.undetermined()),
            "extra": dict(self.extra),
            "domain": None if self.domain is None else self.domain.to_dict(),
            "samples": self.samples[idx].tolist(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Posterior:
        return cls(
            keys=tuple(d["keys"]),
            samples=np.asarray(d["samples"], dtype=float),
            low=tuple(d["low"]),
            high=tuple(d["high"]),
            method=str(d["method"]),
            complete=bool(d.get("complete", True)),
            note=str(d.get("note", "")),
            extra=dict(d.get("extra", {})),
            domain=None if d.get("domain") is None else TrainingDomain.from_dict(d["domain"]),
        )

    def describe(self, truth: Mapping[str, float] | None = None) -> list[str]:
        """One line per unknown: median, 50 % and 90 % intervals, and what the data leave open.
        Called by ``physbench run`` after the table."""
        med, i50, i90 = self.median(), self.interval(0.5), self.interval(0.9)
        undetermined = self.undetermined()
        lines = []
        for k in self.keys:
            line = (
                f"{k}: median {med[k]:.4g}, 50 % [{i50[k][0]:.4g}, {i50[k][1]:.4g}], "
                f"90 % [{i90[k][0]:.4g}, {i90[k][1]:.4g}]"
            )
            if truth is not None and k in truth:
                inside = i90[k][0] <= truth[k] <= i90[k][1]
                line += f"; truth {truth[k]:.4g} ({'inside' if inside else 'outside'} the 90 %)"
            if k in undetermined:
                line += (
                    "; not determined: the interval is about as wide as the range, so the data "
                    "do not tell this unknown"
                )
            lines.append(line)
        if self.domain is not None and not self.domain.inside:
            lines.append(self.domain.describe(self.method))
        if not self.complete:
            lines.append(f"incomplete posterior ({self.method}): {self.note}")
        return lines
