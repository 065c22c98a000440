"""``physbench scenes``: the registered scenes and their unknowns."""

from __future__ import annotations

import argparse

from physbench.commands.arguments import seed_int


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--seed", type=seed_int, default=0, help="instance to describe (default 0)")
    p.add_argument("--toml", metavar="NAME", help="print one scene's instance as TOML and exit")


def main(args: argparse.Namespace) -> int:
    from physbench.plotting.units import DIMENSIONLESS
    from physbench.plugins import get_registry
    from physbench.scene_toml import dumps_scene

    reg = get_registry()
    if args.toml:
        print(dumps_scene(reg.get("scene", args.toml)(args.seed)), end="")
        return 0
    for name in reg.names("scene"):
        gen = reg.get("scene", name)
        scene = gen(args.seed)
        print(f"{name}  ({reg.info('scene', name).package})")
        print(f"    {gen.description}")
        bodies = ", ".join(scene.body_names)
        print(
            f"    bodies: {bodies}" + (f"; test body: {scene.test_body}" if scene.test_body else "")
        )
        by_param: dict[str, list[str]] = {}
        units: dict[str, str] = {}
        for u in scene.unknowns:
            by_param.setdefault(u.name, []).append(f"{u.owner} [{u.low:g}, {u.high:g}]")
            units.setdefault(u.name, u.unit or DIMENSIONLESS)
        for param, items in by_param.items():
            print(f"    unknown {param} ({units[param]}): {', '.join(items)}")
        if not scene.unknowns:
            print("    unknowns: none")
    return 0
