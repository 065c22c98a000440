"""Time to accuracy: how many simulations and how many wall-clock seconds each estimator needs
before its answer is first as good as a threshold (by default the paper's NN value for the row).

Iterations alone hide the cost of an iteration (``resnet3d``'s forward pass against TPE's
sampler), so both are counted. Per cell (a configuration and seed), the crossing is the first
iteration whose ``best_nmse`` (the normalized MSE of the best-by-image-MSE iterate so far, the
answer the loop would give if stopped there) is at or below the threshold. Its cost:

- simulations: the crossing iteration + 1 (the initial guess is the first simulation);
- seconds: the estimator's ``start()`` (``t_start``, 0 where not recorded), then every earlier
  iteration's simulate + render + propose, then the crossing iteration's simulate + render (its
  loss is known then; the next proposal is not needed for the answer). NaN when the sweep
  recorded no per-iteration timings.

A seed that never crosses within the sweep's iterations is censored: it counts as needing more
than the budget. The aggregate is the share of seeds that crossed and the censored median over
all seeds (the median with unreached seeds as +infinity), so it is finite only when more than half
the seeds crossed, and an estimator that rarely crosses cannot look fast by its few lucky seeds.
The wall-clock figures are as measured in the sweep's workers (shared cores, first-cell imports
in ``t_start``): compare estimators within one sweep, not across machines.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.bench.tables import CONFIG, SETTINGS, _ordered_groups, paper_value, upgrade
from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    import pandas as pd

#: The paper row whose value is the default threshold (Table 1, 11 iterations).
REFERENCE = "NN"
#: What the Time to accuracy table shows (summary.md and report.html).
NOTE = (
    "Cost until an estimator's answer (the normalized MSE of its best-by-image-MSE iterate so far) "
    "is first at or below the threshold (default: the paper's NN mean after 11 iterations for "
    "that row): simulations (the initial guess counts as 1) and wall-clock seconds (the "
    "estimator's start plus each iteration's simulate, render and propose up to the crossing "
    "simulation and its render, as timed in the sweep's workers). Reached: seeds that crossed "
    "within the sweep's iterations. Medians are over all seeds with unreached ones counted as "
    "never (censored): '> N' where no more than half the seeds crossed."
)


def _cost(rows: pd.DataFrame, threshold: float) -> tuple[float, float]:
    """(simulations, seconds) until ``rows`` (one cell's iterations) first reach ``threshold``;
    (+inf, +inf) when they never do."""
    rows = rows.sort_values("iteration")
    best = rows["best_nmse"].to_numpy(dtype=float)
    hit = np.flatnonzero(best <= threshold)
    if hit.size == 0:
        return math.inf, math.inf
    k = int(hit[0])
    sim = rows["t_simulate"].to_numpy(dtype=float)
    ren = rows["t_render"].to_numpy(dtype=float)
    est = rows["t_estimator"].to_numpy(dtype=float)
    start = float(rows["t_start"].iloc[0]) if "t_start" in rows.columns else math.nan
    seconds = (
        (0.0 if math.isnan(start) else start)
        + float(np.sum(sim[:k] + ren[:k] + est[:k]))
        + float(sim[k] + ren[k])
    )
    return float(int(rows["iteration"].iloc[k]) + 1), seconds


def threshold_for(scene: str, unknowns: str, threshold: float | None) -> tuple[float, str]:
    """The threshold of one row and where it comes from: ``threshold`` when given, else the
    paper's :data:`REFERENCE` mean; (NaN, why) for a row the paper lacks and no threshold."""
    if threshold is not None:
        return float(threshold), "given"
    ref = paper_value(scene, unknowns, REFERENCE)
    if ref is None:
        return math.nan, f"no paper {REFERENCE} value for this row; pass a threshold"
    return ref[0], f"paper {REFERENCE}"


def per_seed(df: pd.DataFrame, *, threshold: float | None = None) -> pd.DataFrame:
    """One row per finished cell of the long table ``df``: its :data:`CONFIG`, ``seed``,
    ``threshold`` and the ``simulations`` / ``seconds`` it took to reach it (+inf: never). Rows
    without a threshold (see :func:`threshold_for`) are left out; called by :func:`table` and the
    time-to-accuracy figure."""
    import pandas as pd

    if threshold is not None and not (math.isfinite(threshold) and threshold > 0):
        raise PhysbenchError(f"threshold {threshold!r}: expected a finite normalized MSE > 0")
    df = upgrade(df)
    ok = df[(df["status"] == "ok") & df["iteration"].notna()]
    out = []
    for _, rows in ok.groupby("cell", sort=False):
        first = rows.iloc[0]
        limit, _ = threshold_for(str(first["scene"]), str(first["unknowns"]), threshold)
        if math.isnan(limit):
            continue
        sims, secs = _cost(rows, limit)
        out.append(
            {
                **{c: first[c] for c in CONFIG},
                "cell_index": int(first["cell_index"]),
                "seed": int(first["seed"]),
                "threshold": limit,
                "simulations": sims,
                "seconds": secs,
            }
        )
    cols = [*CONFIG, "cell_index", "seed", "threshold", "simulations", "seconds"]
    return pd.DataFrame(out, columns=cols)


def _censored_median(values: np.ndarray) -> float:
    """Median with +inf for unreached seeds: +inf when the median seed did not reach."""
    return float(np.median(values)) if values.size else math.nan


def _matching(df: pd.DataFrame, cfg: dict[str, Any]) -> np.ndarray:
    return np.logical_and.reduce([(df[c] == v).to_numpy(dtype=bool) for c, v in cfg.items()])


def table(df: pd.DataFrame, *, threshold: float | None = None) -> pd.DataFrame:
    """Per configuration (:data:`CONFIG`) of the long table ``df``: ``threshold`` and its
    ``source``, ``seeds`` (finished cells), ``reached`` and ``share`` that crossed within the
    ``iterations``, and the censored ``median_simulations`` / ``median_seconds`` (+inf: no more than
    half crossed; NaN seconds: no timings recorded). A row without a threshold keeps its place
    with NaNs and the reason in ``source``. Written as ``time_to_accuracy.csv`` by
    :func:`physbench.bench.summary.write_summary`."""
    import pandas as pd

    df = upgrade(df)
    seeds = per_seed(df, threshold=threshold)
    ok = df[(df["status"] == "ok") & df["iteration"].notna()]
    rows: list[dict[str, Any]] = []
    for key in _ordered_groups(ok, CONFIG):
        cfg = dict(zip(CONFIG, key, strict=True))
        limit, source = threshold_for(str(cfg["scene"]), str(cfg["unknowns"]), threshold)
        g = seeds[_matching(seeds, cfg)] if len(seeds) else seeds
        n = int(ok.loc[_matching(ok, cfg), "cell"].nunique())
        sims = g["simulations"].to_numpy(dtype=float)
        secs = g["seconds"].to_numpy(dtype=float)
        reached = int(np.isfinite(sims).sum())
        skipped = math.isnan(limit)
        rows.append(
            {
                **cfg,
                "threshold": limit,
                "source": source,
                "seeds": n,
                "reached": math.nan if skipped else reached,
                "share": math.nan if skipped or not n else reached / n,
                "median_simulations": math.nan if skipped else _censored_median(sims),
                "median_seconds": math.nan if skipped else _censored_median(secs),
            }
        )
    return pd.DataFrame(rows)


def _seconds_text(s: float) -> str:
    return f"{1e3 * s:.3g} ms" if s < 1 else f"{s:.3g} s"


def formatted(tta: pd.DataFrame) -> pd.DataFrame:
    """:func:`table` for reading (summary.md, report.html): a row per configuration with the
    threshold, seeds reached and the censored medians ('> N' where the median seed did not
    reach it)."""
    import pandas as pd

    extra = [c for c in SETTINGS if c in tta.columns and tta[c].nunique(dropna=False) > 1]
    rows = []
    for r in tta.to_dict("records"):
        base = {
            "scene": r["scene"],
            "unknowns": r["unknowns"],
            **{c: r[c] for c in extra},
            "estimator": r["estimator"],
        }
        if math.isnan(r["threshold"]):
            skipped = dict.fromkeys(("threshold", "reached", "simulations", "seconds"), "-")
            rows.append({**base, **skipped, "note": r["source"]})
            continue
        beyond = f"> {r['iterations']}"
        sims, secs = r["median_simulations"], r["median_seconds"]
        rows.append(
            {
                **base,
                "threshold": f"{r['threshold']:.2e} ({r['source']})",
                "reached": f"{r['reached']}/{r['seeds']}",
                "simulations": f"{sims:g}" if math.isfinite(sims) else beyond,
                "seconds": (
                    _seconds_text(secs)
                    if math.isfinite(secs)
                    else ("-" if math.isnan(secs) else "median seed did not reach it")
                ),
                "note": "",
            }
        )
    out = pd.DataFrame(rows)
    if len(out) and not out["note"].astype(bool).any():
        out = out.drop(columns="note")
    return out
