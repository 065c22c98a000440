"""``physbench simulate``: one scene instance -> trajectory + frames (.npz) and a preview."""

from __future__ import annotations

import argparse

from physbench.commands.arguments import add_renderer_arguments, make_renderer_from


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", required=True, help="registered scene name or a scene .toml file")
    p.add_argument(
        "--engine", default="pymunk", help="simulator (see `physbench plugins`; default pymunk)"
    )
    p.add_argument("--seed", type=int, default=0, help="scene instance seed (default 0)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="BODY.PARAM=VALUE",
        help="override a body parameter, e.g. --set a.mass=3 (repeatable)",
    )
    add_renderer_arguments(p)
    p.add_argument("--out", metavar="FILE.npz", help="write trajectory and frames here")
    p.add_argument("--preview", metavar="FILE.gif|png", help="write a picture of the run")


def parse_overrides(items: list[str]) -> dict[str, float]:
    from physbench.errors import PhysbenchError

    out: dict[str, float] = {}
    for item in items:
        key, sep, value = item.partition("=")
        try:
            if not sep or "." not in key:
                raise ValueError
            out[key.strip()] = float(value)
        except ValueError:
            raise PhysbenchError(
                f"--set {item!r}: expected BODY.PARAM=NUMBER, e.g. a.mass=3.5"
            ) from None
    return out


def main(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from physbench.errors import PhysbenchError
    from physbench.plugins import create
    from physbench.scenes import resolve_scene

    if args.out and not args.out.endswith(".npz"):
        raise PhysbenchError(f"--out {args.out!r}: the output is an .npz file")
    scene = resolve_scene(args.scene, args.seed)
    scene = scene.with_params(parse_overrides(args.set)).validate()
    renderer = make_renderer_from(args)  # a bad renderer or option fails before simulating
    traj = create("simulator", args.engine).simulate(scene)
    frames = renderer.render(scene, traj)
    print(
        f"{scene.name} seed {args.seed} on {args.engine}: {traj.frames} frames, bodies "
        f"{', '.join(traj.bodies)}, "
        f"frames {frames.shape}"
    )
    for i, name in enumerate(traj.bodies):
        (x0, y0), (x1, y1) = traj.states[0, i, :2], traj.states[-1, i, :2]
        print(f"  {name:>8}: ({x0:6.3f}, {y0:6.3f}) -> ({x1:6.3f}, {y1:6.3f}) m")
    if args.out:
        from physbench.scene_toml import dumps_scene

        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(
            args.out, frames=frames, scene_toml=np.array(dumps_scene(scene)), **traj.to_npz_dict()
        )
        print(f"wrote {args.out}")
    if args.preview:
        from physbench.render.preview import save_preview

        save_preview(scene, traj, args.preview)
        print(f"wrote {args.preview}")
    return 0
