"""``physbench plot DIR``: figures and an HTML report for a ``physbench bench`` output folder.

Writes into ``--out`` (default: DIR itself) ``plots/*.png`` (convergence per scene like the
paper's Fig. 3, parameter-space trajectories for two unknowns like Fig. 5, the image-MSE landscape
along each parameter like Fig. 4, the estimators' win-rate matrix, and the coverage of the
posteriors' intervals when some estimator returned one, the share of seeds that reached the
paper's value against simulations and seconds), ``win_rate.csv``, ``report.html``
(self-contained: tables and figures embedded) and the summaries ``physbench bench`` writes
(``stats.csv``, ``time_to_accuracy.csv``, ``summary.csv``/``.md``/``.tex``), rebuilt from
``results.parquet`` alone: after the tables gain a section, this refreshes a committed sweep
without rerunning it.
"""

from __future__ import annotations

import argparse

from physbench import numeric
from physbench.commands.arguments import add_quiet_argument

#: What ``plot`` rewrites besides figures and report (:mod:`physbench.bench.summary`).
SUMMARIES = (
    "stats.csv",
    "time_to_accuracy.csv",
    "summary.csv",
    "summary.md",
    "summary.tex",
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "dir", metavar="DIR", help="output folder of `physbench bench` (holds results.parquet)"
    )
    p.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="write plots/, the summaries, win_rate.csv and report.html here "
        "(default: the input DIR)",
    )
    p.add_argument(
        "--seeds",
        type=numeric.COUNT,
        default=3,
        metavar="N",
        help="seeds drawn in the trajectory plots (default: 3)",
    )
    p.add_argument(
        "--landscape-seeds",
        type=numeric.LANDSCAPE_SEEDS,
        default=3,
        metavar="N",
        help="scene instances averaged in the image-MSE landscape, which simulates "
        "(default: 3; 0 skips it)",
    )
    p.add_argument(
        "--threshold",
        type=numeric.POSITIVE,
        default=None,
        metavar="NMSE",
        help="the normalized MSE the time-to-accuracy table and figures count to, on every row "
        "(default: the paper's NN value after 11 iterations, per row; rows the paper lacks are "
        "left out)",
    )
    add_quiet_argument(p, "only the final line")


def main(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from physbench.bench import plots, report
    from physbench.bench.store import atomic_write
    from physbench.bench.summary import write_summary
    from physbench.bench.tables import final_rows, read_results, win_rate_table
    from physbench.commands.console import stages, wrote
    from physbench.errors import PhysbenchError, counted

    source = Path(args.dir)
    df = read_results(source)
    if df.empty:
        raise PhysbenchError(
            f"{str(source)!r}: the results table is empty; run `physbench bench SPEC --out "
            f"{source}` first"
        )
    out = Path(args.out) if args.out else source
    try:
        log = json.loads((source / "run.json").read_text())
        title = str(log.get("spec", source.name))
    except (OSError, ValueError):
        log, title = None, source.name
    with stages(args, [*plots.FIGURE_GROUPS, "report"], "plot") as stage:
        figures = plots.plot_all(
            df,
            out / "plots",
            seeds=args.seeds,
            landscape_seeds=args.landscape_seeds,
            stage=stage,
            threshold=args.threshold,
        )
        stage("report")
        rate, _ = win_rate_table(final_rows(df))
        atomic_write(out / "win_rate.csv", rate.to_csv(index_label="estimator").encode())
        write_summary(df, out, title=title, threshold=args.threshold)
        page = report.build(df, out, figures, title=title, run_log=log, threshold=args.threshold)
    count = sum(len(v) for v in figures.values())
    for path in (p for group in figures.values() for p in group):
        wrote(path, args)
    wrote(out / "win_rate.csv", args)
    for name in SUMMARIES:
        wrote(out / name, args)
    wrote(page, args)
    print(f"{counted(count, 'figure')} in {out / 'plots'}; report {page}")
    return 0
