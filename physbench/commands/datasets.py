"""``physbench datasets``: the measured data sets that ship with physbench, their runs, and each
run written out as a recording CSV and a scene TOML (what ``discover`` reads); ``discover
--dataset NAME/RUN`` takes them directly."""

from __future__ import annotations

import argparse
from typing import Any

EPILOG = """\
DATASET is a data set's name (ball_drops, billiards, pendulum_kaheman, pendulum_benard) or
NAME/RUN for some of its runs: ball_drops/whiffle_ball_1 is both drops of that ball,
ball_drops/whiffle_ball_1/2 the second one. Discovery on them, without files:
  physbench discover --dataset ball_drops/whiffle_ball_1
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = EPILOG
    p.formatter_class = argparse.RawDescriptionHelpFormatter
    p.add_argument(
        "dataset",
        metavar="DATASET",
        nargs="?",
        default=None,
        help="list this data set's runs (NAME or NAME/RUN); default: list the data sets",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        default=None,
        help="write each run of DATASET as DIR/RUN.csv (recording) and DIR/RUN.toml (its scene)",
    )


def main(args: argparse.Namespace) -> int:
    from physbench.datasets import dataset_names, describe, load, select
    from physbench.errors import PhysbenchError, counted

    if args.dataset is None:
        if args.out:
            raise PhysbenchError(f"--out {args.out!r}: name the DATASET to write out")
        for name in dataset_names():
            runs = load(name)
            groups = list(dict.fromkeys(r.name.partition("/")[0] for r in runs))
            shown = ", ".join(groups[:6]) + (", ..." if len(groups) > 6 else "")
            print(f"{name}  ({counted(len(runs), 'run')}: {shown})")
            print(f"    {describe(name)}")
        print(
            "\nphysbench datasets NAME lists a data set's runs; physbench discover --dataset "
            "NAME/RUN runs discovery on them"
        )
        return 0
    runs = select(args.dataset)
    if args.out:
        _write(runs, args.out, args)
        return 0
    for run in runs:
        print(_run_line(run))
    return 0


def _run_line(run: Any) -> str:
    """``name: bodies (fields), samples over a duration; the effects the provenance names`` for
    one data-set run."""
    rec = run.recording
    measured = rec.fields or tuple(
        dict.fromkeys(f for tr in rec.tracks.values() for f in tr.fields)
    )
    fields = ", ".join(measured)
    expected = ", ".join(run.expected_effects) or "none"
    return (
        f"{run.name}: {', '.join(rec.bodies)} ({fields}), {rec.n_samples} samples over "
        f"{rec.t_end:.3g} s; effects its provenance names: {expected}"
    )


def _write(runs: list[Any], out: str, args: argparse.Namespace) -> None:
    """Each run as ``out/RUN.csv`` and ``out/RUN.toml`` (``/`` in a run's name becomes ``_``)."""
    from pathlib import Path

    from physbench.commands.console import wrote
    from physbench.recording import write_recordings
    from physbench.scene_toml import dumps_scene

    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    for run in runs:
        stem = run.name.replace("/", "_")
        write_recordings(folder / f"{stem}.csv", run.recording)
        (folder / f"{stem}.toml").write_text(dumps_scene(run.scene), encoding="utf-8")
        wrote(folder / f"{stem}.csv", args)
        wrote(folder / f"{stem}.toml", args)
    first = runs[0].name.replace("/", "_")
    print(
        f"{len(runs)} runs in {folder}; e.g. physbench discover {folder / first}.csv --scene "
        f"{folder / first}.toml"
    )
