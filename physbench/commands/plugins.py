"""``physbench plugins``: every discovered component, the plugins that failed to load, and the
names that several plugins claim."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from physbench.plugins import Component, Registry


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument(
        "--check",
        action="store_true",
        help="exit with status 1 when a plugin failed to load or two claim one name (without "
        "it the listing always ends with status 0): for CI of a plugin package",
    )


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
                    "conflicts": [
                        {
                            "kind": c.kind,
                            "name": c.name,
                            "kept": None if c.kept is None else _origin(c.kept),
                            "ignored": [_origin(i) for i in c.ignored],
                            "message": c.describe(),
                        }
                        for c in reg.conflicts
                    ],
                },
                indent=2,
            )
        )
        return _status_code(args, reg)
    head = ("KIND", "NAME", "PLUGIN", "PACKAGE", "VERSION", "STATUS")
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=True)]
    for r in (head, *rows):
        print("  ".join(str(x).ljust(w) for x, w in zip(r, widths, strict=True)).rstrip())
    if reg.failed:
        print("\nFailed to load (skipped):")
        for f in reg.failed:
            print(f"  {f.plugin} ({f.package} {f.version}): {f.error}")
    if reg.conflicts:
        print("\nName conflicts:")
        for c in reg.conflicts:
            print(f"  {c.describe()}")
    return _status_code(args, reg)


def _status_code(args: argparse.Namespace, reg: Registry) -> int:
    """1 with ``--check`` when a plugin failed or a name conflict exists (said on stderr), else
    0."""
    import sys

    if not args.check or not (reg.failed or reg.conflicts):
        return 0
    from physbench.errors import counted

    print(
        f"physbench plugins: check failed: {counted(len(reg.failed), 'plugin')} failed to load, "
        f"{counted(len(reg.conflicts), 'name conflict')}",
        file=sys.stderr,
    )
    return 1


def _origin(c: Component) -> dict[str, str]:
    return {"plugin": c.plugin, "package": c.package, "version": c.version}


def _status(missing: dict[str, str]) -> str:
    if not missing:
        return "ok"
    install = " ".join(f"'{r}'" for r in dict.fromkeys(sorted(missing.values())))
    return f"unavailable: needs {', '.join(sorted(missing))} (pip install {install})"
