"""Regression check of a sweep against a baseline sweep.

Cells are matched on their full configuration and seed (:data:`~physbench.bench.tables.MATCH`);
a table written before the renderer columns existed counts as the default renderer without
options. Seeds fix the scene instance, the truth, the initial guess and the estimator's
randomness, so a matched pair differs only through code or library changes, and the test is
paired over seeds:

For every estimator × scene × unknown set (× any other setting), with ``d_i = ln(new_i /
base_i)`` the per-seed log ratio of normalized min MSE after N iterations, the configuration is
**worse** when

1. a one-sided Wilcoxon signed-rank test (zero differences dropped) rejects "no shift towards
   larger errors" at family-wise level ``alpha`` (default 0.05) after Holm's correction over all
   compared configurations, **and**
2. the geometric-mean ratio ``exp(mean d_i)`` over all matched seeds is at least ``min_ratio``
   (default 1.25, i.e. errors 25 % larger), so that tiny but consistent shifts are not flagged;

or when more of its matched cells failed than in the baseline. Log ratios because the errors are
heavy-tailed (across seeds the std is about the mean). Holm's correction because a library update
that reshuffles every seed's result would otherwise trip one of many configurations by chance;
a real regression moves (nearly) every seed the same way. An unchanged run gives ``d_i = 0``
exactly and is never flagged. With n seeds the smallest one-sided p is ``2**-n``, which must beat
``alpha / m`` for m configurations: the smoke sweep (m = 20) uses 10 seeds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.bench.tables import CONFIG, MATCH, final_rows, upgrade
from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    import pandas as pd

ALPHA = 0.05
MIN_RATIO = 1.25
FLOOR = 1e-12  # log of an exact zero error


@dataclass
class Comparison:
    table: pd.DataFrame  # one row per configuration: counts, ratios, p-value, verdict
    only_new: int  # cells without a partner in the baseline
    only_base: int

    @property
    def worse(self) -> pd.DataFrame:
        return self.table[self.table["verdict"] == "worse"]


def _p_greater(d: np.ndarray) -> float:
    """One-sided Wilcoxon signed-rank p-value for a shift of ``d`` above 0 (zeros dropped)."""
    nz = d[d != 0]
    if nz.size == 0:
        return 1.0
    from scipy.stats import wilcoxon

    return float(wilcoxon(nz, alternative="greater").pvalue)


def holm(p: Sequence[float]) -> np.ndarray:
    """Holm-Bonferroni adjusted p-values (family-wise error control, any dependence)."""
    v = np.asarray(p, dtype=float)
    order = np.argsort(v, kind="stable")
    m = v.size
    adj = np.empty(m)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * v[i]))
        adj[i] = running
    return adj


def compare(
    new: pd.DataFrame, base: pd.DataFrame, *, alpha: float = ALPHA, min_ratio: float = MIN_RATIO
) -> Comparison:
    """Match the final rows of two long tables and test every configuration (see module doc)."""
    import pandas as pd

    from physbench import numeric

    numeric.LEVEL.check(alpha, "alpha")
    numeric.RATIO.check(min_ratio, "min_ratio")
    cols = list(MATCH)
    # tables written before the renderer columns existed ran the default renderer
    a = final_rows(upgrade(new))[[*cols, "status", "best_nmse"]]
    b = final_rows(upgrade(base))[[*cols, "status", "best_nmse"]]
    m = a.merge(b, on=cols, how="outer", suffixes=("_new", "_base"), indicator=True)
    only_new, only_base = (
        int((m["_merge"] == "left_only").sum()),
        int((m["_merge"] == "right_only").sum()),
    )
    m = m[m["_merge"] == "both"]
    if m.empty:
        raise PhysbenchError(
            "no cell of the new sweep matches a baseline cell (same scene, unknowns, estimator, "
            "options, engines, renderer and its options, blur, noise, resolution, render mode, "
            "iterations and seed); compare sweeps of the same spec"
        )
    rows = []
    for key, g in m.groupby(list(CONFIG), sort=False, dropna=False):
        ok = g[(g["status_new"] == "ok") & (g["status_base"] == "ok")]
        d = np.log(np.maximum(ok["best_nmse_new"].to_numpy(float), FLOOR)) - np.log(
            np.maximum(ok["best_nmse_base"].to_numpy(float), FLOOR)
        )
        rows.append(
            {
                **dict(zip(CONFIG, key, strict=True)),
                "matched": len(g),
                "compared": int(d.size),
                "failed_new": int((g["status_new"] != "ok").sum()),
                "failed_base": int((g["status_base"] != "ok").sum()),
                "mean_new": float(ok["best_nmse_new"].mean()) if d.size else math.nan,
                "mean_base": float(ok["best_nmse_base"].mean()) if d.size else math.nan,
                "gm_ratio": float(np.exp(d.mean())) if d.size else math.nan,
                "worse_seeds": int((d > 0).sum()),
                "better_seeds": int((d < 0).sum()),
                "p_worse": _p_greater(d) if d.size else 1.0,
                "p_better": _p_greater(-d) if d.size else 1.0,
                "identical": bool(d.size) and not np.any(d),
            }
        )
    t = pd.DataFrame(rows)
    t["p_worse_holm"], t["p_better_holm"] = holm(t["p_worse"]), holm(t["p_better"])
    worse = (t["failed_new"] > t["failed_base"]) | (
        (t["p_worse_holm"] < alpha) & (t["gm_ratio"] >= min_ratio)
    )
    better = ~worse & (t["p_better_holm"] < alpha) & (t["gm_ratio"] <= 1 / min_ratio)
    t["verdict"] = np.where(
        worse, "worse", np.where(better, "better", np.where(t.pop("identical"), "identical", "ok"))
    )
    return Comparison(t, only_new, only_base)
