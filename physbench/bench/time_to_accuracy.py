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


def _cost(
    best: np.ndarray,
    iteration: np.ndarray,
    sim: np.ndarray,
    ren: np.ndarray,
    est: np.ndarray,
    start: float,
    threshold: float,
) -> tuple[float, float]:
    """(simulations, seconds) until one cell's iterations (in order) first reach ``threshold``;
    (+inf, +inf) when they never do."""
    hit = np.flatnonzero(best <= threshold)
    if hit.size == 0:
        return math.inf, math.inf
    k = int(hit[0])
    seconds = (
        (0.0 if math.isnan(start) else start)
        + float(np.sum(sim[:k] + ren[:k] + est[:k]))
        + float(sim[k] + ren[k])
    )
    return float(int(iteration[k]) + 1), seconds


def threshold_for(scene: str, unknowns: str, threshold: float | None) -> tuple[float, str]:
    """The threshold of one row and where it comes from: ``threshold`` when given, else the
    paper's :data:`REFERENCE` mean; (NaN, why) for a row the paper lacks and no threshold."""
    if threshold is not None:
        return float(threshold), "given"
    ref = paper_value(scene, unknowns, REFERENCE)
    if ref is None:
        return math.nan, f"no paper {REFERENCE} value for this row; pass a threshold"
    return ref[0], f"paper {REFERENCE}"


def check_threshold(threshold: float, what: str = "threshold") -> float:
    """``threshold`` if it is a finite normalized MSE > 0, else :class:`PhysbenchError` naming it
    as ``what`` (``--threshold`` for the command line)."""
    from physbench import numeric

    if not numeric.POSITIVE.accepts(threshold):
        raise PhysbenchError(
            f"{what} {threshold!r}: expected a finite normalized MSE > 0, e.g. 1e-3"
        )
    return float(threshold)


def per_seed(df: pd.DataFrame, *, threshold: float | None = None) -> pd.DataFrame:
    """One row per finished cell of the long table ``df``: its :data:`CONFIG`, ``seed``,
    ``threshold`` and the ``simulations`` / ``seconds`` it took to reach it (+inf: never). Rows
    without a threshold (see :func:`threshold_for`) are left out; called by :func:`table` and the
    time-to-accuracy figure."""
    import pandas as pd

    if threshold is not None:
        check_threshold(threshold)
    df = upgrade(df)
    ok = df[(df["status"] == "ok") & df["iteration"].notna()]
    cols = [*CONFIG, "cell_index", "seed", "threshold", "simulations", "seconds"]
    # each cell's rows by iteration, the cells in order of first appearance (groupby's order)
    order = pd.factorize(ok["cell"])[0]
    by = np.lexsort((ok["iteration"].to_numpy(dtype=float), order))
    ok, cell = ok.iloc[by], order[by]
    starts = np.flatnonzero(np.r_[True, cell[1:] != cell[:-1]]) if len(ok) else np.array([], int)
    first = ok.iloc[starts]
    limits = {
        key: threshold_for(str(key[0]), str(key[1]), threshold)[0]
        for key in set(zip(first["scene"], first["unknowns"], strict=True))
    }
    limit = np.array(
        [limits[k] for k in zip(first["scene"], first["unknowns"], strict=True)], dtype=float
    )
    best, it = ok["best_nmse"].to_numpy(dtype=float), ok["iteration"].to_numpy(dtype=float)
    sim, ren, est = (ok[c].to_numpy(dtype=float) for c in ("t_simulate", "t_render", "t_estimator"))
    t_start = first["t_start"].to_numpy(dtype=float) if "t_start" in ok.columns else None
    sims, seconds = np.full(len(starts), math.inf), np.full(len(starts), math.inf)
    ends = np.r_[starts[1:], len(ok)] if len(starts) else starts
    for i, (lo, hi) in enumerate(zip(starts, ends, strict=True)):
        sims[i], seconds[i] = _cost(
            best[lo:hi],
            it[lo:hi],
            sim[lo:hi],
            ren[lo:hi],
            est[lo:hi],
            math.nan if t_start is None else t_start[i],
            limit[i],
        )
    keep = ~np.isnan(limit)
    # plain lists: the columns' types inferred as from rows of Python values
    data = {c: first[c].to_numpy(dtype=object)[keep].tolist() for c in CONFIG}
    data["cell_index"] = [int(x) for x in first["cell_index"].to_numpy()[keep]]
    data["seed"] = [int(x) for x in first["seed"].to_numpy()[keep]]
    for c, v in (("threshold", limit), ("simulations", sims), ("seconds", seconds)):
        data[c] = v[keep].tolist()
    if not keep.any():
        return pd.DataFrame([], columns=cols)
    return pd.DataFrame(data, columns=cols)


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
