"""Discovery: fit a simulation to measurements, show where it still disagrees, find which missing
physical effect explains the disagreement, and report how much better the extended model predicts
data it was not fitted on.

:func:`discover` runs every stage; the stages run one by one too (see ``docs/discover.md``)::

    base = fit_base(runs, "pymunk", settings)       # the base model, fitted and scored
    diagnosis = diagnose(base)                      # what it gets wrong (describe() in words)
    trial = try_effect(base, "linear_drag", settings)  # one candidate, fitted and judged

Modules, one concept each: :mod:`~physbench.discover.settings` (every knob),
:mod:`~physbench.discover.results` (what the stages return), :mod:`~physbench.discover.data`
(runs, loading, the held-out split), :mod:`~physbench.discover.model` (base scene + effects +
nuisance parameters -> residuals), :mod:`~physbench.discover.fit` (least squares, estimators,
uncertainty, budgets), :mod:`~physbench.discover.sensitivity` (what the data can see),
:mod:`~physbench.discover.residuals` (per body, per event), :mod:`~physbench.discover.diagnostics`
(statistics pointing at causes, as numbers), :mod:`~physbench.discover.phrasing` (those in
words), :mod:`~physbench.discover.candidates` (which effects to try),
:mod:`~physbench.discover.trial` (one candidate fitted on top of a model),
:mod:`~physbench.discover.significance` (when a candidate is a cause),
:mod:`~physbench.discover.select` (greedy addition, backward elimination),
:mod:`~physbench.discover.equivalence` (what the recording cannot tell apart, the setup's priors),
:mod:`~physbench.discover.pipeline` (the stages composed), :mod:`~physbench.discover.verdict`
(text and JSON) and :mod:`~physbench.discover.report` (plots and HTML).
"""

from __future__ import annotations

from physbench.discover.candidates import CandidateSpec
from physbench.discover.data import DiscoverError, Run, load_runs, make_split, runs_from_dataset
from physbench.discover.diagnostics import diagnose
from physbench.discover.equivalence import compare_explanations
from physbench.discover.phrasing import describe
from physbench.discover.pipeline import (
    candidate_specs,
    conclude,
    discover,
    fit_base,
    renderer_for,
)
from physbench.discover.results import (
    Ambiguity,
    CandidateResult,
    Diagnosis,
    Discovery,
    Finding,
    FitResult,
    Prior,
    Rival,
    Scored,
    Selection,
    Skipped,
)
from physbench.discover.select import prune_causes, select_causes
from physbench.discover.settings import Settings
from physbench.discover.trial import try_effect

__all__ = [
    "Ambiguity",
    "CandidateResult",
    "CandidateSpec",
    "Diagnosis",
    "DiscoverError",
    "Discovery",
    "Finding",
    "FitResult",
    "Prior",
    "Rival",
    "Run",
    "Scored",
    "Selection",
    "Settings",
    "Skipped",
    "candidate_specs",
    "compare_explanations",
    "conclude",
    "describe",
    "diagnose",
    "discover",
    "fit_base",
    "load_runs",
    "make_split",
    "prune_causes",
    "renderer_for",
    "runs_from_dataset",
    "select_causes",
    "try_effect",
]
