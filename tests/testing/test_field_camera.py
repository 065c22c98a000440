"""The second, independent camera (``physbench/testing/field_camera.py``): it passes the renderer
kit, draws bodies where its calibration says, its light drifts as its domain says, and every seed
draws a domain within the stated ranges."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.render.base import RenderError
from physbench.scene import Body, Circle, Scene
from physbench.testing import check_renderer
from physbench.testing.field_camera import GAMMA, Domain, FieldCamera
from physbench.trajectory import Trajectory

STILL = {"shutter": 0.0, "shot": 0.0, "read": 0.0}


def ball_scene(frames: int = 1) -> Scene:
    return Scene(
        "ball",
        (Body("ball", Circle(0.06), (0.7, 0.45)),),
        bounds=(0.0, 0.0, 2.0, 1.5),
        frames=frames,
    )


def still(scene: Scene, xy: tuple[float, float]) -> Trajectory:
    states = np.zeros((scene.frames, 1, 6))
    states[:, 0, :2] = xy
    return Trajectory(("ball",), np.arange(scene.frames) / scene.fps, states, "hand")


def test_it_passes_the_renderer_kit() -> None:
    check_renderer(FieldCamera, seed=3)


@pytest.mark.parametrize("seed", [0, 7])
def test_bodies_are_drawn_where_the_calibration_says(seed: int) -> None:
    scene = ball_scene()
    cam = FieldCamera(320, seed=seed, drift=0.0, **STILL)
    cal = cam.calibration(scene)
    xy = np.array([[0.3, 0.2], [1.7, 1.3], [1.0, 0.75]])
    assert np.allclose(cal.to_image(xy), cam.image_points(scene, xy), atol=1e-9)
    assert np.allclose(cal.to_scene(cam.image_points(scene, xy)), xy, atol=1e-9)
    # a flat white disc (no shading, no highlight) drawn alone: its coverage-weighted centre
    geo = cam._static(scene)[0]
    flat = FieldCamera(320, seed=seed, ambient=1.0, specular=0.0, falloff=0.0)
    for centre in xy:
        img = np.zeros((geo.h, geo.w, 3), np.float32)
        poses = np.tile([*centre, 0.0], (9, 1))
        flat._draw(img, flat._static(scene)[0], Circle(0.06), poses, np.ones(3, np.float32))
        alpha = img[..., 0]
        v, u = np.mgrid[0 : geo.h, 0 : geo.w]
        mid = np.array([(alpha * u).sum(), (alpha * v).sum()]) / alpha.sum()
        # a disc under a mild perspective and lens images nearly as an ellipse about its
        # projection (measured: 0.06 px off near a corner)
        assert np.hypot(*(mid - cal.to_image(centre))) < 0.1, (seed, centre)
        assert alpha.sum() == pytest.approx(
            np.pi * 0.06**2 / cal.metres_per_pixel(cal.to_image(centre)) ** 2, rel=0.05
        )


def test_the_light_drifts_as_the_domain_says() -> None:
    scene = ball_scene(frames=20)
    cam = FieldCamera(320, seed=4, drift=0.1, **STILL)
    frames = cam.exposure(scene, still(scene, (1.9, 1.4))).astype(float)
    level = cam.domain.level(np.linspace(0, 1, 20))
    assert level.min() >= 0.9 - 1e-12 and level.max() <= 1.1 + 1e-12 and np.ptp(level) > 0.05
    # away from the ball, every pixel is the first frame's scaled by the level (gamma encoded)
    region = (slice(20, 100), slice(150, 300))
    ratio = frames[:, *region].mean(axis=(1, 2, 3)) / frames[0, *region].mean()
    want = (level / level[0]) ** (1 / GAMMA)
    assert np.abs(ratio - want).max() < 0.01
    plate = cam.plate(scene).astype(float)
    assert plate[region].mean() == pytest.approx(
        frames[0, *region].mean() / level[0] ** (1 / GAMMA), rel=0.02
    )


def test_every_seed_draws_a_domain_in_the_stated_ranges() -> None:
    domains = [Domain.draw(s) for s in range(60)]
    for d in domains:
        d.check()
        assert 18 <= d.crf <= 30 and 0.03 <= d.drift <= 0.10 and d.oblique <= 25
    assert {d.texture for d in domains} == {"bricks", "planks", "plaster"}
    assert len({d.crf for d in domains}) > 8
    assert Domain.draw(5) == Domain.draw(5) and Domain.draw(5) != Domain.draw(6)


def test_bad_options_are_named() -> None:
    with pytest.raises(RenderError, match="zoom: unknown option"):
        FieldCamera(zoom=2)
    with pytest.raises(RenderError, match="crf = 60"):
        FieldCamera(crf=60)
    with pytest.raises(RenderError, match="texture = 'marble'"):
        FieldCamera(texture="marble")
    with pytest.raises(RenderError, match="view = "):
        FieldCamera(view=(1, 1, 0, 0))
    with pytest.raises(RenderError, match=r"k1 = -0\.5.*folds the image"):
        FieldCamera(320, k1=-0.5, fov=100).calibration(ball_scene())
