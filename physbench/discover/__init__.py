"""Discovery: fit a simulation to measurements, show where it still disagrees, find which missing
physical effect explains the disagreement, and report how much better the extended model predicts
data it was not fitted on.

Modules, one concept each: :mod:`~physbench.discover.data` (runs, loading, the held-out split),
:mod:`~physbench.discover.model` (base scene + effects + nuisance parameters -> residuals),
:mod:`~physbench.discover.fit` (least squares, estimators, uncertainty),
:mod:`~physbench.discover.residuals` (per body, per event), :mod:`~physbench.discover.diagnostics`
(statistics pointing at causes), :mod:`~physbench.discover.candidates` (which effects to try),
:mod:`~physbench.discover.select` (candidate fits, held-out comparison, criterion, greedy addition),
:mod:`~physbench.discover.verdict` (text and JSON) and :mod:`~physbench.discover.report` (plots and
HTML).
"""

from __future__ import annotations

from physbench.discover.data import DiscoverError, Run, load_runs, make_split, runs_from_cases
from physbench.discover.select import CandidateResult, Discovery, Settings, discover

__all__ = [
    "CandidateResult",
    "DiscoverError",
    "Discovery",
    "Run",
    "Settings",
    "discover",
    "load_runs",
    "make_split",
    "runs_from_cases",
]
