"""What a command tells its user besides its result, all on stderr so that stdout carries only
the result (text or ``--json``): progress, shown on a terminal only, and ``wrote PATH`` for every
file written; ``-q`` silences both."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any


def show_progress(args: argparse.Namespace) -> bool:
    """Whether a command shows progress: not with ``-q``, and never into a pipe or log file (a
    redraw there is a line of ``\\r`` fragments). Looked up when a command starts, so a replaced
    ``sys.stderr`` counts."""
    return not getattr(args, "quiet", False) and sys.stderr.isatty()


def progress_bar(args: argparse.Namespace, **kwargs: Any) -> Any:
    """A tqdm bar on stderr, disabled where :func:`show_progress` says so."""
    from tqdm import tqdm

    return tqdm(file=sys.stderr, disable=not show_progress(args), dynamic_ncols=True, **kwargs)


@contextmanager
def stages(args: argparse.Namespace, names: Sequence[str], desc: str) -> Iterator[Any]:
    """A bar over a command's named stages, for work without a finer count; call the yielded
    function with each stage's name as it begins."""
    bar = progress_bar(args, total=len(names), desc=desc, unit="stage", leave=False)
    begun: list[str] = []

    def begin(name: str) -> None:
        if begun:
            bar.update(1)
        begun.append(name)
        bar.set_postfix_str(name)

    try:
        yield begin
        if begun:
            bar.update(1)
    finally:
        bar.close()


def wrote(path: str | Path, args: argparse.Namespace) -> None:
    """Echo a file (or folder) a command wrote, unless ``args`` ask for ``-q``."""
    if not getattr(args, "quiet", False):
        print(f"wrote {path}", file=sys.stderr)
