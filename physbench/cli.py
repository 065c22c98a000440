"""The ``physbench`` command. Subcommands live in :mod:`physbench.commands`, one module each,
imported only when chosen, so ``physbench --help`` stays fast."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import traceback
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

#: subcommand -> (module in physbench.commands, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "scenes": ("scenes", "list the registered scenes and their unknowns"),
    "plugins": ("plugins", "list every discovered component and any plugin that failed to load"),
    "simulate": (
        "simulate",
        "simulate a scene, save trajectory + frames (.npz), preview as GIF/PNG",
    ),
    "run": ("run", "identify parameters: the correction loop on a simulated or given observation"),
    "train": (
        "train",
        "train the resnet3d correction network (or --posterior: npe) for a scene and parameter set",
    ),
    "bench": ("bench", "run a benchmark sweep spec (TOML) into tables of normalized min MSE"),
    "plot": ("plot", "plots and an HTML report for a benchmark output folder"),
    "compare": (
        "compare",
        "flag estimator x scene cells that got significantly worse than a baseline",
    ),
    "discover": (
        "discover",
        "find the missing physical effect behind a recording's disagreement with the model",
    ),
    "track": ("track", "follow a scene's bodies through a video into a recording CSV (metres)"),
    "datasets": (
        "datasets",
        "the measured data sets that ship with physbench: list them, their runs, write them out",
    ),
}


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    from physbench.commands.arguments import refuse_empty_values

    parser = argparse.ArgumentParser(
        prog="physbench",
        description="Identify physical object properties from video or trajectories, and benchmark "
        "the methods.",
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an unexpected error"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, help_) in COMMANDS.items():
        p = sub.add_parser(name, help=help_, description=help_)
        if only is None or only == name:
            # Argument definitions are cheap; the heavy work sits in each module's main().
            importlib.import_module(f"physbench.commands.{module}").add_arguments(p)
            refuse_empty_values(p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; every way it can end is an exit status and at most one line on stderr
    (``--debug`` adds the traceback): 2 for errors physbench or a plugin reports, 70 for a bug,
    130 for Ctrl-C, 141 when the reader of stdout left."""
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    debug = "--debug" in argv
    try:
        return _run(argv, debug)
    except KeyboardInterrupt:
        if debug:
            raise
        print("physbench: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # the last guard: physbench's own bug, never a plugin's
        if debug:
            raise
        where = f"physbench {command}" if command in COMMANDS else "physbench"
        print(
            f"{where}: internal error: {type(exc).__name__}: {exc} (please report it "
            f"{how_to_report()}, with the command and the output of `physbench --version`; "
            "rerun with --debug for the traceback)",
            file=sys.stderr,
        )
        return 70  # EX_SOFTWARE


def _run(argv: list[str], debug: bool) -> int:
    chosen = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(chosen if chosen in COMMANDS else "")
    args = parser.parse_args(argv)
    if args.version:
        from importlib.metadata import version

        print(f"physbench {version('physbench')}")
        return 0
    if args.command is None:
        parser.print_help()
        return 0
    from physbench.errors import PhysbenchError

    module = importlib.import_module(f"physbench.commands.{COMMANDS[args.command][0]}")
    try:
        try:
            with warnings_as_lines(args.command):
                return int(module.main(args) or 0)
        except (Exception, SystemExit) as exc:
            _blame_plugin(exc)
            raise
    except PhysbenchError as exc:
        if debug:
            traceback.print_exc()
        print(f"physbench {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        if debug:
            traceback.print_exc()
        from physbench.cost import OVERRIDE, overridden

        why = (
            f"{OVERRIDE} turned off the size check that refuses such a job"
            if overridden()
            else "more than the size check estimated"
        )
        print(
            f"physbench {args.command}: error: out of memory: the job needed more memory than "
            f"this machine could give ({why}); make its sizes (frames, substeps, bodies, "
            "resolution, batch, seeds) smaller",
            file=sys.stderr,
        )
        return 2
    except BrokenPipeError:
        # The reader left (``| head``): stop quietly, as Unix tools do. Python would otherwise
        # report the failed flush of stdout again at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # 128 + SIGPIPE, what a shell reports for a tool killed by the signal


def warning_line(
    command: str, message: Warning | str, category: type[Warning], filename: str
) -> str:
    """``physbench COMMAND: warning: MESSAGE`` on one line, as the commands word their own
    warnings; a warning from outside physbench (numpy, a plugin) adds its category, e.g.
    ``(RuntimeWarning)``."""
    text = " ".join(str(message).split())
    own = Path(__file__).parent in Path(filename).resolve().parents
    return f"physbench {command}: warning: {text}" + ("" if own else f" ({category.__name__})")


@contextmanager
def warnings_as_lines(command: str) -> Iterator[None]:
    """While ``command`` runs, Python's warnings (``warnings.warn``) reach stderr as one
    :func:`warning_line` each, instead of Python's two lines with the source path and code.
    Which warnings are shown, and how often, stays the warnings filters' business (``-W``)."""
    import warnings

    shown = warnings.showwarning

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: object = None,
        line: str | None = None,
    ) -> None:
        text = warning_line(command, message, category, filename)
        if "tqdm" in sys.modules:  # above a progress bar, not through it
            sys.modules["tqdm"].tqdm.write(text, file=sys.stderr)
        else:
            print(text, file=sys.stderr)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = shown


def _blame_plugin(exc: BaseException) -> None:
    """Raise a :class:`~physbench.plugins.ComponentError` from ``exc`` when a third party's
    plugin raised it where no explicit guard stood (physbench's own errors pass)."""
    from physbench.errors import PhysbenchError

    if isinstance(exc, PhysbenchError | BrokenPipeError) or "physbench.plugins" not in sys.modules:
        return
    from physbench.plugins import ComponentError, blame

    culprit = blame(exc)
    if culprit is not None:
        raise ComponentError(*culprit, exc) from exc


def issue_tracker() -> str | None:
    """Where to report a bug: the ``Issues``/``Bug``/``Tracker`` URL of physbench's metadata
    (``[project.urls]``), or ``None`` when it names none."""
    from importlib.metadata import PackageNotFoundError, metadata

    try:
        urls = metadata("physbench").get_all("Project-URL") or []
    except PackageNotFoundError:
        urls = []
    for entry in urls:
        label, _, url = entry.partition(",")
        if any(w in label.lower() for w in ("issue", "bug", "tracker")) and url.strip():
            return url.strip()
    return None


def how_to_report() -> str:
    """``at <issue tracker URL>``, or, where physbench has none, the README section that says
    what to send and to whom; called for the line of an internal error."""
    url = issue_tracker()
    return f"at {url}" if url else 'as the README\'s "Reporting a problem" says'


if __name__ == "__main__":
    raise SystemExit(main())
