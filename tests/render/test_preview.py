"""Previews for people: GIF and PNG pictures of a run."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import UnknownNameError
from physbench.render.base import RenderError
from physbench.render.preview import save_preview
from physbench.scene import Body, Box, Circle, Scene
from physbench.trajectory import Trajectory

BOUNDS = (0.0, 0.0, 4.0, 4.0)


def make_scene(*bodies: Body) -> Scene:
    return Scene(name="t", bodies=bodies, bounds=BOUNDS, test_body=bodies[0].name)


def still(scene: Scene, frames: int = 1) -> Trajectory:
    states = np.zeros((frames, len(scene.bodies), 6))
    for i, b in enumerate(scene.bodies):
        states[:, i, :3] = (*b.position, b.angle)
    return Trajectory(scene.body_names, np.arange(frames) / scene.fps, states)


@pytest.fixture
def three() -> Scene:
    return make_scene(
        Body("test", Circle(0.3), (0.8, 2.5)),
        Body("a", Box(0.6, 0.4), (2.0, 1.0), angle=0.3),
        Body("b", Circle(0.3), (2.5, 1.2)),
    )


def moving(scene: Scene, frames: int = 12) -> Trajectory:
    traj = still(scene, frames)
    traj.states[:, :, 0] += np.linspace(0, 0.8, frames)[:, None]
    return traj


def test_preview_writes_gif_and_png(three: Scene, tmp_path) -> None:
    from PIL import Image

    traj = moving(three, frames=5)
    gif = save_preview(three, traj, tmp_path / "run.gif", size=96, focus="a")
    png = save_preview(three, traj, tmp_path / "run.png", size=96)
    with Image.open(gif) as im:
        assert im.n_frames == 5 and im.size == (96, 96)
    with Image.open(png) as im:
        rgb = np.asarray(im.convert("RGB"))
    assert rgb.shape == (96, 96, 3)
    assert (rgb.min(axis=2) < 200).any()  # something besides the white background was drawn
    with pytest.raises(RenderError, match=r"accepted: \.gif, \.png"):
        save_preview(three, traj, tmp_path / "run.mp4")
    with pytest.raises(UnknownNameError):
        save_preview(three, traj, tmp_path / "x.gif", focus="nope")
