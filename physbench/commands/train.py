"""``physbench train``: train the resnet3d correction network for a scene and parameter set, or
with ``--posterior`` the npe amortized posterior."""

from __future__ import annotations

import argparse
from typing import Any

from physbench import numeric
from physbench.commands.arguments import (
    SIZE_CHECK_HELP,
    add_params_argument,
    add_quiet_argument,
    add_renderer_choice,
    add_scene_argument,
    bounded_int,
    nonnegative_int,
    positive_int,
    resolution_int,
)

# physbench.estimators.resnet3d.train.MAX_SAMPLES, MAX_BATCH, MAX_WORKERS and sidecar.FRAMES,
# repeated so that building the parser imports nothing heavy (a test checks they agree).
MAX_SAMPLES = 10**9
MAX_BATCH = 4096
MAX_WORKERS = 64
FRAMES = (2, 64)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = SIZE_CHECK_HELP
    _add_target_arguments(p)
    _add_training_arguments(p)
    _add_data_arguments(p)
    _add_validation_arguments(p)
    _add_mode_arguments(p)


def _add_target_arguments(p: argparse.ArgumentParser) -> None:
    """What is trained (scene and unknowns) and where it is written."""
    add_scene_argument(
        p,
        required=False,
        help="a fresh instance per sample group: a registered generator (a TOML file is one "
        "instance and is refused)",
    )
    add_params_argument(p)
    p.add_argument("--out", metavar="DIR", help="output folder (default: runs/train/SCENE__PARAMS)")


def _add_training_arguments(p: argparse.ArgumentParser) -> None:
    """The budget, the network's shape, the device, augmentation and the starting weights."""
    p.add_argument(
        "--samples",
        type=bounded_int(1, MAX_SAMPLES),
        default=None,
        help="training budget in samples (default 40000; --posterior: simulations, default 20000)",
    )
    p.add_argument(
        "--batch",
        type=bounded_int(1, MAX_BATCH),
        default=None,
        help="sequences per training step (default 16; --posterior: 256)",
    )
    p.add_argument(
        "--lr", type=numeric.LEARNING_RATE, default=1e-3, help="learning rate (default 1e-3)"
    )
    p.add_argument(
        "--widths",
        default="16,32,64,128",
        help="channel widths of the 4 stages (paper: 64,128,256,512)",
    )
    p.add_argument(
        "--resolution",
        type=resolution_int,
        default=32,
        help="network input resolution (default 32)",
    )
    p.add_argument(
        "--frames",
        type=bounded_int(*FRAMES),
        default=None,
        help="frames per sequence after subsampling (default 15; --posterior: 30)",
    )
    p.add_argument(
        "--minutes",
        type=numeric.NON_NEGATIVE,
        default=0.0,
        help="wall-clock budget of this session (a resumed run gets it afresh); training ends at "
        "this or --samples, whichever comes first (default: none)",
    )
    p.add_argument(
        "--device", default="cpu", help="torch device to train on, e.g. cuda (default cpu)"
    )
    p.add_argument(
        "--blur-max",
        type=numeric.BLUR,
        default=0.0,
        help="augment: blur half the observed sequences by sigma ~ U(0, this) pixels (default 0: "
        "off)",
    )
    p.add_argument(
        "--near",
        type=numeric.SHARE,
        default=0.0,
        help="share of a sample group's simulations drawn near another one's parameters (each "
        "unknown moved by N(0, --near-scale) of its range), for pairs as close as the loop's "
        "second correction sees (default 0: every simulation from the prior, as the first)",
    )
    p.add_argument(
        "--near-scale",
        type=numeric.LEVEL,
        default=0.05,
        help="spread of --near simulations, as a share of each unknown's range (default 0.05)",
    )
    p.add_argument(
        "--init",
        default="",
        help="fine-tune: start from these weights (.safetensors) instead of a fresh network; "
        "their --widths must match, --resolution and --frames may differ (a bigger input from "
        "the same tensors); training draws scene instances after the ones they were trained on",
    )


def _add_data_arguments(p: argparse.ArgumentParser) -> None:
    """How the training data are made: engine, renderer, processes and threads."""
    p.add_argument("--engine", default="pymunk", help="simulator generating the training data")
    add_renderer_choice(p)
    p.add_argument(
        "--workers",
        type=bounded_int(0, MAX_WORKERS),
        default=1,
        help="data-generating processes (default 1; 0: in the training process)",
    )
    p.add_argument(
        "--threads", type=nonnegative_int, default=0, help="torch threads (default: torch's choice)"
    )


def _add_validation_arguments(p: argparse.ArgumentParser) -> None:
    """Validation during training and the held-out evaluation after it."""
    p.add_argument(
        "--val-groups",
        type=positive_int,
        default=24,
        help="validation scene instances (fixed seeds)",
    )
    p.add_argument(
        "--eval-every",
        type=positive_int,
        default=2_000,
        help="samples between validation/checkpoints",
    )
    p.add_argument(
        "--eval-seeds",
        type=nonnegative_int,
        default=5,
        help="held-out runs of the final evaluation (0 to skip)",
    )


def _add_mode_arguments(p: argparse.ArgumentParser) -> None:
    """Resuming, the npe posterior instead of resnet3d, and how much is printed."""
    p.add_argument(
        "--no-resume", action="store_true", help="start over even if a checkpoint exists"
    )
    p.add_argument(
        "--posterior",
        action="store_true",
        help="train the npe amortized posterior (a mixture density network on pixel summaries) "
        "instead; uses --scene, --params, --out, --samples, --batch, --lr, --frames, --engine, "
        "--renderer, --threads",
    )
    add_quiet_argument(p, "only the result lines")


def check_size(spec: Any, samples: int, scene: Any, minutes: float = 0.0) -> None:
    """Refuse a training run this machine cannot finish (:mod:`physbench.cost`): every sample is
    a simulation of the scene rendered at the data's render resolution (the network's own time
    is left out, so this is a lower bound); ``minutes`` (> 0) ends it sooner."""
    from physbench import cost

    one = cost.of_scene(scene, resolution=spec.render_resolution, mode="mark").times(samples)
    if minutes > 0:
        one = cost.Cost(one.memory, min(one.seconds, 60.0 * minutes))
    cost.check(
        one,
        f"this training ({cost.simulations(samples, scene, spec.render_resolution)})",
        "--samples",
    )


def main(args: argparse.Namespace) -> int:
    from physbench.commands.arguments import DEFAULT_SCENE
    from physbench.estimators.resnet3d.training_data import DataSpec

    if args.posterior:
        return _posterior(args)
    _fill_defaults(args)
    scene_name = args.scene or DEFAULT_SCENE  # a registered generator or a scene TOML file
    params, scene, renderer, renderer_options = _check_problem(args, scene_name)
    widths = _parse_widths(args.widths)
    _check_settings(args)
    spec = DataSpec(
        scene_name,
        params,
        engine=args.engine,
        renderer=renderer,
        renderer_options=renderer_options,
        resolution=args.resolution,
        frames=args.frames,
        blur_max=args.blur_max,
        near=args.near,
        near_scale=args.near_scale,
    )
    check_size(spec, args.samples, scene, args.minutes)
    path, meta = _train(args, spec, widths)
    _print_trained(args, path, meta)
    if args.eval_seeds:
        _print_held_out(path, args.eval_seeds)
    return 0


def _fill_defaults(args: argparse.Namespace) -> None:
    """The resnet3d defaults of the flags whose default depends on --posterior."""
    args.samples = 40_000 if args.samples is None else args.samples
    args.batch = 16 if args.batch is None else args.batch
    args.frames = 15 if args.frames is None else args.frames


def _check_problem(
    args: argparse.Namespace, scene_name: str
) -> tuple[tuple[str, ...], Any, str, dict[str, Any]]:
    """Check resnet3d is installed, the unknowns and the renderer; the unknowns, the scene
    instance of seed 0 and the renderer's name and options."""
    from physbench.commands.arguments import renderer_choice
    from physbench.components import make_renderer
    from physbench.plugins import get_registry
    from physbench.requirements import require
    from physbench.scenes.generator import resolve_scene
    from physbench.unknowns import ParamSpace, split_params

    require("estimator", "resnet3d", get_registry().get("estimator", "resnet3d"))
    params = split_params(args.params)
    scene = resolve_scene(scene_name, 0)
    ParamSpace.from_scene(scene, params)  # unknown parameter names fail here, listing the known
    renderer, renderer_options = renderer_choice(args)
    make_renderer(renderer, renderer_options, resolution=64, mode="mark")  # fail before training
    return params, scene, renderer, renderer_options


def _parse_widths(text: str) -> tuple[int, ...]:
    """The 4 stage widths of ``--widths``."""
    from physbench.errors import PhysbenchError

    try:
        widths = tuple(int(w) for w in text.split(","))
        assert len(widths) == 4 and all(w > 0 for w in widths)
    except (ValueError, AssertionError):
        raise PhysbenchError(
            f"--widths {text!r}: expected 4 positive integers, e.g. 16,32,64,128"
        ) from None
    return widths


def _check_settings(args: argparse.Namespace) -> None:
    """Refuse sizes, budgets and a device the training cannot use."""
    from physbench.errors import PhysbenchError
    from physbench.estimators.resnet3d import sidecar

    for name in ("samples", "batch"):
        if getattr(args, name) < 1:
            raise PhysbenchError(f"--{name} {getattr(args, name)}: must be >= 1")
    # The limits loading enforces: weights outside them could be trained but never loaded.
    for name, (lo, hi) in (("resolution", sidecar.RESOLUTION), ("frames", sidecar.FRAMES)):
        if not lo <= getattr(args, name) <= hi:
            raise PhysbenchError(f"--{name} {getattr(args, name)}: expected {lo}..{hi}")
    for name in ("minutes", "blur_max"):
        if not getattr(args, name) >= 0:
            raise PhysbenchError(f"--{name.replace('_', '-')} {getattr(args, name)}: must be >= 0")
    if args.device != "cpu":
        import torch

        try:
            torch.empty(1, device=args.device)
        except (RuntimeError, AssertionError) as exc:
            raise PhysbenchError(
                f"--device {args.device!r} is not usable here ({exc}); use cpu or an available "
                "GPU, e.g. cuda"
            ) from None


def _train(
    args: argparse.Namespace, spec: Any, widths: tuple[int, ...]
) -> tuple[Any, dict[str, Any]]:
    """Train (resuming from a checkpoint unless --no-resume); the weights' path and metadata."""
    from pathlib import Path

    from physbench.commands.console import show_progress
    from physbench.estimators.resnet3d.network import NetConfig
    from physbench.estimators.resnet3d.train import TrainConfig, train, weights_name

    n_out = len(spec.params)
    net = NetConfig(n_outputs=n_out, widths=widths, resolution=args.resolution, frames=args.frames)  # type: ignore[arg-type]
    cfg = TrainConfig(
        samples=args.samples,
        batch=args.batch,
        lr=args.lr,
        val_groups=args.val_groups,
        eval_every=args.eval_every,
        workers=args.workers,
        threads=args.threads,
        device=args.device,
        minutes=args.minutes,
        init=args.init,
    )
    out = Path(args.out or f"runs/train/{weights_name(spec)}")
    checkpoint = out / "checkpoint.safetensors"
    if not args.no_resume and checkpoint.is_file():
        _say_resuming(checkpoint, args.samples)
    return train(spec, net, cfg, out, resume=not args.no_resume, progress=show_progress(args))


def _say_resuming(checkpoint: Any, samples: int) -> None:
    """Say on stderr where training resumes from ``checkpoint``."""
    import json
    import sys

    try:
        done = json.loads(checkpoint.with_suffix(".json").read_text())["samples"]
        at = f"at {done} of {samples} samples"
    except (OSError, ValueError, KeyError, TypeError):
        at = "(its sample count unreadable)"
    print(
        f"resuming from {checkpoint} {at} (--no-resume starts over)",
        file=sys.stderr,
    )


def _print_trained(args: argparse.Namespace, path: Any, meta: dict[str, Any]) -> None:
    """The files written and the training's result line."""
    from physbench.commands.console import wrote

    wrote(path, args)
    wrote(path.with_suffix(".json"), args)
    print(
        f"weights: {path} (+ {path.with_suffix('.json').name}); validation MSE of normalised Δp: "
        f"{meta['val_mse']:.3g}; "
        f"{meta['training']['samples_seen']} samples in {meta['training']['wall_s']:.0f} s"
    )


def _print_held_out(path: Any, seeds: int) -> None:
    """The mean normalized min MSE of the weights on held-out seeds after 1, 2 and 11 iterations."""
    from physbench.bench.held_out import evaluate_weights

    rows = evaluate_weights(path, seeds=range(seeds), iterations=11)
    for it in (1, 2, 11):
        vals = [r[it] for r in rows]
        print(
            f"held-out seeds 0..{seeds - 1}: normalized min MSE after {it:2d} "
            "iterations: "
            f"{sum(vals) / len(vals):.3g}"
        )


def _posterior(args: argparse.Namespace) -> int:
    """``train --posterior``: simulate, fit the npe ensemble, write its weights."""
    from pathlib import Path

    from physbench.commands.arguments import DEFAULT_SCENE, renderer_choice
    from physbench.commands.console import show_progress, wrote
    from physbench.components import make_renderer
    from physbench.errors import PhysbenchError
    from physbench.estimators.npe.estimator import NPEEstimator
    from physbench.estimators.npe.train import NPETrainConfig, train, weights_name
    from physbench.estimators.npe.training_data import NPEDataSpec
    from physbench.requirements import require
    from physbench.scenes.generator import is_scene_file, resolve_scene
    from physbench.unknowns import ParamSpace, split_params

    require("estimator", "npe", NPEEstimator)
    params = split_params(args.params)
    scene_name = args.scene or DEFAULT_SCENE
    if is_scene_file(scene_name):
        raise PhysbenchError(
            f"--posterior --scene {scene_name!r}: a scene file is one instance; npe learns over "
            "a generator's instances, e.g. --scene three_circles"
        )
    ParamSpace.from_scene(resolve_scene(scene_name, 0), params)  # unknown names fail here
    renderer, renderer_options = renderer_choice(args)
    make_renderer(renderer, renderer_options, resolution=64, mode="mark")
    samples = 20_000 if args.samples is None else args.samples
    batch = 256 if args.batch is None else args.batch
    frames = 30 if args.frames is None else args.frames
    for name, value, low in (("samples", samples, 20), ("batch", batch, 1), ("frames", frames, 2)):
        if value < low:
            raise PhysbenchError(f"--{name} {value}: must be >= {low}")
    spec = NPEDataSpec(
        scene_name,
        params,
        engine=args.engine,
        renderer=renderer,
        renderer_options=renderer_options,
        frames=frames,
    )
    check_size(spec, samples, resolve_scene(scene_name, 0))
    cfg = NPETrainConfig(samples=samples, batch=batch, lr=args.lr, threads=args.threads)
    out = Path(args.out or f"runs/train/npe/{weights_name(spec)}")
    path, meta = train(spec, None, cfg, out, progress=show_progress(args))
    wrote(path, args)
    wrote(path.with_suffix(".json"), args)
    t = meta["training"]
    print(
        f"npe weights: {path} (+ {path.with_suffix('.json').name}); validation NLL in logit-unit "
        f"space {meta['val_nll']:.3f} ({t['train_rows']} training rows from {samples} "
        f"simulations; {t['simulate_s']:.0f} s simulating, {t['wall_s']:.0f} s in all)"
    )
    return 0
