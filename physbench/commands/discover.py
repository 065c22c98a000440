"""``physbench discover``: fit a scene to a recording, show where it disagrees, find the missing
effect(s), and report the held-out gain."""

from __future__ import annotations

import argparse

from physbench.commands.arguments import add_renderer_arguments, add_video_input_arguments


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "recording",
        metavar="RECORDING",
        help="tracked trajectories (.csv: t,body,x,y[,angle][,run]), observed frames "
        "(.npz, key 'frames'), or a camera's video (.mp4, .mov, .avi, .mkv, .webm, .gif, or a "
        "folder of images): tracked first, as physbench track does",
    )
    p.add_argument(
        "--scene",
        required=True,
        metavar="SCENE.toml",
        help="the setup, with the base model's unknowns",
    )
    p.add_argument(
        "--effects",
        nargs="+",
        metavar="NAME",
        help="candidate effects (default: every registered effect that applies)",
    )
    p.add_argument("--json", metavar="OUT", help="write the verdict as JSON here ('-' for stdout)")
    p.add_argument("--report", metavar="DIR", help="write plots and index.html into this folder")
    p.add_argument("--engine", default="pymunk", help="simulator (default pymunk)")
    p.add_argument(
        "--estimator",
        default="lsq",
        help="base fit: lsq (local least squares, default) or a registered estimator (tpe, "
        "cmaes, optuna, random) polished by lsq",
    )
    p.add_argument(
        "--iterations",
        type=int,
        default=60,
        help="estimator iterations for the base fit (default 60)",
    )
    p.add_argument(
        "--holdout", type=float, default=0.3, help="share of the data held out (default 0.3)"
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
    p.add_argument("--run", help="use only this run of a multi-run CSV")
    p.add_argument(
        "--min-gain",
        type=float,
        default=None,
        help="held-out gain a cause must reach (default 0.1)",
    )
    p.add_argument(
        "--min-delta-bic", type=float, default=None, help="BIC drop a cause must reach (default 10)"
    )
    p.add_argument(
        "--floor",
        type=float,
        default=None,
        metavar="METRES",
        help="the data's accuracy: held-out errors count in quadrature with it, so a smaller "
        "disagreement names no cause (default: what the recording states; a video's tracker "
        "states half a pixel)",
    )
    p.add_argument("--max-causes", type=int, default=None, help="most effects added (default 3)")
    add_renderer_arguments(p, from_frames=True)
    p.add_argument(
        "--seed", type=int, default=0, help="seed of a black-box base-fit estimator (default 0)"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="print only the causes and the gain")
    video = p.add_argument_group("video", "when RECORDING is a video: how to read and track it")
    add_video_input_arguments(video)
    video.add_argument(
        "--track-out",
        default=None,
        metavar="REC.csv",
        help="also write the video's tracks as a recording CSV",
    )


def main(args: argparse.Namespace) -> int:
    import json
    import sys
    from pathlib import Path

    from physbench.commands.arguments import renderer_choice
    from physbench.discover import Settings, discover, load_runs, renderer_for
    from physbench.discover.verdict import text, to_dict
    from physbench.plugins import create

    runs = load_runs(
        args.recording,
        args.scene,
        run=args.run,
        calibration=args.calibration,
        background=args.background,
        start=args.start,
        end=args.end,
        track_out=args.track_out,
        progress=not args.quiet,
    )
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
        **kw,
    )
    renderer = None
    if runs[0].frames is not None:  # the renderer flags apply to frames only
        name, options = renderer_choice(args)
        renderer = renderer_for(
            runs, name, options, resolution=args.resolution, mode=args.render_mode
        )
    disc = discover(runs, create("simulator", args.engine), settings=settings, renderer=renderer)
    if args.quiet:
        causes = ", ".join(disc.causes) or "none"
        print(
            f"causes: {causes}; gain {disc.gain:.1%} (held-out error "
            f"{disc.base.heldout:.4g} -> {disc.final.heldout:.4g} {disc.unit})"
        )
    else:
        print(text(disc))
    if args.json:
        payload = json.dumps(to_dict(disc), indent=2)
        if args.json == "-":
            sys.stdout.write(payload + "\n")
        else:
            Path(args.json).parent.mkdir(parents=True, exist_ok=True)
            Path(args.json).write_text(payload + "\n", encoding="utf-8")
            print(f"wrote {args.json}", file=sys.stderr)
    if args.report:
        from physbench.discover.report import write_report

        page = write_report(disc, args.report)
        print(f"wrote {page}", file=sys.stderr)
    return 0
