"""The ``physbench`` command. Subcommands live in :mod:`physbench.commands`, one module each,
imported only when chosen, so ``physbench --help`` stays fast."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence

#: subcommand -> (module in physbench.commands, one-line help)
COMMANDS: dict[str, tuple[str, str]] = {
    "scenes": ("scenes", "list the registered scenes and their unknowns"),
    "plugins": ("plugins", "list every discovered component and any plugin that failed to load"),
    "simulate": (
        "simulate",
        "simulate a scene, save trajectory + frames (.npz), preview as GIF/PNG",
    ),
    "run": ("run", "identify parameters: the correction loop on a simulated or given observation"),
    "train": ("train", "train the resnet3d correction network for a scene and parameter set"),
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
}


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="physbench",
        description="Identify physical object properties from video or trajectories, and benchmark "
        "the methods.",
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module, help_) in COMMANDS.items():
        p = sub.add_parser(name, help=help_, description=help_)
        if only is None or only == name:
            # Argument definitions are cheap; the heavy work sits in each module's main().
            importlib.import_module(f"physbench.commands.{module}").add_arguments(p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
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
        return int(module.main(args) or 0)
    except PhysbenchError as exc:
        print(f"physbench {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader left (``| head``): stop quietly, as Unix tools do. Python would otherwise
        # report the failed flush of stdout again at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # 128 + SIGPIPE, what a shell reports for a tool killed by the signal


if __name__ == "__main__":
    raise SystemExit(main())
