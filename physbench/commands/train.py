"""``physbench train``: train the resnet3d correction network for a scene and parameter set."""

from __future__ import annotations

import argparse

from physbench.commands.arguments import add_renderer_choice


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", required=True, help="registered scene name")
    p.add_argument(
        "--params",
        required=True,
        help="comma-separated unknown parameters, e.g. mass or mass,elasticity",
    )
    p.add_argument("--out", help="output folder (default runs/train/SCENE__PARAMS)")
    p.add_argument(
        "--samples", type=int, default=40_000, help="training budget in samples (default 40000)"
    )
    p.add_argument("--batch", type=int, default=16)
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument(
        "--widths",
        default="16,32,64,128",
        help="channel widths of the 4 stages (paper: 64,128,256,512)",
    )
    p.add_argument(
        "--resolution", type=int, default=32, help="network input resolution (default 32)"
    )
    p.add_argument(
        "--frames", type=int, default=15, help="frames per sequence after subsampling (default 15)"
    )
    p.add_argument(
        "--minutes",
        type=float,
        default=0.0,
        help="wall-clock budget; training ends at this or --samples, whichever comes first "
        "(default: none)",
    )
    p.add_argument(
        "--device", default="cpu", help="torch device to train on, e.g. cuda (default cpu)"
    )
    p.add_argument(
        "--blur-max",
        type=float,
        default=0.0,
        help="augment: blur half the observed sequences by sigma ~ U(0, this) pixels (default 0: "
        "off)",
    )
    p.add_argument(
        "--init",
        default="",
        help="fine-tune: start from these weights (.safetensors) instead of a fresh network",
    )
    p.add_argument("--engine", default="pymunk", help="simulator generating the training data")
    add_renderer_choice(p)
    p.add_argument("--workers", type=int, default=1, help="data-generating processes (default 1)")
    p.add_argument("--threads", type=int, default=0, help="torch threads (default: torch's choice)")
    p.add_argument(
        "--val-groups", type=int, default=24, help="validation scene instances (fixed seeds)"
    )
    p.add_argument(
        "--eval-every", type=int, default=2_000, help="samples between validation/checkpoints"
    )
    p.add_argument(
        "--eval-seeds",
        type=int,
        default=5,
        help="held-out runs of the final evaluation (0 to skip)",
    )
    p.add_argument(
        "--no-resume", action="store_true", help="start over even if a checkpoint exists"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def main(args: argparse.Namespace) -> int:
    from pathlib import Path

    from physbench.commands.arguments import renderer_choice
    from physbench.errors import PhysbenchError
    from physbench.estimators.resnet3d.data import DataSpec
    from physbench.estimators.resnet3d.model import NetConfig
    from physbench.estimators.resnet3d.train import TrainConfig, train, weights_name
    from physbench.experiment import make_renderer
    from physbench.params import ParamSpace
    from physbench.plugins import get_registry
    from physbench.requirements import require

    require("estimator", "resnet3d", get_registry().get("estimator", "resnet3d"))
    params = tuple(p.strip() for p in args.params.split(",") if p.strip())
    scene = get_registry().get("scene", args.scene)(0)
    ParamSpace.from_scene(scene, params)  # unknown parameter names fail here, listing the known
    renderer, renderer_options = renderer_choice(args)
    make_renderer(renderer, renderer_options, resolution=64, mode="mark")  # fail before training
    try:
        widths = tuple(int(w) for w in args.widths.split(","))
        assert len(widths) == 4 and all(w > 0 for w in widths)
    except (ValueError, AssertionError):
        raise PhysbenchError(
            f"--widths {args.widths!r}: expected 4 positive integers, e.g. 16,32,64,128"
        ) from None
    for name in ("samples", "batch", "resolution", "frames"):
        if getattr(args, name) < 1:
            raise PhysbenchError(f"--{name} {getattr(args, name)}: must be >= 1")
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
    spec = DataSpec(
        args.scene,
        params,
        engine=args.engine,
        renderer=renderer,
        renderer_options=renderer_options,
        resolution=args.resolution,
        frames=args.frames,
        blur_max=args.blur_max,
    )
    n_out = len(params)
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
    path, meta = train(spec, net, cfg, out, resume=not args.no_resume, progress=not args.quiet)
    print(
        f"weights: {path} (+ {path.with_suffix('.json').name}); validation MSE of normalised Δp: "
        f"{meta['val_mse']:.3g}; "
        f"{meta['training']['samples_seen']} samples in {meta['training']['wall_s']:.0f} s"
    )
    if args.eval_seeds:
        from physbench.estimators.resnet3d.evaluate import evaluate_weights

        rows = evaluate_weights(path, seeds=range(args.eval_seeds), iterations=11)
        for it in (1, 2, 11):
            vals = [r[it] for r in rows]
            print(
                f"held-out seeds 0..{args.eval_seeds - 1}: normalized min MSE after {it:2d} "
                "iterations: "
                f"{sum(vals) / len(vals):.3g}"
            )
    return 0
