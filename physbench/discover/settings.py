"""Every knob of a discovery, in one frozen value that each stage takes.

The defaults are the calibrated ones: the significance thresholds (``min_gain``,
``min_delta_bic``) were set on control recordings (no hidden effect, both engines), see
``docs/discover.md``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from physbench import numeric
from physbench.discover.data import DiscoverError

#: A continuation horizon: a share of each fitted part.
HORIZON = numeric.finite(0, 1, low_open=True)


@dataclass(frozen=True)
class Settings:
    """Every knob of a discovery (defaults are the calibrated ones)."""

    effects: Sequence[str] | None = None  # candidate effect names (None: every registered one)
    holdout: float = 0.3  # share of the data held out
    split: str = "auto"  # time | runs | auto
    lead: float = 0.25  # share of a held-out run that fits its initial state
    nuisance: Sequence[str] | str = "auto"
    estimator: str = "lsq"  # base fit: lsq, or a registered estimator followed by lsq
    estimator_iterations: int = 60
    estimator_options: dict[str, Any] | None = None
    seed: int = 0
    min_gain: float = 0.1
    min_delta_bic: float = 10.0
    #: Measurement floor (m; rad where only angles were measured): held-out errors count in
    #: quadrature with it, so a disagreement below what the sensor can tell is no evidence;
    #: None: the recordings' stated accuracy.
    floor: float | None = None
    max_causes: int = 3
    shortlist: int = 4
    max_nfev: int = 30
    base_max_nfev: int = 60
    #: Most simulations of one candidate fit per continuation horizon (the base fit gets twice).
    budget: int = 120
    #: Contact scenes: simulations of a candidate's quick screening fit, and how many candidates
    #: per round then get the full fit.
    quick_budget: int = 40
    screen: int = 3
    #: Finite-difference step in units of each parameter's scale: large enough to step over the
    #: saw-tooth that contact detection at discrete steps puts into the residuals.
    diff_step: float = 0.3
    #: Continuation horizons (shares of each fitted part, fitted in turn); None: (0.5, 1) for
    #: scenes with contacts, where late bounces make the fit multimodal, else (1,).
    horizons: Sequence[float] | None = None
    #: Candidates whose held-out error is within this factor of the chosen one's are reported as
    #: explaining the data about as well.
    ambiguity: float = 0.05
    #: What the setup fixes by a reference (names of
    #: :data:`~physbench.discover.candidates.REFERENCES`: ``scale`` a reference length in the
    #: plane, ``clock`` a known frame rate, ``axes`` a plumb line, ``origin``, ``lens``,
    #: ``plane``): the measurement causes they fix are not candidates.
    references: Sequence[str] = ()
    #: A cause beats another explanation when its held-out sum of squares is lower by this many
    #: standard deviations of the paired held-out noise (:mod:`physbench.discover.equivalence`);
    #: short of that the recording cannot tell them apart.
    beat_z: float = 2.0

    def __post_init__(self) -> None:
        """Refuse a setting outside its range (:mod:`physbench.numeric`): NaN and the
        infinities included, which would switch a threshold off."""
        checks: dict[str, numeric.Number] = {
            "holdout": numeric.HOLDOUT,
            "lead": numeric.SHARE,
            "estimator_iterations": numeric.COUNT,
            "seed": numeric.SEED,
            "min_gain": numeric.SHARE,
            "ambiguity": numeric.SHARE,
            "min_delta_bic": numeric.NON_NEGATIVE,
            "max_causes": numeric.COUNT,
            "shortlist": numeric.COUNT,
            "max_nfev": numeric.COUNT,
            "base_max_nfev": numeric.COUNT,
            "budget": numeric.COUNT,
            "quick_budget": numeric.COUNT,
            "screen": numeric.COUNT,
            "diff_step": numeric.POSITIVE,
            "beat_z": numeric.NON_NEGATIVE,
        }
        for name, number in checks.items():
            number.check(getattr(self, name), name, DiscoverError)
        if self.floor is not None:
            numeric.FLOOR.check(self.floor, "floor", DiscoverError)
        if self.horizons is not None:
            if isinstance(self.horizons, str) or not isinstance(self.horizons, Sequence):
                raise DiscoverError(
                    f"horizons = {self.horizons!r}: expected a list of shares in (0, 1]"
                )
            for h in self.horizons:
                HORIZON.check(h, "horizons", DiscoverError)
        from physbench.discover.candidates import REFERENCES

        if isinstance(self.references, str) or any(r not in REFERENCES for r in self.references):
            raise DiscoverError(
                f"references = {self.references!r}: expected a list of {', '.join(REFERENCES)}"
            )
