"""The renderer contract's defaults: resolution and mode checks, ``shape`` from a still."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from physbench.render.base import (
    MODES,
    Renderer,
    RenderError,
    check_resolution,
)
from physbench.scene import Body, Box, Circle, Scene
from physbench.trajectory import Trajectory


def make_scene(*bodies: Body) -> Scene:
    return Scene(name="t", bodies=bodies, bounds=(0.0, 0.0, 4.0, 4.0), test_body=bodies[0].name)


def still(scene: Scene) -> Trajectory:
    states = np.zeros((1, len(scene.bodies), 6))
    for i, b in enumerate(scene.bodies):
        states[0, i, :3] = (*b.position, b.angle)
    return Trajectory(scene.body_names, np.zeros(1), states)


class Dots(Renderer):
    """A renderer without its own ``shape``: one channel, a dot per body."""

    name: ClassVar[str] = "dots"
    modes: ClassVar[tuple[str, ...]] = ("mask",)

    def render(self, scene, traj, *, focus=None, out=None):  # type: ignore[no-untyped-def]
        n = int(self.resolution)  # type: ignore[arg-type]
        frames = np.zeros((traj.frames, 1, n // 2, n), np.float32)
        frames[:, 0, 0, : len(traj.bodies)] = 1.0
        return frames


def test_shape_defaults_to_a_rendered_still() -> None:
    scene = make_scene(Body("a", Circle(0.3), (1.0, 1.0)), Body("b", Box(0.4, 0.2), (2.0, 1.0)))
    assert Dots(resolution=10, mode="mask").shape(scene) == (scene.frames, 1, 5, 10)
    assert Dots(resolution=10, mode="mask").shape(scene, frames=3) == (3, 1, 5, 10)


def test_modes_and_resolution_are_checked_for_every_renderer() -> None:
    assert MODES == ("mark", "instance", "mask", "rgb")
    with pytest.raises(RenderError, match="renderer 'dots' supports modes mask"):
        Dots(mode="mark")
    assert check_resolution(32) == 32 and check_resolution([48, 64]) == (48, 64)
    for bad in (0, True, 2.5, (64,), "64"):
        with pytest.raises(RenderError, match="resolution = "):
            check_resolution(bad)
