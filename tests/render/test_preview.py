"""Previews for people: GIF and PNG pictures of a run, captioned with the bodies' names, the scene,
the time and a scale bar in metres."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import UnknownNameError
from physbench.render.base import RenderError
from physbench.render.preview import MARGIN, save_preview, scale_length
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
        assert im.n_frames == 5 and im.size[0] == 96 and im.size[1] > 96  # a caption band below
    with Image.open(png) as im:
        rgb = np.asarray(im.convert("RGB"))
    assert rgb.shape[1:] == (96, 3) and rgb.shape[0] > 96
    assert (rgb.min(axis=2) < 200).any()  # something besides the white background was drawn
    with pytest.raises(RenderError, match=r"accepted: \.gif, \.png"):
        save_preview(three, traj, tmp_path / "run.mp4")
    with pytest.raises(UnknownNameError):
        save_preview(three, traj, tmp_path / "x.gif", focus="nope")


def test_previews_name_the_bodies_the_scene_the_time_and_the_scale(
    three: Scene, tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from PIL import ImageDraw

    written: list[str] = []
    text = ImageDraw.ImageDraw.text

    def record(self, xy, string, *args, **kwargs):
        written.append(string)
        return text(self, xy, string, *args, **kwargs)

    monkeypatch.setattr(ImageDraw.ImageDraw, "text", record)
    traj = moving(three, frames=5)  # frames k at t = k / fps
    save_preview(three, traj, tmp_path / "run.gif", size=96)
    assert [w for w in written if w.startswith("t ")] == [
        f"t   t = {k / three.fps:.2f} s" for k in range(5)
    ]
    assert written.count("test") == written.count("a") == written.count("b") == 5
    assert written.count("1 m") == 5  # a 4 m wide world: the largest 1-2-5 length <= 1/4 of it
    written.clear()
    save_preview(three, traj, tmp_path / "run.png", size=96)
    assert sorted(written) == sorted(
        [
            "test",
            "a",
            "b",
            f"t   t = 0.00 to {4 / three.fps:.2f} s (5 snapshots, faint: early)",
            "1 m",
        ]
    )


def test_the_scale_bar_is_as_long_as_its_label_says(three: Scene, tmp_path) -> None:
    from PIL import Image

    png = save_preview(three, still(three), tmp_path / "run.png", size=200)
    with Image.open(png) as im:
        dark = np.asarray(im.convert("L"))[200:] < 60  # the caption band below the scene
    longest = max(_longest_run(row) for row in dark)
    metres_per_pixel = 4.0 * (1 + 2 * MARGIN) / 200
    assert abs(longest * metres_per_pixel - 1.0) < 0.03  # "1 m", to a pixel or two


def _longest_run(row: np.ndarray) -> int:
    best = n = 0
    for v in row:
        n = n + 1 if v else 0
        best = max(best, n)
    return best


@pytest.mark.parametrize(("width", "length"), [(4.24, 1.0), (10.0, 2.0), (0.3, 0.05), (40, 10)])
def test_the_scale_bar_takes_a_round_length_of_at_most_a_quarter_of_the_width(
    width: float, length: float
) -> None:
    assert scale_length(width) == pytest.approx(length)


@pytest.mark.parametrize("suffix", [".gif", ".png"])
def test_simulate_previews_with_the_chosen_renderer(tmp_path, suffix: str) -> None:
    from PIL import Image

    from physbench.cli import main

    def picture(*argv: str) -> np.ndarray:
        path = tmp_path / f"p{len(argv)}{suffix}"
        assert main(["simulate", "--resolution", "16", "-q", "--preview", str(path), *argv]) == 0
        with Image.open(path) as im:
            return np.asarray(im.convert("RGB"), dtype=float)

    raster = picture()
    camera = picture("--renderer", "camera", "-R", "noise=0")

    # The raster preview draws bodies on white; the camera's is its own footage, a textured wall
    # (white only in the caption band below it).
    def white(img: np.ndarray) -> float:
        return float((img == 255).all(axis=2).mean())

    assert white(raster) > 0.6 and white(camera) < 0.3, (white(raster), white(camera))
    if suffix == ".png":  # snapshots side by side, each as wide as the preview
        assert camera.shape[1] > 2 * raster.shape[1]
