"""``physbench compare NEW BASELINE``: flag configurations whose error got significantly worse.

Exit status: 0 when nothing got worse, 1 when something did, 2 on bad input.
"""

from __future__ import annotations

import argparse

from physbench import numeric
from physbench.commands.arguments import add_quiet_argument

# The same defaults as physbench.bench.compare (argument parsing imports nothing heavy).
ALPHA, MIN_RATIO = 0.05, 1.25

EPILOG = """\
NEW and BASELINE are `physbench bench` output folders (or their results.parquet). Cells are matched
on scene, unknowns, estimator and options, engines, renderer and its options, blur, noise,
resolution, render mode, iterations and seed (a table from before renderers were recorded counts as
the default renderer). Seeds fix truth, initial guess and estimator randomness, so differences are
real.

Test, per estimator x scene x unknown set (x other settings), on d = ln(new / baseline) of each
matched seed's normalized min MSE after N iterations: WORSE when a one-sided Wilcoxon signed-rank
test (zero differences dropped), Holm-corrected over all configurations compared, gives
p < --alpha (default 0.05) AND the geometric-mean ratio exp(mean d) >= --min-ratio (default 1.25);
also WORSE when more matched cells failed than in the baseline. BETTER is the mirror image. An
unchanged run gives d = 0 for every seed and is never flagged. With n seeds the smallest possible
p is 2^-n, which must beat alpha / (number of configurations): e.g. 10 seeds for 20
configurations."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = EPILOG
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument(
        "new", metavar="NEW", help="the sweep to check (output folder or results.parquet)"
    )
    p.add_argument(
        "baseline", metavar="BASELINE", help="the reference sweep, e.g. results/baseline"
    )
    p.add_argument(
        "--alpha",
        type=numeric.LEVEL,
        default=ALPHA,
        help=f"significance level of the one-sided test (default: {ALPHA})",
    )
    p.add_argument(
        "--min-ratio",
        type=numeric.RATIO,
        default=MIN_RATIO,
        metavar="R",
        help="smallest geometric-mean error ratio new/baseline that counts as worse "
        f"(default: {MIN_RATIO})",
    )
    p.add_argument(
        "--all", action="store_true", help="list every configuration, not only changed ones"
    )
    add_quiet_argument(p, "no table: only the summary line (and the regressions)")


def main(args: argparse.Namespace) -> int:
    from physbench.bench.compare import compare
    from physbench.bench.tables import SETTINGS, markdown, read_results
    from physbench.errors import counted

    res = compare(
        read_results(args.new),
        read_results(args.baseline),
        alpha=args.alpha,
        min_ratio=args.min_ratio,
    )
    t = res.table
    shown = t if args.all else t[t["verdict"].isin(["worse", "better"])]
    if len(shown) and not args.quiet:
        view = shown[
            [
                "scene",
                "unknowns",
                "estimator",
                "compared",
                "failed_new",
                "failed_base",
                "mean_base",
                "mean_new",
                "gm_ratio",
                "worse_seeds",
                "better_seeds",
                "p_worse",
                "p_worse_holm",
                "verdict",
            ]
        ].copy()
        extra = [c for c in SETTINGS if t[c].nunique() > 1]
        for c in reversed(extra):
            view.insert(3, c, shown[c])
        for c in ("mean_base", "mean_new"):
            view[c] = view[c].map(lambda v: f"{v:.3e}")
        view["gm_ratio"] = view["gm_ratio"].map(lambda v: f"{v:.3f}")
        for c in ("p_worse", "p_worse_holm"):
            view[c] = view[c].map(lambda v: f"{v:.3g}")
        print(markdown(view))
    counts = t["verdict"].value_counts().to_dict()
    summary = ", ".join(
        f"{counts[k]} {k}" for k in ("worse", "better", "ok", "identical") if k in counts
    )
    unmatched = (
        f"; unmatched cells: {res.only_new} new, {res.only_base} baseline"
        if res.only_new or res.only_base
        else ""
    )
    print(
        f"compared {counted(int(t['matched'].sum()), 'cell')} in "
        f"{counted(len(t), 'configuration')}: "
        f"{summary}{unmatched} (worse: one-sided Wilcoxon, Holm-corrected p < {args.alpha}, "
        f"and geometric-mean ratio >= {args.min_ratio})"
    )
    if len(res.worse):
        print(
            "REGRESSION: "
            + "; ".join(
                f"{r.estimator} on {r.scene} [{r.unknowns}]" for r in res.worse.itertuples()
            )
        )
        return 1
    return 0
