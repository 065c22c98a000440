"""Sweep specs that ship inside the package, so that the quick start's sweep runs from a wheel
(``physbench bench --example smoke --out smoke``; from Python, :func:`physbench.example`). Each is
a spec TOML in this folder; ``benchmarks/`` in a checkout holds the same specs among the
repository's benchmarks (a test keeps the two equal)."""

from __future__ import annotations

from pathlib import Path

from physbench.errors import UnknownNameError

FOLDER = Path(__file__).resolve().parent


def example_names() -> list[str]:
    """The names of the shipped example specs."""
    return sorted(p.stem for p in FOLDER.glob("*.toml"))


def example_path(name: str) -> Path:
    """The spec file of the shipped example ``name``; an unknown name lists the known ones."""
    names = example_names()
    if name not in names:
        raise UnknownNameError("example spec", name, names)
    return FOLDER / f"{name}.toml"
