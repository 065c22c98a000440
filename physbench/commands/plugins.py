"""``physbench plugins``: every discovered component, and plugins that failed to load."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output")


def main(args: argparse.Namespace) -> int:
    import json

    from physbench.plugins import get_registry

    reg = get_registry()
    rows = [(c.kind, c.name, c.plugin, c.package, c.version) for c in reg.all()]
    if args.json:
        print(
            json.dumps(
                {
                    "components": [
                        dict(zip(("kind", "name", "plugin", "package", "version"), r, strict=True))
                        for r in rows
                    ],
                    "failed": [f.__dict__ for f in reg.failed],
                },
                indent=2,
            )
        )
        return 0
    head = ("KIND", "NAME", "PLUGIN", "PACKAGE", "VERSION")
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=True)]
    for r in (head, *rows):
        print("  ".join(str(x).ljust(w) for x, w in zip(r, widths, strict=True)).rstrip())
    if reg.failed:
        print("\nFailed to load (skipped):")
        for f in reg.failed:
            print(f"  {f.plugin} ({f.package} {f.version}): {f.error}")
    return 0
