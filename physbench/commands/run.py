"""``physbench run``: the correction loop on a simulated (or given) observation.

By default the observation is simulated: for ``--seed`` the scene instance, random true
parameters and a random initial guess all derive from that seed. ``--observation FILE`` uses
given frames instead (format: :mod:`physbench.observation`): a file from ``physbench simulate``
(or ``--save-observation``) brings its scene instance, its truth and the engine that made it, so
the normalized error is reported; a file of frames only has no truth, so only image MSE is.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from physbench.commands.arguments import (
    SIZE_CHECK_HELP,
    add_json_argument,
    add_params_argument,
    add_quiet_argument,
    add_renderer_arguments,
    add_scene_argument,
    add_video_input_arguments,
    bounded_float,
    positive_int,
    seed_int,
)
from physbench.limits import MAX_NOISE, MAX_RESOLUTION


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = SIZE_CHECK_HELP
    _add_estimator_arguments(p)
    _add_problem_arguments(p)
    _add_simulation_arguments(p)
    _add_observation_arguments(p)
    _add_output_arguments(p)


def _add_estimator_arguments(p: argparse.ArgumentParser) -> None:
    """The estimator and its options."""
    p.add_argument(
        "--estimator",
        default="tpe",
        metavar="NAME",
        help="correction estimator (default: tpe; see `physbench plugins`)",
    )
    p.add_argument(
        "-o",
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="estimator option, repeatable, e.g. -o startup=5 or -o sampler=cmaes (values parse as "
        "JSON, else text)",
    )


def _add_problem_arguments(p: argparse.ArgumentParser) -> None:
    """The scene, its unknowns, the iteration budget and the seed."""
    add_scene_argument(
        p,
        required=False,
        help="with an --observation file that carries its scene, that scene instance, which "
        "--scene must name",
    )
    add_params_argument(
        p,
        help="or a scene-level key: gravity, camera.scale, camera.clock, an --effect's parameter "
        "(linear_drag.c); KEY=LOW:HIGH gives any of them a range (gravity=-11:-9)",
    )
    p.add_argument(
        "--effect",
        action="append",
        default=[],
        metavar="NAME[:KEY=VALUE,...]",
        help="simulate the model (and a simulated observation) with this effect, e.g. linear_drag "
        "or linear_drag:c=0.3 (repeatable; see `physbench plugins`); --params may name its "
        "parameters (linear_drag.c)",
    )
    p.add_argument(
        "--bodies",
        nargs="+",
        default=None,
        metavar="BODY",
        help="only these bodies' unknowns: a, or a b, a+b, a,b (default: all)",
    )
    p.add_argument(
        "--iterations",
        type=positive_int,
        default=11,
        metavar="N",
        help="simulations = propose calls (default: 11, as in the paper)",
    )
    p.add_argument(
        "--seed",
        type=seed_int,
        default=0,
        help="scene instance, truth, initial guess and estimator seed (default: 0); with an "
        "--observation file that carries its scene, only the initial guess and estimator seed",
    )


def _add_simulation_arguments(p: argparse.ArgumentParser) -> None:
    """The engines, the renderer and what degrades the simulated observation."""
    p.add_argument(
        "--engine",
        default=None,
        metavar="NAME",
        help="simulator of the model (default: pymunk, or the engine that made the --observation "
        "file)",
    )
    p.add_argument(
        "--observe-engine",
        default=None,
        metavar="NAME",
        help="simulator that makes the observation (default: --engine); another engine gives a "
        "sim-to-sim reality gap",
    )
    add_renderer_arguments(p)
    p.add_argument(
        "--blur",
        type=bounded_float(0.0, MAX_RESOLUTION),
        default=0.0,
        metavar="SIGMA",
        help="Gaussian blur (pixels) of the observation only; the model stays sharp (at most "
        "--resolution)",
    )
    p.add_argument(
        "--noise",
        type=bounded_float(0.0, MAX_NOISE),
        default=0.0,
        metavar="SIGMA",
        help=f"Gaussian pixel noise (standard deviation, at most {MAX_NOISE:g}) of the "
        "observation only",
    )


def _add_observation_arguments(p: argparse.ArgumentParser) -> None:
    """A given observation: an observation file, a camera's video or a filmed simulation."""
    p.add_argument(
        "--observation",
        default=None,
        metavar="FILE",
        help="observed frames (.npz with key 'frames', (T, C, H, W) in [0, 1]), e.g. from "
        "`physbench simulate --out`, whose scene, truth and engine the run takes",
    )
    video = p.add_argument_group(
        "video",
        "observe a camera's video (tracked, then segmented into per-body masks in the scene's "
        "frame), or film the simulated observation with a camera renderer",
    )
    video.add_argument(
        "--video", default=None, metavar="FILE", help="a video file or a folder of images"
    )
    add_video_input_arguments(video)
    video.add_argument(
        "--observer",
        default=None,
        metavar="NAME",
        help="film the simulated observation with this camera renderer (e.g. camera), then track "
        "and segment it: the visual gap",
    )
    video.add_argument(
        "--observer-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an option of --observer, repeatable (e.g. tilt=15, bitrate=2000000, resolution=640)",
    )


def _add_output_arguments(p: argparse.ArgumentParser) -> None:
    """What is written: the observation, the history, a plot, and how much is printed."""
    p.add_argument(
        "--save-observation",
        default=None,
        metavar="FILE",
        help="write the observation used to FILE (.npz)",
    )
    p.add_argument(
        "--out",
        default=None,
        metavar="FILE.json",
        help="write the history as JSON here (the layout of --json)",
    )
    add_json_argument(p, "the history")
    p.add_argument(
        "--plot",
        default=None,
        metavar="FILE",
        help="convergence plot (best-so-far errors per iteration), e.g. out.png; with an "
        "estimator that returns a posterior (smc) also its marginals, e.g. out.posterior.png",
    )
    add_quiet_argument(p, "only the final line (or the JSON)")


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.3e}"


def print_table(history: Any, out: Any = None) -> None:
    """The per-iteration table: parameters, image MSE, normalized MSE, best-so-far, timings (ms)."""
    out = sys.stdout if out is None else out  # looked up now: sys.stdout may be replaced
    keys = list(history.keys)
    has_truth = history.truth is not None
    head = (
        ["iter", *keys, "image MSE"] + (["norm MSE"] if has_truth else []) + ["best", "best image"]
    )
    head += (["best norm"] if has_truth else []) + ["sim ms", "render ms", "est ms"]
    rows = []
    for r in history.iterations:
        row = [str(r.iteration), *(f"{r.params[k]:.4g}" for k in keys), _fmt(r.loss)]
        row += [_fmt(r.nmse)] if has_truth else []
        row += [str(r.best_iteration), _fmt(r.best_loss)] + (
            [_fmt(r.best_nmse)] if has_truth else []
        )
        row += [
            f"{1e3 * r.t_simulate:.2f}",
            f"{1e3 * r.t_render:.2f}",
            f"{1e3 * r.t_estimator:.2f}",
        ]
        if r.failed:
            row[-1] += f"  (simulation failed: {r.failed})"
        rows.append(row)
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(head)]
    print("  ".join(h.rjust(w) for h, w in zip(head, widths, strict=True)), file=out)
    for row in rows:
        print(
            "  ".join(c.rjust(w) for c, w in zip(row, widths, strict=False))
            + "".join(row[len(widths) :]),
            file=out,
        )


def describe_observation(history: Any) -> str:
    """One line on an observation file: its scene, what made it and what models it."""
    meta = history.meta
    if history.truth is None:
        return (
            f"observation {meta['observation']}: frames only (no scene or truth in the file); "
            f"modelled as scene {meta['scene']} by {meta['simulator']}"
        )
    maker = f"made by {meta['observe_engine'] or 'an engine the file does not name'}"
    if meta.get("observe_effects"):
        maker += f" with {', '.join(meta['observe_effects'])}"
    return (
        f"observation {meta['observation']}: scene {meta['scene']}, {maker}; modelled by "
        f"{meta['simulator']}"
    )


def main(args: argparse.Namespace) -> int:
    _check_arguments(args)
    config = _build_config(args)
    history = _run_with_progress(args, config)
    _save_outputs(args, history)
    _warn_about_result(history)
    if args.json:
        print(history.to_json(indent=1))
        return 0
    if not args.quiet:
        _print_details(args, history)
    _print_posterior(history)
    _print_final_line(args, history)
    return 0


def _check_arguments(args: argparse.Namespace) -> None:
    """Refuse an iteration count below 1 and a blur wider than the frame."""
    from physbench.errors import PhysbenchError

    if args.iterations < 1:
        raise PhysbenchError(f"--iterations {args.iterations}: expected a whole number >= 1")
    if args.blur > args.resolution:
        raise PhysbenchError(
            f"--blur {args.blur:g}: expected at most the frame width --resolution "
            f"{args.resolution} pixels (a wider blur leaves flat frames)"
        )


def _build_config(args: argparse.Namespace) -> Any:
    """The checked :class:`~physbench.experiment.RunConfig` the flags describe."""
    from physbench.commands.arguments import parse_key_values, renderer_choice, split_bodies
    from physbench.components import default_render_mode
    from physbench.experiment import RunConfig, check_config
    from physbench.unknowns import split_params

    params = split_params(args.params)
    bodies = None if args.bodies is None else split_bodies(args.bodies)
    renderer, renderer_options = renderer_choice(args)
    config = RunConfig(
        scene=args.scene,
        params=params,
        estimator=args.estimator,
        options=parse_key_values(args.option, "--option"),
        seed=args.seed,
        iterations=args.iterations,
        engine=args.engine,
        observe_engine=args.observe_engine,
        renderer=renderer,
        renderer_options=renderer_options,
        blur=args.blur,
        noise=args.noise,
        resolution=args.resolution,
        render_mode=args.render_mode or default_render_mode(renderer),
        bodies=bodies,
        observation=args.observation,
        observer=args.observer,
        observer_options=parse_key_values(args.observer_option, "--observer-option"),
        video=args.video,
        calibration=args.calibration,
        background=args.background,
        video_start=args.start,
        video_end=args.end,
        effects=tuple(args.effect),
        allow_gaps=args.allow_gaps,
        transfer=args.transfer,
        capture_fps=args.capture_fps,
    )
    check_config(config)  # a bad name or option: fail before the progress bar appears
    return config


def _run_with_progress(args: argparse.Namespace, config: Any) -> Any:
    """Run ``config`` behind a progress bar showing the best errors so far; the history."""
    from physbench.commands.console import progress_bar
    from physbench.experiment import DEFAULT_SCENE, run_config

    bar = progress_bar(
        args,
        total=args.iterations,
        desc=f"{args.estimator} on {args.scene or args.observation or DEFAULT_SCENE}",
        unit="it",
        leave=False,
    )

    def progress(rec: Any) -> None:
        post = {"best image": f"{rec.best_loss:.2e}"}
        if rec.best_nmse is not None:
            post["best norm"] = f"{rec.best_nmse:.2e}"
        bar.set_postfix(post, refresh=False)
        bar.update(1)

    try:
        return run_config(
            config,
            callback=progress,
            save_observation=args.save_observation,
            notice=lambda text: bar.write(f"physbench run: warning: {text}", file=sys.stderr),
        )
    finally:
        bar.close()


def _save_outputs(args: argparse.Namespace, history: Any) -> None:
    """Report the saved observation; write the plots and the history JSON asked for."""
    from pathlib import Path

    from physbench.commands.console import wrote

    if args.save_observation:
        # numpy adds .npz to a name without it
        saved = str(args.save_observation)
        wrote(saved if saved.endswith(".npz") else saved + ".npz", args)
    if args.plot:
        from physbench.plotting.convergence import plot_convergence, run_title

        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        plot_convergence({f"{history.estimator}": [history]}, args.plot, title=run_title(history))
        wrote(args.plot, args)
        if history.posterior is not None:
            from physbench.plotting.posterior import plot_posterior, posterior_path

            drawn = plot_posterior(history.posterior, posterior_path(args.plot), history.truth)
            wrote(str(drawn), args)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(history.to_json(indent=1) + "\n", encoding="utf-8")
        wrote(args.out, args)


def _warn_about_result(history: Any) -> None:
    """Warn on stderr of estimates at a range's end, of a failed fit, of incomplete or uninformed
    posteriors, of an observation outside a learned posterior's training data and of one the
    model does not reproduce."""
    if history.at_bound:
        print(
            f"physbench run: warning: {', '.join(history.at_bound)} ended at an end of "
            "its range: the range, not the data, may hold the estimate; widen the unknown's range "
            "(--params KEY=LOW:HIGH, or a scene TOML's [[unknowns]]) and run again",
            file=sys.stderr,
        )
    if history.fit is not None and history.fit.failed:
        print(f"physbench run: warning: {history.fit.describe()}", file=sys.stderr)
    post = history.posterior
    if post is not None and not post.complete:
        print(f"physbench run: warning: incomplete posterior: {post.note}", file=sys.stderr)
    if post is not None and post.domain is not None and not post.domain.inside:
        print(f"physbench run: warning: {post.domain.describe(post.method)}", file=sys.stderr)
    check = history.predictive
    if check is not None and not check.reproduced:
        from physbench.posterior.predictive import warning

        print(f"physbench run: warning: {warning(check.p)}", file=sys.stderr)
    if post is not None and post.undetermined():
        print(
            f"physbench run: warning: the data do not determine {', '.join(post.undetermined())}: "
            "the posterior is about as wide as the range",
            file=sys.stderr,
        )


def _print_details(args: argparse.Namespace, history: Any) -> None:
    """The observation, the per-iteration table, mean timings, the truth and the best iterate."""
    if args.observation:
        print(describe_observation(history))
    print_table(history)
    t = history.timings()
    print(
        f"per iteration: simulate {1e3 * t['simulate']:.2f} ms, render "
        f"{1e3 * t['render']:.2f} ms, "
        f"estimator {1e3 * t['estimator']:.2f} ms"
    )
    best = history.best
    if history.truth is not None:
        print("truth:   " + "  ".join(f"{k}={v:.4g}" for k, v in history.truth.items()))
    print(
        f"best (iteration {best.iteration}, by image MSE): "
        + "  ".join(
            f"{k}={v:.4g}"
            + (" (unseen: a guess)" if k in history.unseen else "")
            + (
                " (at its range's end: the true value may lie beyond)"
                if k in history.at_bound
                else ""
            )
            for k, v in best.params.items()
        )
    )
    _explain_worse_than_initial(history)


def _explain_worse_than_initial(history: Any) -> None:
    """Say why, when the result ends further from the truth than the initial guess: the result
    is the iterate that matches the frames best, and the truth is not in the frames."""
    best, start = history.best_nmse, history.initial_nmse
    if best is None or start is None or best <= start:
        return
    nearest = min(
        (r for r in history.iterations if r.nmse is not None and not r.failed),
        key=lambda r: r.nmse,
    )
    print(
        f"note: the result (normalized MSE {best:.3e}) is further from the truth than the initial "
        f"guess ({start:.3e}): an estimator sees only the frames, and iteration "
        f"{history.best.iteration} matches them best (image MSE {history.best.loss:.3e}); "
        f"iteration {nearest.iteration} came nearer the truth (normalized MSE "
        f"{nearest.nmse:.3e}) but matched the frames less well (image MSE {nearest.loss:.3e})"
    )


def _print_posterior(history: Any) -> None:
    """The posterior's summary, when the estimator returned one."""
    if history.posterior is not None:
        print(f"posterior ({history.posterior.method}, {len(history.posterior)} samples):")
        for line in history.posterior.describe(history.truth):
            print("  " + line)
        if history.predictive is not None:
            print("  " + history.predictive.describe())


def _print_final_line(args: argparse.Namespace, history: Any) -> None:
    """The final line: the normalized min MSE, or without a truth the min image MSE."""
    from physbench.errors import counted

    n = len(history)
    if history.best_nmse is not None:
        print(
            f"normalized min MSE after {counted(n, 'iteration')}: {history.best_nmse:.3e} "
            f"(initial guess {history.initial_nmse:.3e}; min image MSE {history.min_loss:.3e})"
        )
    else:
        print(
            f"min image MSE after {counted(n, 'iteration')}: {history.min_loss:.3e} (no truth: "
            f"observation from {args.observation or args.video})"
        )
