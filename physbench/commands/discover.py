"""``physbench discover``: fit a scene to a recording, show where it disagrees, find the missing
effect(s), and report the held-out gain."""

from __future__ import annotations

import argparse
from typing import Any

from physbench import numeric
from physbench.commands.arguments import (
    SIZE_CHECK_HELP,
    add_quiet_argument,
    add_renderer_arguments,
    add_scene_argument,
    add_video_input_arguments,
    positive_int,
    seed_int,
)

#: what :func:`physbench.discover.discover` reports to its ``stage`` callback, in order
STAGES = ("base fit", "candidate effects", "verdict")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = SIZE_CHECK_HELP
    _add_data_arguments(p)
    _add_output_arguments(p)
    _add_fit_arguments(p)
    _add_threshold_arguments(p)
    add_renderer_arguments(p, from_frames=True)
    p.add_argument(
        "--seed",
        type=seed_int,
        default=0,
        help="instance of a registered --scene and seed of a black-box base-fit estimator "
        "(default 0)",
    )
    add_quiet_argument(p, "print only the causes and the gain")
    video = p.add_argument_group("video", "when RECORDING is a video: how to read and track it")
    add_video_input_arguments(video)
    video.add_argument(
        "--track-out",
        default=None,
        metavar="REC.csv",
        help="also write the video's tracks as a recording CSV",
    )


def _add_data_arguments(p: argparse.ArgumentParser) -> None:
    """The data: a recording and its scene, or a shipped data set; the candidates."""
    p.add_argument(
        "recording",
        metavar="RECORDING",
        nargs="?",
        default=None,
        help="tracked trajectories (.csv: t,body,x,y[,angle][,run]), observed frames "
        "(.npz, key 'frames'), a Tracker project's hand-marked points (.trz, .trk), or a "
        "camera's video (.mp4, .mov, .avi, .mkv, .webm, .gif, or a folder of images): tracked "
        "first, as physbench track does (or --dataset instead)",
    )
    add_scene_argument(
        p,
        required=False,
        help="the setup, with the base model's unknowns (its --seed instance); required with "
        "RECORDING",
    )
    p.add_argument(
        "--dataset",
        metavar="NAME[/RUN]",
        default=None,
        help="instead of RECORDING and --scene: runs of a data set that ships with physbench, "
        "each with its own scene, e.g. ball_drops/whiffle_ball_1 (see `physbench datasets`)",
    )
    p.add_argument(
        "--effects",
        nargs="+",
        metavar="NAME",
        help="candidate effects (default: every registered effect that applies)",
    )
    p.add_argument("--run", help="use only this run of a multi-run CSV")


def _add_output_arguments(p: argparse.ArgumentParser) -> None:
    """Where the verdict goes: JSON on stdout or in a file, an HTML report."""
    p.add_argument(
        "--out", metavar="FILE.json", help="write the verdict as JSON here (the layout of --json)"
    )
    # Before --out existed, --json took the file ('-': stdout); that spelling still works.
    p.add_argument(
        "--json",
        nargs="?",
        const="-",
        default=None,
        metavar="FILE",
        help="print the verdict as JSON on stdout instead of the text (a file: --out FILE.json; "
        "--json FILE is the older spelling of --out FILE)",
    )
    p.add_argument("--report", metavar="DIR", help="write plots and index.html into this folder")


def _add_fit_arguments(p: argparse.ArgumentParser) -> None:
    """The base fit: engine, estimator and budget, the held-out split, the nuisances."""
    p.add_argument("--engine", default="pymunk", help="simulator (default pymunk)")
    p.add_argument(
        "--estimator",
        default="lsq",
        help="base fit: lsq (local least squares, default) or a registered estimator (tpe, "
        "cmaes, optuna, random) polished by lsq",
    )
    p.add_argument(
        "--iterations",
        type=positive_int,
        default=60,
        help="estimator iterations for the base fit (default 60)",
    )
    p.add_argument(
        "--holdout",
        type=numeric.HOLDOUT,
        default=0.3,
        help="share of the data held out (default 0.3)",
    )
    p.add_argument(
        "--split",
        default="auto",
        choices=("auto", "time", "runs"),
        help="hold out each run's later part (time) or whole runs (runs); auto: runs with >= 3 "
        "runs",
    )
    p.add_argument(
        "--nuisance",
        nargs="+",
        default=["auto"],
        metavar="NAME",
        help="initial-state parameters fitted per run: auto, none, or names like ball.vx0 "
        "force0.fx",
    )


def _add_threshold_arguments(p: argparse.ArgumentParser) -> None:
    """What a cause must reach to be named, and how many are added."""
    p.add_argument(
        "--min-gain",
        type=numeric.SHARE,
        default=None,
        help="held-out gain a cause must reach (default 0.1)",
    )
    p.add_argument(
        "--min-delta-bic",
        type=numeric.NON_NEGATIVE,
        default=None,
        help="BIC drop a cause must reach (default 10)",
    )
    p.add_argument(
        "--floor",
        type=numeric.FLOOR,
        default=None,
        metavar="METRES",
        help="the data's accuracy (radians where only angles were measured): held-out errors "
        "count in quadrature with it, so a smaller disagreement names no cause (default: what "
        "the recording states; a video's tracker states it from each track's noise)",
    )
    p.add_argument(
        "--max-causes", type=positive_int, default=None, help="most effects added (default 3)"
    )
    p.add_argument(
        "--reference",
        nargs="+",
        default=[],
        metavar="WHAT",
        help="what the setup fixes by a reference, so that it is not a candidate cause: scale "
        "(a reference length in the plane), clock (a known frame rate), axes (a plumb line or "
        "level), origin, lens, plane",
    )


def check_size(runs: list[Any], settings: Any, renderer: Any) -> None:
    """Refuse a discovery this machine cannot finish (:mod:`physbench.cost`). Its simulations, an
    order of magnitude: the base fit's estimator iterations, then per run the base fit's budget
    twice and a candidate fit's budget for each of the shortlisted candidates and the chosen."""
    from physbench import cost

    n = settings.estimator_iterations + settings.budget * (2 + settings.shortlist + 1)
    resolution = 0 if renderer is None else _width(renderer.resolution)
    mode = None if renderer is None else renderer.mode
    total = cost.Cost(0.0, 0.0)
    for run in runs:
        total = total + cost.of_scene(run.scene, resolution=resolution, mode=mode, held=3).times(n)
    biggest = max(runs, key=lambda r: r.scene.frames * r.scene.substeps * len(r.scene.bodies))
    cost.check(
        total,
        f"this discovery ({len(runs)} x {cost.simulations(n, biggest.scene, resolution)}, at most)",
        "--iterations, the recording's length or the scene's substeps or bodies",
    )


def _width(resolution: int | tuple[int, int]) -> int:
    return resolution if isinstance(resolution, int) else max(resolution)


def _runs(args: argparse.Namespace) -> list[Any]:
    """The runs to discover on: RECORDING with --scene, or a shipped data set's (--dataset)."""
    from physbench.commands.console import show_progress, wrote
    from physbench.discover import load_runs
    from physbench.errors import PhysbenchError
    from physbench.scenes import resolve_scene

    if args.dataset is not None:
        given = [
            f
            for f, v in (
                ("RECORDING", args.recording),
                ("--scene", args.scene),
                ("--run", args.run),
            )
            if v
        ]
        if given:
            raise PhysbenchError(
                f"--dataset {args.dataset!r} brings its recordings and scenes; leave out "
                f"{' and '.join(given)} (choose runs as --dataset NAME/RUN)"
            )
        from physbench.datasets import select
        from physbench.discover.data import runs_from_dataset

        return runs_from_dataset(select(args.dataset))
    if args.recording is None or args.scene is None:
        raise PhysbenchError(
            "give a RECORDING and its --scene (physbench discover REC.csv --scene S), or a data "
            "set that ships with physbench (physbench discover --dataset NAME/RUN; see "
            "`physbench datasets`)"
        )
    runs = load_runs(
        args.recording,
        resolve_scene(args.scene, args.seed),
        run=args.run,
        calibration=args.calibration,
        background=args.background,
        start=args.start,
        end=args.end,
        track_out=args.track_out,
        allow_gaps=args.allow_gaps,
        progress=show_progress(args),
        transfer=args.transfer,
        capture_fps=args.capture_fps,
    )
    if args.track_out:
        wrote(args.track_out, args)
    return runs


def main(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from physbench.commands.arguments import renderer_choice
    from physbench.commands.console import stages, wrote
    from physbench.components import create
    from physbench.discover import Settings, discover, renderer_for
    from physbench.discover.verdict import headline, text, to_dict
    from physbench.errors import PhysbenchError

    out, to_stdout = args.out, args.json == "-"
    if args.json not in (None, "-"):  # the older --json FILE
        if out is not None:
            raise PhysbenchError(
                f"--json {args.json!r} and --out {out!r}: give the file once, as --out"
            )
        out = args.json
    runs = _runs(args)
    nuisance = args.nuisance[0] if args.nuisance in (["auto"], ["none"]) else list(args.nuisance)
    kw = {
        k: v
        for k, v in (
            ("min_gain", args.min_gain),
            ("min_delta_bic", args.min_delta_bic),
            ("max_causes", args.max_causes),
            ("floor", args.floor),
        )
        if v is not None
    }
    settings = Settings(
        effects=args.effects,
        holdout=args.holdout,
        split=args.split,
        nuisance=nuisance,
        estimator=args.estimator,
        estimator_iterations=args.iterations,
        seed=args.seed,
        references=tuple(args.reference),
        **kw,
    )
    renderer = None
    if runs[0].frames is not None:  # the renderer flags apply to frames only
        name, options = renderer_choice(args)
        renderer = renderer_for(
            runs, name, options, resolution=args.resolution, mode=args.render_mode
        )
    check_size(runs, settings, renderer)
    with stages(args, STAGES, "discover") as stage:
        disc = discover(
            runs,
            create("simulator", args.engine),
            settings=settings,
            renderer=renderer,
            stage=stage,
        )
    if to_stdout:
        print(json.dumps(to_dict(disc), indent=2))
    elif args.quiet:
        print(
            f"{headline(disc)}; gain {disc.gain:.1%} (held-out error "
            f"{disc.base.heldout:.4g} -> {disc.final.heldout:.4g} {disc.unit})"
        )
    else:
        print(text(disc))
    if out:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        Path(out).write_text(json.dumps(to_dict(disc), indent=2) + "\n", encoding="utf-8")
        wrote(out, args)
    if args.report:
        from physbench.discover.report import write_report

        wrote(write_report(disc, args.report), args)
    return 0
