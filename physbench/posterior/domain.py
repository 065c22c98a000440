"""Is the observation like the data a learned posterior was trained on?

An amortized posterior (``npe``) is a network's answer; on an input unlike its training data
(blurred frames, another engine's physics, a camera's footage) it still answers, just as
confidently, and wrongly: with a 3 px blur the posterior collapses onto the ends of the ranges,
which looks like "the data do not determine" when the data do. The estimator measures how far its
input lies from its training set and records it here, on the
:class:`~physbench.posterior.samples.Posterior` it returns.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any


@dataclass(frozen=True)
class TrainingDomain:
    """``distance``: how far the input lies from the training data, by ``statistic`` (a
    sentence saying what it measures); ``threshold``: the largest distance still counted as
    inside (set from the training or validation data, e.g. twice the largest distance seen
    there)."""

    distance: float
    threshold: float
    statistic: str

    @property
    def inside(self) -> bool:
        return self.distance <= self.threshold

    def describe(self, method: str) -> str:
        """The sentence ``physbench run`` prints when the input lies outside."""
        return (
            f"outside {method}'s training data (blur? another engine?): use smc. The "
            f"observation lies at {self.distance:.3g} by {self.statistic}, beyond the "
            f"{self.threshold:.3g} the training data allow"
        )

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "inside": self.inside}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TrainingDomain:
        return cls(float(d["distance"]), float(d["threshold"]), str(d["statistic"]))
