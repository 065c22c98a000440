"""``physbench simulate``: one scene instance -> trajectory + frames (.npz) or, filmed by the
camera renderer, a video file, and a preview."""

from __future__ import annotations

import argparse
from typing import Any

from physbench.commands.arguments import (
    DEFAULT_SCENE,
    SIZE_CHECK_HELP,
    add_quiet_argument,
    add_renderer_arguments,
    add_scene_argument,
    make_renderer_from,
    seed_int,
)

#: ``--out`` suffixes written as a video file (camera renderer only).
VIDEO_SUFFIXES = (".mp4", ".mkv", ".avi", ".mov", ".webm", ".gif")
#: ``--plate`` suffixes.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = SIZE_CHECK_HELP
    add_scene_argument(p, required=False)
    p.add_argument(
        "--engine", default="pymunk", help="simulator (see `physbench plugins`; default pymunk)"
    )
    p.add_argument("--seed", type=seed_int, default=0, help="scene instance seed (default 0)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="BODY.PARAM=VALUE",
        help="override a body parameter, e.g. --set a.mass=3 (repeatable)",
    )
    p.add_argument(
        "--effect",
        action="append",
        default=[],
        metavar="NAME[:KEY=VALUE,...]",
        help="simulate with an effect, e.g. linear_drag:c=0.3 (repeatable; see `physbench "
        "plugins`): a recording or clip with physics the scene's model lacks, for discover",
    )
    add_renderer_arguments(p)
    p.add_argument(
        "--out",
        metavar="FILE",
        help="write trajectory and frames here: FILE.npz (any renderer), or with --renderer "
        f"camera a video file ({', '.join(VIDEO_SUFFIXES)}) of the clip at the frames' times",
    )
    p.add_argument(
        "--plate",
        metavar="FILE.png",
        help="with --renderer camera: write the empty scene (background, no bodies, no noise) as "
        "an image, the clean plate a tracker takes as background",
    )
    p.add_argument("--preview", metavar="FILE.gif|png", help="write a picture of the run")
    add_quiet_argument(p, "no output but errors and warnings")


def parse_overrides(items: list[str]) -> dict[str, float]:
    """``--set BODY.PARAM=VALUE`` items as ``{"a.mass": 3.5}``; a value must be a finite number."""
    from physbench.errors import PhysbenchError
    from physbench.numeric import ANY

    out: dict[str, float] = {}
    for item in items:
        key, sep, value = item.partition("=")
        try:
            if not sep or "." not in key:
                raise ValueError
            out[key.strip()] = float(ANY.parse(value))
        except ValueError:
            raise PhysbenchError(
                f"--set {item!r}: expected BODY.PARAM=NUMBER (a finite number), e.g. a.mass=3.5"
            ) from None
    return out


def make_effects(items: list[str]) -> list:
    """Effect instances from ``--effect NAME[:KEY=VALUE,...]`` items."""
    from physbench.components import make_effect

    return [make_effect(item) for item in items]


def main(args: argparse.Namespace) -> int:
    from physbench.scenes import resolve_scene

    video = _check_paths(args)
    scene = resolve_scene(args.scene or DEFAULT_SCENE, args.seed)
    scene = scene.with_params(parse_overrides(args.set)).validate()
    renderer = make_renderer_from(args)  # a bad renderer or option fails before simulating
    camera = _camera(renderer, args, video)
    _check_size(scene, renderer, args.resolution)
    effects = make_effects(args.effect)
    traj = _simulate(args.engine, scene, effects)
    # A video is filmed as it is written (_write_out): no separate render of the frames.
    frames_shape = renderer.shape(scene, traj.frames) if video else None
    frames = None if video else renderer.render(scene, traj)
    if not args.quiet:
        _print_trajectory(args, scene, traj, frames_shape if frames is None else frames.shape)
    _write_out(args, scene, traj, frames, effects, camera, video)
    _write_pictures(args, scene, traj, camera)
    return 0


def _check_paths(args: argparse.Namespace) -> bool:
    """Refuse --out, --plate and --preview names of a kind not written; whether --out is a
    video."""
    from pathlib import Path

    from physbench.errors import PhysbenchError

    suffix = Path(args.out).suffix.lower() if args.out else ""
    video = suffix in VIDEO_SUFFIXES
    if args.out and suffix != ".npz" and not video:
        raise PhysbenchError(
            f"--out {args.out!r}: expected an .npz file, or a video file "
            f"({', '.join(VIDEO_SUFFIXES)}) with --renderer camera"
        )
    if args.plate and Path(args.plate).suffix.lower() not in IMAGE_SUFFIXES:
        raise PhysbenchError(
            f"--plate {args.plate!r}: expected an image file ({', '.join(IMAGE_SUFFIXES)})"
        )
    if args.preview:
        from physbench.render.preview import SUFFIXES as PREVIEW_SUFFIXES

        if Path(args.preview).suffix.lower() not in PREVIEW_SUFFIXES:
            raise PhysbenchError(
                f"--preview {args.preview!r}: expected {' or '.join(PREVIEW_SUFFIXES)} "
                "(an animation or a trail picture)"
            )
    return video


def _camera(renderer: Any, args: argparse.Namespace, video: bool) -> Any:
    """``renderer`` if it is a camera, else None; refuse a video or plate without one."""
    from physbench.errors import PhysbenchError
    from physbench.render.base import Camera

    camera = renderer if isinstance(renderer, Camera) else None
    for flag, value, wants in (
        ("--out", args.out if video else None, "a video"),
        ("--plate", args.plate, "a plate"),
    ):
        if value and camera is None:
            raise PhysbenchError(
                f"{flag} {value!r}: {wants} is filmed by --renderer camera; renderer "
                f"{renderer.name!r} makes {renderer.mode!r} channels, not a colour image "
                "(write its frames to an .npz file)"
            )
    return camera


def _check_size(scene: Any, renderer: Any, resolution: int) -> None:
    """Refuse a simulation this machine cannot hold (:mod:`physbench.cost`)."""
    from physbench import cost

    # Rendered frames are held twice: as rendered and while --out compresses them.
    one = cost.of_scene(scene, resolution=resolution, mode=renderer.mode, held=2)
    cost.check(
        one,
        f"this simulation ({cost.simulations(1, scene, resolution)})",
        "--resolution or the scene's frames, substeps or bodies",
    )


def _simulate(engine: str, scene: Any, effects: list) -> Any:
    """The trajectory of ``scene`` on ``engine`` with ``effects`` and their measurements."""
    from physbench.components import create

    traj = create("simulator", engine).simulate(scene, effects=effects)
    if effects:
        from physbench.effects import apply_measurements

        traj = apply_measurements(traj, effects)
    return traj


def _print_trajectory(args: argparse.Namespace, scene: Any, traj: Any, shape: Any) -> None:
    """One line on the run, then each body's start and end position."""
    print(
        f"{scene.name} seed {args.seed} on {args.engine}: {traj.frames} frames, bodies "
        f"{', '.join(traj.bodies)}, "
        f"frames {shape}"
    )
    for i, name in enumerate(traj.bodies):
        (x0, y0), (x1, y1) = traj.states[0, i, :2], traj.states[-1, i, :2]
        print(f"  {name:>8}: ({x0:6.3f}, {y0:6.3f}) -> ({x1:6.3f}, {y1:6.3f}) m")


def _write_out(
    args: argparse.Namespace,
    scene: Any,
    traj: Any,
    frames: Any,
    effects: list,
    camera: Any,
    video: bool,
) -> None:
    """Write --out: the camera's clip as a video file, or trajectory and frames as .npz."""
    if not args.out:
        return
    from pathlib import Path

    from physbench.commands.console import wrote

    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    if video:
        from physbench.video.writer import write_clip

        assert camera is not None
        write_clip(camera, args.out, scene, traj)
    else:
        import numpy as np

        from physbench.scene_toml import dumps_scene

        np.savez_compressed(
            args.out,
            frames=frames,
            scene_toml=np.array(dumps_scene(scene)),
            effects=np.array([repr(e) for e in effects], dtype=str),
            **traj.to_npz_dict(),
        )
    wrote(args.out, args)


def _write_pictures(args: argparse.Namespace, scene: Any, traj: Any, camera: Any) -> None:
    """Write the --plate image and the --preview picture."""
    from pathlib import Path

    from physbench.commands.console import wrote

    if args.plate:
        from PIL import Image

        assert camera is not None
        Path(args.plate).parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(camera.plate(scene)).save(args.plate)
        wrote(args.plate, args)
    if args.preview:
        from physbench.commands.arguments import renderer_choice
        from physbench.render.preview import save_preview

        name, options = renderer_choice(args)
        save_preview(scene, traj, args.preview, renderer=name, options=options)
        wrote(args.preview, args)
