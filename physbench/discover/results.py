"""What the stages of a discovery return: values, built once and not changed afterwards.

:class:`FitResult` (one least-squares optimum), :class:`Scored` (a fitted model and its held-out
error), :class:`Finding` (one residual statistic, as numbers), :class:`Diagnosis` (a model's
findings and residual breakdown), :class:`CandidateResult` (one candidate effect fitted on top of
a model and judged against it), :class:`Skipped` (a candidate that could not be fitted),
:class:`Selection` (the causes chosen) and :class:`Discovery` (everything, for the verdict).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from physbench.discover.intervals import LEVEL

if TYPE_CHECKING:
    from physbench.discover.data import Run, Split
    from physbench.discover.model import Model
    from physbench.discover.residuals import Breakdown
    from physbench.discover.settings import Settings


@dataclass(frozen=True)
class FitResult:
    """The optimum of one fit. ``values``: every parameter of the model (fitted or not)."""

    values: dict[str, float]
    free: list[str]
    stderr: dict[str, float]
    ssr: float
    n: int
    nfev: int
    simulations: int
    status: str
    correlations: dict[str, dict[str, float]] = field(default_factory=dict)
    #: Effect parameters left at a nonzero end of their range, even after widening it
    #: (:func:`~physbench.discover.fit.least_squares`): their true values may lie beyond.
    at_bound: tuple[str, ...] = ()
    #: 90 % interval (low, high) of each fitted parameter, clipped to its range, made by
    #: ``interval_method`` (:mod:`physbench.discover.intervals`); ``stderr`` is the i.i.d.
    #: Jacobian standard error, a lower bound when residuals are correlated.
    intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    interval_method: str = ""
    #: Half width of each interval before clipping to the range (what a profile aims at).
    half_widths: dict[str, float] = field(default_factory=dict)

    @property
    def k(self) -> int:
        return len(self.free)

    @property
    def rms(self) -> float:
        return math.sqrt(self.ssr / self.n) if self.n else math.nan

    def bic(self, extra_k: int = 0) -> float:
        """Bayesian information criterion with unknown noise: ``n ln(SSR/n) + k ln n``."""
        n = max(self.n, 1)
        return n * math.log(max(self.ssr, 1e-300) / n) + (self.k + extra_k) * math.log(n)


@dataclass(frozen=True, eq=False)
class Scored:
    """A fitted model and how well it predicts the held-out data (``failure``: why it could not
    be scored, with ``heldout`` infinite)."""

    label: str
    causes: tuple[str, ...]
    model: Model
    fit: FitResult
    heldout: float
    heldout_n: int
    failure: str = ""

    @property
    def bic(self) -> float:
        return self.fit.bic()

    def summary(self, keys: Sequence[str] | None = None) -> dict[str, Any]:
        params = self.model.params
        shown = [p.key for p in params if p.kind != "nuisance"] if keys is None else list(keys)
        return {
            "effects": list(self.causes),
            "params": {k: self.model.values[k] for k in shown},
            "stderr": {k: self.fit.stderr.get(k) for k in shown},
            "intervals": {k: list(self.fit.intervals[k]) for k in shown if k in self.fit.intervals},
            "interval_level": LEVEL,
            "interval_method": self.fit.interval_method,
            "nuisance": {p.key: self.model.values[p.key] for p in params if p.kind == "nuisance"},
            "fit_error": self.fit.rms,
            "heldout_error": self.heldout,
            "criterion": self.bic,
            "n_fit": self.fit.n,
            "n_heldout": self.heldout_n,
            "k": self.fit.k,
            "simulations": self.fit.simulations,
        }


@dataclass(frozen=True)
class Finding:
    """One statistic of the disagreement between a fitted model and the data, as numbers
    (:mod:`physbench.discover.phrasing` puts it into words).

    ``kind``: ``free_flight``, ``impacts``, ``drift``, ``offset``, ``envelope``, ``period``,
    ``centre`` or ``start`` (a body the scene starts at rest moves in the first samples; it
    suggests no effect: the scene's start or the nuisance parameters are to change); ``run``
    and ``body`` where it was measured; ``event``: the samples it measures (``free``,
    ``impact``, ``jointed``, or ``""`` for all of them); ``statistic`` names the headline
    number, ``size`` is its value and ``stderr`` its standard error (nan where none is estimated);
    ``trend``: how the statistic scales, ``constant``, ``linear`` or ``quadratic`` (with the speed
    in free flight, with the amplitude of a swing), ``growing`` or ``shrinking`` (with the impact
    speed), ``""`` when not measured; ``values``: every number reported; ``suggests``: the effects
    it points at.
    """

    kind: str
    run: str
    body: str
    event: str
    statistic: str
    size: float
    stderr: float = math.nan
    trend: str = ""
    values: dict[str, float] = field(default_factory=dict)
    suggests: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """What a fitted model gets wrong: the findings and the residual breakdown per body, field and
    event."""

    findings: list[Finding]
    breakdown: Breakdown


@dataclass(frozen=True)
class Skipped:
    """A candidate effect that was not fitted, and why."""

    effect: str
    reason: str


@dataclass(frozen=True, eq=False)
class CandidateResult:
    """One candidate fit: the effect added to the model of ``round`` - 1 causes (``previous``),
    judged against that model."""

    round: int
    effect: str  # the effect's key (label or name)
    name: str  # registered name
    params: dict[str, float]
    stderr: dict[str, float]
    fixed: dict[str, float]
    heldout_error: float
    gain: float  # against the model it extends
    gain_vs_base: float
    criterion: float
    delta_criterion: float
    significant: bool
    chosen: bool = False
    note: str = ""
    scored: Scored | None = None
    quick: bool = False
    previous: Scored | None = None  # the model this candidate extends
    #: Its parameters (bare names) left at an end of their range: the magnitude is a lower bound
    #: at best, and the verdict says so wherever it names the candidate.
    at_bound: tuple[str, ...] = ()
    #: 90 % interval (low, high) of each parameter and the method that made it
    #: (:attr:`FitResult.intervals`); ``stderr`` is the i.i.d. Jacobian lower bound.
    intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    interval_method: str = ""
    #: A measurement effect's largest change, at its fitted values, of a recorded position (m)
    #: and of a recorded angle (rad) over the data (:func:`~physbench.discover.significance.judge`
    #: does not name one the data's own accuracy could make); ``None`` for an effect on the
    #: motion, or data of frames.
    shift: tuple[float, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "effect": self.effect,
            "name": self.name,
            "round": self.round,
            "params": self.params,
            "stderr": self.stderr,
            "intervals": {k: list(v) for k, v in self.intervals.items()},
            "interval_level": LEVEL,
            "interval_method": self.interval_method,
            "fixed": self.fixed,
            "heldout_error": _num(self.heldout_error),
            "gain": _num(self.gain),
            "gain_vs_base": _num(self.gain_vs_base),
            "criterion": _num(self.criterion),
            "delta_criterion": _num(self.delta_criterion),
            "significant": self.significant,
            "chosen": self.chosen,
            "note": self.note,
            "quick_fit_only": self.quick,
            "at_bound": list(self.at_bound),
            "shift": None if self.shift is None else [_num(v) for v in self.shift],
        }


def _num(v: float) -> float | None:
    return float(v) if v is not None and math.isfinite(v) else None


@dataclass(frozen=True)
class Rival:
    """Another explanation of what a cause explains: the effects ``effects`` (keys; registered
    ``names``) added instead of it to the model it extends, fitted and scored on the held-out
    data. ``z``: how much better the cause predicts the held-out data, in standard deviations of
    the noise of that difference (> 0: the cause is better; nan: not comparable); ``same``: the
    two predict the same held-out data (they differ by less than a quarter of the noise), as
    explanations that are one and the same by construction do; ``measurement``: every one of its
    effects is a measurement cause."""

    effects: tuple[str, ...]
    names: tuple[str, ...]
    measurement: bool
    heldout_error: float
    z: float
    same: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {
            "effects": list(self.effects),
            "names": list(self.names),
            "kind": "measurement" if self.measurement else "physical",
            "heldout_error": _num(self.heldout_error),
            "z": _num(self.z),
            "same_predictions": self.same,
        }


@dataclass(frozen=True)
class Ambiguity:
    """A cause and the rival explanations this recording cannot tell apart from it
    (:mod:`physbench.discover.equivalence`): each explains the data as the cause does, and the
    cause does not beat it by ``Settings.beat_z`` standard deviations of the held-out noise.
    ``degeneracies``: why some are one and the same by construction (codes that
    :mod:`physbench.discover.phrasing` puts into words: ``"g"``, ``"tilt"``, ``"angle"``)."""

    cause: str
    name: str
    measurement: bool
    heldout_error: float
    rivals: tuple[Rival, ...]
    degeneracies: tuple[str, ...] = ()

    @property
    def members(self) -> list[tuple[str, ...]]:
        """Every explanation, the cause first, each as its registered effect names."""
        return [(self.name,), *(r.names for r in self.rivals)]

    @property
    def physical_alone(self) -> bool:
        """Whether the cause is physical and no rival is a measurement error: the physical
        explanation stands, though the recording does not pin which one."""
        return not self.measurement and not any(r.measurement for r in self.rivals)


@dataclass(frozen=True)
class Prior:
    """What the setup says about a cause, as numbers (:mod:`physbench.discover.phrasing` puts it
    into words). ``kind``: ``still_air`` (a uniform pull on a free body in a side view: no
    horizontal force acts in still air, and g is known), ``level_table`` (a uniform pull seen from
    above: the table's tilt it takes); ``values``: the numbers (m/s², rad, relative errors)."""

    kind: str
    effect: str
    body: str
    values: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Selection:
    """The outcome of the greedy selection: the (possibly refitted) base model, the final model,
    every candidate fit in the order tried, the causes in the order added, the candidates about as
    good as each cause, and the candidates not tried with the reason."""

    base: Scored
    final: Scored
    candidates: list[CandidateResult]
    causes: list[str]
    alternatives: dict[str, list[str]]
    skipped: list[tuple[str, str]]
    #: The causes the data cannot tell apart from other explanations, with those explanations
    #: (:func:`~physbench.discover.equivalence.compare_explanations`); a cause not listed is
    #: named alone.
    ambiguities: list[Ambiguity] = field(default_factory=list)
    priors: list[Prior] = field(default_factory=list)

    @property
    def gain(self) -> float:
        """``1 - heldout(final) / heldout(base)``."""
        return 1.0 - self.final.heldout / self.base.heldout if self.base.heldout > 0 else 0.0


@dataclass(frozen=True, eq=False)
class Discovery:
    """Everything a discovery found; :mod:`physbench.discover.verdict` turns it into text and
    JSON."""

    runs: Sequence[Run]
    split: Split
    settings: Settings
    engine: str
    unit: str
    base: Scored
    final: Scored
    candidates: list[CandidateResult]
    causes: list[str]
    gain: float
    skipped: list[tuple[str, str]]
    alternatives: dict[str, list[str]] = field(default_factory=dict)
    findings: dict[str, list[Finding]] = field(default_factory=dict)
    breakdowns: dict[str, Breakdown] = field(default_factory=dict)
    seconds: float = 0.0
    #: See :attr:`Selection.ambiguities` and :attr:`Selection.priors`.
    ambiguities: list[Ambiguity] = field(default_factory=list)
    priors: list[Prior] = field(default_factory=list)

    @property
    def cause_results(self) -> list[CandidateResult]:
        return [c for c in self.candidates if c.chosen]

    def ambiguity(self, cause: str) -> Ambiguity | None:
        """The rivals of ``cause`` (a key of :attr:`causes`), or None when it is named alone."""
        return next((a for a in self.ambiguities if a.cause == cause), None)
