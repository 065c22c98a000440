"""Segmenting camera frames into the scene frame: the masks match sharp renders of the same poses,
touching bodies split along their contact, foreground away from every body is dropped, and bad
inputs are named."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.calibration import Calibration
from physbench.components import create
from physbench.render.camera import CameraRenderer
from physbench.render.raster import RasterRenderer
from physbench.scene import Body, Box, Circle, Scene
from physbench.scenes import resolve_scene
from physbench.trajectory import Trajectory
from physbench.video.segment import (
    Segmenter,
    SegmentError,
    body_threshold,
    difference,
    fill_holes,
    foreground,
    noise_threshold,
)


def segment(cam: CameraRenderer, scene: Scene, traj: Trajectory, mode: str) -> np.ndarray:
    film, plate = cam.film(scene, traj), cam.plate(scene)
    seg = Segmenter(scene, cam.calibration(scene), film.shape[1:3], resolution=64, mode=mode)
    floor = noise_threshold(film[0], plate)
    out = []
    for k, image in enumerate(film):
        diff = difference(image, plate)
        poses = traj.states[k, :, :3]
        thr = body_threshold(diff, cam.calibration(scene).to_image(poses[:, :2]), floor)
        out.append(seg.frame(seg.coverage((diff > thr).astype(np.float32), poses)))
    return np.stack(out)


@pytest.mark.parametrize("name", ["three_circles", "stacked_boxes"])
def test_filmed_frames_segment_into_the_sharp_masks(name: str) -> None:
    scene = resolve_scene(name, 3)
    traj = create("simulator", "pymunk").simulate(scene)
    cam = CameraRenderer(640, tilt=15.0, bitrate=2_000_000, seed=1)
    got = segment(cam, scene, traj, "instance")
    ref = RasterRenderer(64, "instance").render(scene, traj)
    area = got.sum(axis=(0, 2, 3)) / ref.sum(axis=(0, 2, 3))
    np.testing.assert_allclose(area, 1.0, atol=0.04)  # measured: within 2.7 %
    # Pixel error far below the signal (mean square of the sharp masks).
    assert np.mean((got - ref) ** 2) < 0.01 * np.mean(ref**2)


def test_touching_bodies_split_along_their_contact() -> None:
    a = Body("a", Circle(0.3), (1.7, 1.5))
    b = Body("b", Box(0.6, 0.6), (2.3, 1.5))
    scene = Scene("touch", (a, b), bounds=(0.0, 0.0, 4.0, 3.0), frames=1).validate()
    states = np.array([[[1.7, 1.5, 0, 0, 0, 0], [2.3, 1.5, 0, 0, 0, 0]]])
    traj = Trajectory(scene.body_names, np.zeros(1), states)
    cam = CameraRenderer(640, noise=0.0, light=0.0, flicker=0.0, background="plain")
    got = segment(cam, scene, traj, "instance")[0]
    ref = RasterRenderer(64, "instance").render(scene, traj)[0]
    for i in range(2):
        assert got[i].sum() == pytest.approx(ref[i].sum(), rel=0.03)
        assert np.abs(got[i] - ref[i]).max() < 0.35  # only edge pixels differ, and by little


def test_foreground_far_from_every_body_is_dropped() -> None:
    scene = Scene(
        "one", (Body("a", Circle(0.2), (1.0, 1.0)),), bounds=(0.0, 0.0, 4.0, 3.0), frames=1
    ).validate()
    h, w = 300, 400
    cal = Calibration.from_scale(0.01, (-0.5, 299.5))  # 1 cm pixels, scene = the image
    seg = Segmenter(scene, cal, (h, w), resolution=64, mode="mask")
    fg = np.zeros((h, w), np.float32)
    fg[180:221, 80:121] = 1.0  # a 41 cm square around the body's centre (1, 1): in reach
    fg[20:60, 300:340] = 1.0  # a passer-by far from the body
    cov = seg.coverage(fg, np.array([[1.0, 1.0, 0.0]]))
    ys, xs = np.nonzero(cov[0] > 0)
    # 16 pixels per metre: the body's square spans columns 8-24 and rows 25-39; the passer-by
    # (columns 48-54, rows 3-10) is gone.
    assert xs.max() < 25 and ys.min() > 24
    assert cov[0].sum() == pytest.approx(0.41 * 0.41 * 16 * 16, rel=0.05)


def test_mark_mode_marks_the_focus_body_alone() -> None:
    scene = resolve_scene("stacked_boxes", 10)
    traj = create("simulator", "pymunk").simulate(scene)
    cam = CameraRenderer(320, seed=2)
    film, plate = cam.film(scene, traj), cam.plate(scene)
    seg = Segmenter(scene, cam.calibration(scene), film.shape[1:3], resolution=32, mode="mark")
    cov = seg.coverage(foreground(film[0], plate, 40), traj.states[0, :, :3])
    focus = scene.body_names[1]
    marked, plain = seg.frame(cov, focus), seg.frame(cov)
    np.testing.assert_array_equal(marked[1], cov[1])
    np.testing.assert_array_equal(plain[1], 0.0)
    np.testing.assert_array_equal(plain[0], cov.max(axis=0))


def test_bad_inputs_are_named() -> None:
    scene = resolve_scene("stacked_boxes", 10)
    cal = Calibration.from_scale(0.01, (0.0, 0.0))
    with pytest.raises(SegmentError, match="mode = 'rgb'"):
        Segmenter(scene, cal, (100, 100), mode="rgb")
    seg = Segmenter(scene, cal, (100, 100), resolution=16)
    with pytest.raises(SegmentError, match=r"poses have shape \(2, 3\); expected \(3, 3\)"):
        seg.coverage(np.zeros((100, 100), np.float32), np.zeros((2, 3)))
    with pytest.raises(SegmentError, match="frame is 50x100 px; this video's frames are 100x100"):
        seg.coverage(np.zeros((100, 50), np.float32), np.zeros((3, 3)))


def test_small_holes_in_the_foreground_are_filled_and_gaps_are_not() -> None:
    mask = np.zeros((40, 60), bool)
    mask[5:20, 5:20] = True
    mask[10:12, 10:12] = False  # a highlight's 4 px under the threshold
    mask[5:35, 30:55] = True
    mask[12:28, 37:48] = False  # a ring's 176 px middle: background
    mask[0:10, 25:28] = True
    mask[0:4, 26] = False  # open to the edge
    out = fill_holes(mask, max_area=50)
    assert out[10:12, 10:12].all()
    assert not out[12:28, 37:48].any()
    assert not out[0:4, 26].any()
    assert (out & ~mask).sum() == 4  # nothing else changes
    assert fill_holes(mask, max_area=500)[12:28, 37:48].all()


def test_a_ball_with_a_highlight_segments_without_a_hole() -> None:
    # The box scene's ball on its light wall: the specular highlight falls under the threshold
    # (a hole down to 0.28 in the 64 px masks, measured); the observed masks must be as solid
    # as the rendered ones inside. Their outermost pixels are left out: one of them follows where
    # the coder put the ball's edge (0.23 in one frame, 0.73 with another x264 setting).
    from scipy.ndimage import binary_erosion

    from physbench.video.footage import filmed_observation

    scene = resolve_scene("stacked_boxes", 10)
    cam = CameraRenderer(640, tilt=15.0, bitrate=2_000_000, seed=1)
    obs = filmed_observation(scene, {}, create("simulator", "pymunk"), cam, RasterRenderer(64))
    ref = RasterRenderer(64).render(scene, create("simulator", "pymunk").simulate(scene))
    got = np.asarray(obs.frames)[:, 0]
    inside = np.stack([binary_erosion(mask) for mask in np.asarray(ref)[:, 0] > 0.999])
    assert got[inside].min() > 0.5
