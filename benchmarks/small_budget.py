"""The small-budget study's table (issue 16, item 1) from a `physbench bench
benchmarks/small_budget.toml` run: per Table 1 row, each estimator's mean normalized min MSE after
11 iterations, and paired ratios of means (same seeds, so the same truths and initial guesses)
with 95 % BCa intervals; over all rows, the geometric mean of the per-row ratios with a bootstrap
that resamples seeds within each row.

    python benchmarks/small_budget.py [results/small_budget] [--add results/small_budget_gp]

Writes ``final.csv`` (each cell's final value: the compact record the test reads; the 23 MB
results.parquet is not committed) and ``small_budget.md`` into the folder. ``--add FOLDER`` adds
the final values of another sweep of the same rows (benchmarks/small_budget_gp.toml: ``gp`` on
the same seeds) to ``final.csv``, in place of that estimator's earlier values; ``final.csv``
already holding them is read as it is (the long table may be gone). An estimator that ran on
fewer seeds than the others is compared with them on its own seeds only, in a section of its
own.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from physbench.bench.tables import ratio_ci

#: (estimator, against): the comparisons the docs draw, on every seed.
PAIRS = [
    ("cmaes", "cmaes at the guess"),
    ("cmaes lhs 5", "cmaes at the guess"),
    ("tpe lhs 5", "tpe"),
    ("tpe lhs 7", "tpe"),
    ("tpe lhs 20", "tpe"),
    ("tpe", "random"),
    ("cmaes", "random"),
    ("cmaes at the guess", "random"),
    ("gp", "random"),
    ("gp", "tpe"),
    ("gp", "cmaes"),
]

#: The comparisons for an estimator that ran on a subset of the seeds (``gp``), on that subset.
SUBSET_AGAINST = ["random", "tpe", "cmaes"]


def final_values(folder: Path) -> pd.DataFrame:
    """One row per cell: row (scene/unknowns), estimator label, seed, best_nmse after the last
    iteration."""
    t = pd.read_parquet(folder / "results.parquet")
    last = t[(t.iteration == t.iterations - 1) & (t.status == "ok")]
    out = last.assign(row=last.scene + "/" + last.unknowns)
    return out[["row", "estimator", "seed", "best_nmse"]].sort_values(["row", "estimator", "seed"])


def geo_ratio(wide: dict[str, pd.DataFrame], a: str, b: str, n: int = 2000) -> tuple[float, ...]:
    """Geometric mean over rows of mean(a) / mean(b), and its 95 % percentile interval from
    resampling seeds within each row (``wide``: per row, seeds x estimators)."""
    rng = np.random.default_rng(0)
    point = np.exp(np.mean([np.log(w[a].mean() / w[b].mean()) for w in wide.values()]))
    logs = np.zeros(n)
    for w in wide.values():
        x, y = w[a].to_numpy(), w[b].to_numpy()
        idx = rng.integers(0, len(x), (n, len(x)))
        logs += np.log(x[idx].mean(axis=1) / y[idx].mean(axis=1))
    boots = np.exp(logs / len(wide))
    return float(point), *np.percentile(boots, [2.5, 97.5]).tolist()


def _ratio_lines(wide: dict[str, pd.DataFrame], pairs: list[tuple[str, str]]) -> list[str]:
    lines = [
        "| estimator / against | " + " | ".join(wide) + " | all rows |",
        "|---|" + "---|" * (len(wide) + 1),
    ]
    for a, b in pairs:
        cells = []
        for w in wide.values():
            p, lo, hi = ratio_ci(w[a].to_numpy(), w[b].to_numpy(), level=0.95)
            cells.append(f"{p:.2f} [{lo:.2f}, {hi:.2f}]")
        g, glo, ghi = geo_ratio(wide, a, b)
        lines.append(f"| {a} / {b} | " + " | ".join(cells) + f" | {g:.2f} [{glo:.2f}, {ghi:.2f}] |")
    return lines


def subset_report(final: pd.DataFrame, name: str) -> list[str]:
    """The section for ``name``, an estimator that ran on fewer seeds than the rest: every
    estimator's mean on those seeds, and paired ratios against :data:`SUBSET_AGAINST`."""
    own = final[final.estimator == name]
    wide = {}
    for r, g in final.groupby("row"):
        seeds = set(own[own.row == r].seed)
        wide[r] = g[g.seed.isin(seeds)].pivot(index="seed", columns="estimator", values="best_nmse")
    first = next(iter(wide.values()))
    names = [name] + [n for n in first.columns if n != name]
    lo, hi = int(first.index.min()), int(first.index.max())
    lines = [
        "",
        f"## {name}: {len(first)} seeds per row ({lo}..{hi})",
        "",
        f"Mean normalized min MSE after 11 iterations on the seeds {name} ran.",
        "",
        "| row | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for r, w in wide.items():
        lines.append(f"| {r} | " + " | ".join(f"{w[n].mean():.2e}" for n in names) + " |")
    lines += ["", f"Paired ratios of means on the same {len(first)} seeds, as above.", ""]
    return lines + _ratio_lines(wide, [(name, b) for b in SUBSET_AGAINST])


def report(final: pd.DataFrame) -> str:
    counts = final.groupby("estimator").size()
    partial = sorted(counts[counts < counts.max()].index)
    full = final[~final.estimator.isin(partial)]
    wide = {
        r: g.pivot(index="seed", columns="estimator", values="best_nmse")
        for r, g in full.groupby("row")
    }
    names = list(next(iter(wide.values())).columns)
    seeds = len(next(iter(wide.values())))
    lines = [
        f"# Small budgets: 11 iterations, {seeds} seeds per row",
        "",
        "Mean normalized min MSE after 11 iterations (best iterate by image MSE).",
        "",
        "| row | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for r, w in wide.items():
        lines.append(f"| {r} | " + " | ".join(f"{w[n].mean():.2e}" for n in names) + " |")
    lines += [
        "",
        "Paired ratios of means, estimator / against, with 95 % BCa intervals over seeds;",
        "last column: the geometric mean over the rows with a 95 % interval (seeds resampled",
        "within rows).",
        "",
        *_ratio_lines(wide, [(a, b) for a, b in PAIRS if {a, b} <= set(names)]),
    ]
    for name in partial:
        lines += subset_report(final, name)
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("folder", nargs="?", default="results/small_budget", type=Path)
    ap.add_argument("--add", type=Path, action="append", default=[], metavar="FOLDER")
    args = ap.parse_args()
    folder = args.folder
    if (folder / "results.parquet").is_file():
        final = final_values(folder)
    else:
        final = pd.read_csv(folder / "final.csv")
    for extra in args.add:
        more = final_values(extra)
        final = final[~final.estimator.isin(set(more.estimator))]
        final = pd.concat([final, more]).sort_values(["row", "estimator", "seed"])
    final.to_csv(folder / "final.csv", index=False, float_format="%.6g")
    final = pd.read_csv(folder / "final.csv")  # the report reads what the tests read
    text = report(final)
    (folder / "small_budget.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
