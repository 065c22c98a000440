"""Built-in scene generators, one per module, each a seeded ``(seed) -> Scene`` callable.

A generator carries ``name`` and ``description`` attributes (set by
:func:`~physbench.scenes.generator.scene_generator`) and is registered through the
``register_scenes`` hook like any third-party scene.
"""

from __future__ import annotations

from typing import Any

from physbench.hookspecs import hookimpl
from physbench.scenes.generator import SceneGenerator, resolve_scene, scene_generator

__all__ = ["SceneGenerator", "resolve_scene", "scene_generator"]


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
