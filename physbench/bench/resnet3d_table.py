"""The tables of the learned estimator's evaluation sweep (``benchmarks/resnet3d.toml``).

1. The criteria, for ``resnet3d`` per Table 1 row: the paper's NN value, normalized min MSE after
   2 and after 11 iterations, their ratio, and the ratio of blurred to sharp after 11 iterations.
   Ratios are ratios of means over the same seeds (same scene instances and initial guesses), with
   a 90 % paired BCa bootstrap interval over seeds (:func:`~physbench.bench.tables.ratio_ci`), so a
   reader can tell a real miss from the spread of heavy-tailed errors. Two more blur columns: the
   ratio on seeds 0-9 only (the issue's 10 runs), and a diagnostic, the ratio of the *final*
   iterates' errors: the metric picks the best iterate by image MSE, which under blur compares
   blurred with sharp frames and can keep a worse iterate.
2. One shot: ``resnet3d`` after 2 iterations (one correction from the random initial guess)
   against the paper's NN after 11, sharp and blurred: the mean with its 90 % BCa interval over
   seeds (:func:`~physbench.bench.tables.bootstrap_ci`) and the distance, mean / paper value.
3. Every estimator: mean ± std after 2 and after 11 iterations, per scene, unknowns, bodies, blur.

``benchmarks/resnet3d_table.py`` prints :func:`table` of a sweep folder (results/resnet3d/table.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from physbench.bench.tables import bootstrap_ci, paper_value, ratio_ci
from physbench.errors import counted

if TYPE_CHECKING:
    import pandas as pd

KEYS = ["scene", "unknowns", "bodies"]
#: The issue's runs: seeds 0-9.
FIRST_TEN = 10


def after(g: pd.DataFrame, n: int, column: str = "best_nmse") -> pd.Series:
    """Best-so-far (or, with ``column="nmse"``, that iterate's) normalized MSE after ``n``
    iterations, indexed by seed."""
    return g[g.iteration == n - 1].set_index("seed")[column].sort_index()


def _fmt_ratio(r: tuple[float, float, float], limit: float = 2.0) -> str:
    mark = "yes" if r[0] <= limit else "no"
    return f"{r[0]:.2f} [{r[1]:.2f}, {r[2]:.2f}] | {mark}"


def criteria(ok: pd.DataFrame) -> list[str]:
    """Table 1 (Markdown lines) from the finished rows ``ok`` of the long table."""
    rows = [
        "| scene | unknowns | bodies | paper NN | after 2 | after 11 | ≤ paper | 2 / 11 [90 %] "
        "| ≤ 2 | blur 3, after 11 | blur / sharp [90 %] | ≤ 2 | blur / sharp, seeds 0-9 "
        "| blur / sharp, final iterate | seeds |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    nn = ok[ok.estimator_name == "resnet3d"]
    for (scene, unknowns, bodies), g in nn.groupby(KEYS, sort=True):
        sharp, blur = g[g.blur == 0], g[g.blur > 0]
        a2, a11, b11 = after(sharp, 2), after(sharp, 11), after(blur, 11)
        common = a11.index.intersection(b11.index)
        paper = paper_value(scene, unknowns, "NN") if bodies == "all" else None
        first = common[common < FIRST_TEN]
        paper_cell = f"{paper[0]:.1e}" if paper else "–"
        beats = ("yes" if a11.mean() <= paper[0] else "no") if paper else "–"
        final_ratio = (
            after(blur, 11, "nmse")[common].mean() / after(sharp, 11, "nmse")[common].mean()
        )
        rows.append(
            f"| {scene} | {unknowns} | {bodies} | {paper_cell} | {a2.mean():.2e} | "
            f"{a11.mean():.2e} | {beats} | "
            f"{_fmt_ratio(ratio_ci(a2.values, a11.values))} | {b11.mean():.2e} | "
            f"{_fmt_ratio(ratio_ci(b11[common].values, a11[common].values))} | "
            f"{b11[first].mean() / a11[first].mean():.2f} | "
            f"{final_ratio:.2f} | {len(a11)} |"
        )
    return rows


def one_shot(ok: pd.DataFrame) -> list[str]:
    """Table 2 (Markdown lines): ``resnet3d`` after 2 iterations against the paper's NN after 11,
    per Table 1 row (rows without a paper value are left out) and blur."""
    rows = [
        "| scene | unknowns | blur | paper NN, after 11 | after 2 [90 %] | after 2 / paper "
        "| ≤ paper | seeds |",
        "|---|---|---|---|---|---|---|---|",
    ]
    nn = ok[(ok.estimator_name == "resnet3d") & (ok.bodies == "all")]
    for (scene, unknowns, blur), g in nn.groupby(["scene", "unknowns", "blur"], sort=True):
        paper = paper_value(scene, unknowns, "NN")
        if not paper:
            continue
        a2 = after(g, 2)
        lo, hi = bootstrap_ci(a2.values, level=0.9)
        rows.append(
            f"| {scene} | {unknowns} | {blur:g} | {paper[0]:.1e} | {a2.mean():.2e} "
            f"[{lo:.1e}, {hi:.1e}] | {a2.mean() / paper[0]:.2f} | "
            f"{'yes' if a2.mean() <= paper[0] else 'no'} | {len(a2)} |"
        )
    return rows


def table(folder: str | Path) -> str:
    """Both tables (Markdown) of the sweep in ``folder`` (its ``results.parquet``), and a line per
    configuration whose cells failed."""
    import pandas as pd

    df = pd.read_parquet(Path(folder) / "results.parquet")
    ok = df[df.status == "ok"]
    rows = [
        "## resnet3d against the issue's criteria",
        "",
        *criteria(ok),
        "",
        "## One shot: resnet3d after 2 iterations against the paper's NN after 11",
        "",
        *one_shot(ok),
        "",
        "## Every estimator at equal iterations",
        "",
        "| scene | unknowns | bodies | blur | estimator | after 2 | after 11 | 2 / 11 | seeds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    keys = [*KEYS, "blur", "estimator_name"]
    for key, g in ok.groupby(keys, sort=True):
        a2, a11 = after(g, 2), after(g, 11)
        rows.append(
            f"| {key[0]} | {key[1]} | {key[2]} | {key[3]:g} | {key[4]} | "
            f"{a2.mean():.2e} ± {a2.std():.1e} | {a11.mean():.2e} ± {a11.std():.1e} | "
            f"{a2.mean() / a11.mean():.2f} | {len(a11)} |"
        )
    failed = df[df.status != "ok"].drop_duplicates("cell")
    if len(failed):
        rows.append("")
        for key, g in failed.groupby(keys):
            rows.append(
                f"failed: {' '.join(map(str, key))}: {counted(len(g), 'cell')} "
                f"({g.error.iloc[0][:120]})"
            )
    return "\n".join(rows)
