"""``physbench plugins``: every discovered component, and plugins that failed to load."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output")


def main(args: argparse.Namespace) -> int:
    import json

    from physbench.plugins import get_registry
    from physbench.requirements import missing_of

    reg = get_registry()
    missing = {(c.kind, c.name): missing_of(c.obj) for c in reg.all()}
    rows = [
        (c.kind, c.name, c.plugin, c.package, c.version, _status(missing[c.kind, c.name]))
        for c in reg.all()
    ]
    if args.json:
        print(
            json.dumps(
                {
                    "components": [
                        dict(
                            zip(
                                ("kind", "name", "plugin", "package", "version"), r[:5], strict=True
                            ),
                            available=not missing[r[0], r[1]],
                            missing=missing[r[0], r[1]],
                        )
                        for r in rows
                    ],
                    "failed": [f.__dict__ for f in reg.failed],
                },
                indent=2,
            )
        )
        return 0
    head = ("KIND", "NAME", "PLUGIN", "PACKAGE", "VERSION", "STATUS")
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=True)]
    for r in (head, *rows):
        print("  ".join(str(x).ljust(w) for x, w in zip(r, widths, strict=True)).rstrip())
    if reg.failed:
        print("\nFailed to load (skipped):")
        for f in reg.failed:
            print(f"  {f.plugin} ({f.package} {f.version}): {f.error}")
    return 0


def _status(missing: dict[str, str]) -> str:
    if not missing:
        return "ok"
    install = " ".join(f"'{r}'" for r in dict.fromkeys(sorted(missing.values())))
    return f"unavailable: needs {', '.join(sorted(missing))} (pip install {install})"
