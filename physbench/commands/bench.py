"""``physbench bench SPEC --out DIR``: run a sweep spec (see :mod:`physbench.bench.spec`).

Writes into DIR: ``cells/<key>.json`` (one per finished cell; re-running skips them),
``results.parquet`` (one row per cell × iteration), ``stats.csv``, ``summary.{csv,md,tex}``
(Table 1 layout), ``spec.toml`` and ``run.json``. ``physbench plot DIR`` adds plots and a report.
"""

from __future__ import annotations

import argparse
import shlex
import sys

from physbench import numeric
from physbench.commands.arguments import (
    SIZE_CHECK_HELP,
    add_quiet_argument,
    add_renderer_choice,
)

EPILOG = """\
A spec is TOML: scenes (each with its unknown sets), estimators, seeds, iterations, and the axes
renderer, engine, observe_engine, blur, noise, resolution, render_mode (one value or a list each);
see benchmarks/README.md. A cell's run seed is its seed value: `physbench run --seed S` with the
same settings reproduces it. Failed cells are recorded with their error and do not stop the sweep.

Re-running the same command on the same DIR resumes: finished cells are skipped. Every cell records
what produced it (a hash of its scene as generated for its seed, the estimator's resolved options,
the physbench version); a resume refuses, before running anything, when that changed for any
finished cell (or a cell predates these records): --allow-stale keeps such cells, --fresh starts
over.

One run at a time writes a DIR: a second run on the same DIR refuses (naming the first one's pid),
or waits for it with --wait. With --executor processes (the default), a cell that kills its worker
process (os._exit, a segfault in an extension) is run once more alone, then recorded as failed, and
the sweep goes on; --executor serial runs cells in this process, so such a cell ends the command
(finished cells are saved). Worker processes end when this process does.

"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = EPILOG + SIZE_CHECK_HELP
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument(
        "spec",
        metavar="SPEC",
        nargs="?",
        default=None,
        help="sweep spec (TOML), e.g. benchmarks/smoke.toml in a checkout; or --example NAME",
    )
    p.add_argument(
        "--example",
        metavar="NAME",
        default=None,
        help="run a spec that ships with physbench instead of a SPEC file: smoke (the quick "
        "start's sweep, 240 cells, about 2 minutes on 2 cores)",
    )
    p.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="output folder (created; an existing one is resumed)",
    )
    p.add_argument(
        "--executor",
        default="processes",
        choices=("serial", "processes", "dask"),
        help="where cells run: this process, local worker processes (default; a cell that kills "
        "its process is recorded as failed), or a Dask cluster (trusted: it sends back pickles)",
    )
    p.add_argument(
        "--workers",
        type=numeric.WORKERS,
        default=None,
        metavar="N",
        help="worker processes (default: all cores)",
    )
    p.add_argument(
        "--address",
        default=None,
        metavar="tcp://HOST:PORT",
        help="Dask scheduler address (with --executor dask; default: start a LocalCluster of "
        "--workers processes); only a cluster you trust: results arrive as pickles, which can "
        "run code here",
    )
    add_renderer_choice(
        p,
        renderer_help="run every cell with this renderer instead of the spec's renderer axis "
        "(with the -R options only); -R alone updates the options of the spec's single renderer",
    )
    p.add_argument(
        "--fresh", action="store_true", help="discard the cells already in DIR and run everything"
    )
    p.add_argument(
        "--retry-failed", action="store_true", help="run the cells recorded as failed again"
    )
    p.add_argument(
        "--allow-stale",
        action="store_true",
        help="resume even when finished cells were produced by other code or settings (a changed "
        "scene generator, estimator default or physbench version); they are kept as they are",
    )
    p.add_argument(
        "--wait",
        action="store_true",
        help="when another run is writing DIR, wait for it to finish (default: refuse)",
    )
    add_quiet_argument(p, "no table: only the final line")


def _spec_path(args: argparse.Namespace) -> str:
    """The spec file: SPEC, or the shipped example --example names (exactly one of them)."""
    from physbench.errors import PhysbenchError

    if (args.spec is None) == (args.example is None):
        raise PhysbenchError(
            "give a sweep spec file (physbench bench SPEC --out DIR) or a shipped example "
            f"(physbench bench --example NAME --out DIR), {'not both' if args.spec else 'one'}"
        )
    if args.example is None:
        return str(args.spec)
    from physbench.examples import example_path

    return str(example_path(args.example))


def main(args: argparse.Namespace) -> int:
    from physbench.bench.runner import run_sweep
    from physbench.bench.spec import load_spec, with_renderer
    from physbench.commands.arguments import check_renderer_options, parse_key_values
    from physbench.commands.console import show_progress, wrote
    from physbench.errors import counted

    spec = load_spec(_spec_path(args))
    if args.renderer is not None or args.renderer_option:
        options = parse_key_values(args.renderer_option, "--renderer-option")
        if args.renderer is not None or len(spec.renderers) == 1:
            check_renderer_options(args.renderer or spec.renderers[0].name, options)
        spec = with_renderer(spec, args.renderer, options)
    command = ""
    if sys.argv[1:2] == ["bench"]:
        command = "physbench bench " + " ".join(shlex.quote(a) for a in sys.argv[2:])
    try:
        res = run_sweep(
            spec,
            args.out,
            executor=args.executor,
            workers=args.workers,
            address=args.address,
            fresh=args.fresh,
            retry_failed=args.retry_failed,
            allow_stale=args.allow_stale,
            wait=args.wait,
            progress=show_progress(args),
            command=command,
        )
    except KeyboardInterrupt:
        print(
            f"physbench bench: interrupted; finished cells are saved in {args.out}: re-run the "
            "same command to resume",
            file=sys.stderr,
        )
        return 130
    if not args.quiet:
        from physbench.bench.tables import markdown, paper_layout

        print(markdown(paper_layout(res.stats)))
    wrote(res.out, args)
    print(
        f"{spec.name}: {counted(res.cells, 'cell')} ({res.ran} run, {res.skipped} already done, "
        f"{res.failed} failed) in {res.wall_s:.1f} s with {res.executor}; "
        f"table {res.out / 'results.parquet'}"
    )
    return 0
