"""Built-in scene generators, one per module, each a seeded ``(seed) -> Scene`` callable.

A generator carries ``name`` and ``description`` attributes (set by :func:`scene_generator`) and is
registered through the ``register_scenes`` hook like any third-party scene.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from physbench.hookspecs import hookimpl
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


def resolve_scene(name_or_path: str, seed: int = 0) -> Scene:
    """A registered scene generator's instance for ``seed``, or a scene loaded from a TOML path."""
    if name_or_path.endswith(".toml") or Path(name_or_path).is_file():
        from physbench.scene_toml import load_scene

        return load_scene(name_or_path)
    from physbench.plugins import get_registry

    return get_registry().get("scene", name_or_path)(seed)


def _builtins() -> list[Any]:
    from physbench.scenes import (
        ball_drop,
        bouncing_balls,
        pendulum,
        second_order,
        stacked_boxes,
        three_circles,
    )

    return [
        m.generate
        for m in (three_circles, second_order, stacked_boxes, bouncing_balls, pendulum, ball_drop)
    ]


@hookimpl
def register_scenes() -> list[Any]:
    return _builtins()
