"""Scene generators: seeded ``(seed) -> Scene`` callables with a ``name`` and a ``description``,
and the lookup of a scene by registered name or TOML path."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from physbench.scene import Scene


class SceneGenerator(Protocol):
    name: str
    description: str

    def __call__(self, seed: int = 0) -> Scene: ...


def scene_generator(
    name: str, description: str
) -> Callable[[Callable[[int], Scene]], SceneGenerator]:
    """Decorator: mark a ``(seed) -> Scene`` function as a registrable scene generator."""

    def wrap(fn: Callable[[int], Scene]) -> SceneGenerator:
        fn.name = name  # type: ignore[attr-defined]
        fn.description = description  # type: ignore[attr-defined]
        return fn  # type: ignore[return-value]

    return wrap


def is_scene_file(name_or_path: str) -> bool:
    """Whether a ``--scene`` value names a scene TOML file rather than a registered generator."""
    try:
        return name_or_path.endswith(".toml") or Path(name_or_path).is_file()
    except OSError:  # e.g. a name too long for a path: it cannot name a file
        return False


def resolve_scene(name_or_path: str, seed: int = 0) -> Scene:
    """A registered scene generator's instance for ``seed``, or a scene loaded from a TOML path."""
    if is_scene_file(name_or_path):
        from physbench.scene_toml import load_scene

        return load_scene(name_or_path)
    from physbench.plugins import get_registry, guard

    generate = get_registry().get("scene", name_or_path)
    with guard("scene", generate, f"the call for seed {seed}"):
        return generate(seed)
