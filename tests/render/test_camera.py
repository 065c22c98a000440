"""The camera renderer films a scene like a real camera: its calibration is the true map to the
scene, motion blur keeps the centroid, the plate is the empty scene, bad options are named, and an
H.264 round trip keeps the picture."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.calibration import Calibration
from physbench.render.base import RenderError
from physbench.render.camera import CameraRenderer
from physbench.scene import Body, Box, Circle, Scene
from physbench.testing import Check, Subject, parametrize_with_checks
from physbench.testing.renderers import probe_scene, probe_trajectory
from physbench.trajectory import Trajectory
from physbench.video.writer import write_clip

#: A clean picture: no noise, no uneven or changing light, a uniform background.
CLEAN = {"noise": 0.0, "light": 0.0, "flicker": 0.0, "background": "plain"}


def one_body(pos: tuple[float, float], shape: object = None) -> Scene:
    body = Body("ball", shape or Circle(0.1), pos)  # type: ignore[arg-type]
    return Scene("one", (body,), bounds=(0.0, 0.0, 4.0, 3.0), frames=1).validate()


def still(scene: Scene, velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Trajectory:
    states = np.array([[[*b.position, b.angle, *velocity] for b in scene.bodies]], float)
    return Trajectory(scene.body_names, np.zeros(1), states)


def blob(image: np.ndarray, plate: np.ndarray, threshold: int = 60) -> np.ndarray:
    """The pixels that differ from the plate: a boolean (H, W) mask."""
    return np.abs(image.astype(int) - plate.astype(int)).sum(axis=-1) > threshold


def centroid(mask: np.ndarray) -> np.ndarray:
    v, u = np.nonzero(mask)
    return np.array([u.mean(), v.mean()])


def test_frames_have_the_declared_shape_type_and_range() -> None:
    scene, cam = probe_scene(), CameraRenderer(64)
    traj = probe_trajectory(scene)
    frames = cam.render(scene, traj)
    assert frames.shape == cam.shape(scene) == (scene.frames, 3, 48, 64)
    assert frames.dtype == np.float32 and frames.min() >= 0 and frames.max() <= 1
    film = cam.film(scene, traj)
    assert film.shape == (scene.frames, 48, 64, 3) and film.dtype == np.uint8
    np.testing.assert_array_equal(frames, film.transpose(0, 3, 1, 2) / np.float32(255))
    assert CameraRenderer((30, 50)).shape(scene, 2) == (2, 3, 30, 50)
    assert CameraRenderer().mode == "rgb" and CameraRenderer().shape(scene)[2:] == (480, 640)


def test_the_seed_fixes_background_light_and_noise() -> None:
    scene = probe_scene()
    traj = probe_trajectory(scene)
    a = CameraRenderer(64, seed=3).film(scene, traj)
    np.testing.assert_array_equal(a, CameraRenderer(64, seed=3).film(scene, traj))
    assert (a != CameraRenderer(64, seed=4).film(scene, traj)).mean() > 0.3
    plates = [CameraRenderer(64, seed=s, noise=0).plate(scene) for s in (3, 4)]
    assert np.abs(plates[0].astype(int) - plates[1]).max() > 20  # another wall, not just noise


@pytest.mark.parametrize(
    "pose",
    [
        {},
        {"k1": -0.1},
        {"tilt": 25},
        {"tilt": 25, "k1": 0.08},
        {"tilt": 20, "yaw": -30, "roll": 10},
    ],
)
def test_the_calibration_maps_a_still_body_onto_its_blob(pose: dict[str, float]) -> None:
    cam = CameraRenderer(640, **CLEAN, **pose)  # type: ignore[arg-type]
    for pos in ((1.0, 1.0), (3.2, 2.5), (0.3, 0.3)):
        scene = one_body(pos)
        mask = blob(cam.film(scene, still(scene))[0], cam.plate(scene))
        want = cam.calibration(scene).to_image(np.array(pos))
        assert np.linalg.norm(centroid(mask) - want) < 0.3, (pose, pos)
        assert (cam.calibration(scene).lens is None) == ("k1" not in pose)
        np.testing.assert_allclose(cam.calibration(scene).to_scene(want), pos, atol=1e-9)


def test_four_image_points_give_the_true_calibration() -> None:
    cam = CameraRenderer(320, tilt=30, yaw=15)
    scene = one_body((2.0, 1.5))
    xmin, ymin, xmax, ymax = scene.bounds
    corners = np.array([(xmin, ymin), (xmax, ymin), (xmax, ymax), (xmin, ymax)])
    fitted = Calibration.from_points(cam.image_points(scene, corners), corners)
    pixels = np.array([(0.0, 0.0), (319.0, 239.0), (100.5, 40.25)])
    np.testing.assert_allclose(
        fitted.to_scene(pixels), cam.calibration(scene).to_scene(pixels), atol=1e-9
    )
    # The bounds lie inside the image with the margin around them.
    uv = cam.image_points(scene, corners)
    assert (uv > 2).all() and (uv[:, 0] < 317).all() and (uv[:, 1] < 237).all()


def test_a_view_frames_part_of_the_plane() -> None:
    scene = one_body((1.0, 1.0))
    whole, part = CameraRenderer(320), CameraRenderer(320, view=(0.5, 0.5, 1.5, 1.25))
    centre = np.array([[1.0, 0.875]])
    np.testing.assert_allclose(part.image_points(scene, centre)[0], (159.5, 119.5), atol=1e-6)
    # A quarter of the world's width fills the image: four times the pixels per metre.
    ratio = whole.calibration(scene).metres_per_pixel((160, 120)) / part.calibration(
        scene
    ).metres_per_pixel((160, 120))
    assert ratio == pytest.approx(4.0, rel=1e-6)


def test_a_tilted_camera_sees_parallel_lines_converge() -> None:
    scene = one_body((2.0, 1.5))
    corners = np.array([(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)])

    def widths(**pose: float) -> tuple[float, float, float]:
        bl, br, tr, tl = CameraRenderer(320, **pose).image_points(scene, corners)  # type: ignore[arg-type]
        left, right = tl - bl, tr - br  # the two vertical sides of the bounds
        cross = left[0] * right[1] - left[1] * right[0]
        return float(tr[0] - tl[0]), float(br[0] - bl[0]), float(cross)

    top, bottom, cross = widths()
    assert top == pytest.approx(bottom) and cross == pytest.approx(0, abs=1e-9)
    top, bottom, cross = widths(tilt=30)
    assert top > 1.2 * bottom and abs(cross) > 1  # tilt > 0: the top is nearer, sides converge
    left_near = CameraRenderer(320, yaw=-30).image_points(scene, corners)
    # v runs down: a side's height is v(bottom) - v(top); yaw < 0 brings the left side nearer.
    assert left_near[0, 1] - left_near[3, 1] > 1.2 * (left_near[1, 1] - left_near[2, 1])


def test_motion_blur_spreads_a_moving_body_along_its_velocity_and_keeps_its_centroid() -> None:
    scene = one_body((2.0, 1.5), Circle(0.15))
    plate = CameraRenderer(320, **CLEAN).plate(scene)  # type: ignore[arg-type]

    def moments(velocity: tuple[float, float, float], shutter: float) -> np.ndarray:
        """Centroid and variance (px) of the red body's darkening of the grey plate's green: the
        blurred image is the sharp one averaged over the sub-frame poses."""
        cam = CameraRenderer(320, shutter=shutter, subframes=16, **CLEAN)  # type: ignore[arg-type]
        image = cam.film(scene, still(scene, velocity))[0]
        w = plate[..., 1].astype(float) - image[..., 1]
        v, u = np.mgrid[0 : w.shape[0], 0 : w.shape[1]]
        mu, mv = (w * u).sum() / w.sum(), (w * v).sum() / w.sum()
        return np.array(
            [mu, mv, (w * (u - mu) ** 2).sum() / w.sum(), (w * (v - mv) ** 2).sum() / w.sum()]
        )

    px_per_m = 1 / CameraRenderer(320).calibration(scene).metres_per_pixel((160, 120))
    sharp = moments((0.0, 0.0, 0.0), 1.0)
    for velocity, shutter in (((3.0, 0.0, 0.0), 1.0), ((3.0, 0.0, 0.0), 0.4), ((0, -2, 0), 1.0)):
        blurred = moments(velocity, shutter)
        np.testing.assert_allclose(blurred[:2], sharp[:2], atol=0.05)  # the centroid stays
        # Sub-frame offsets spread uniformly over the exposure: variance (S^2 - 1) / (12 S^2) L^2.
        streak = np.abs(velocity[:2]) * shutter * scene.dt * px_per_m
        grow = streak**2 * (16**2 - 1) / (12 * 16**2)
        np.testing.assert_allclose(blurred[2:] - sharp[2:], grow, rtol=0.05, atol=0.05)
        assert grow.max() > 0.5


def test_the_plate_is_the_empty_scene_in_the_light_of_frame_0() -> None:
    scene = probe_scene()
    traj = probe_trajectory(scene)
    cam = CameraRenderer(160, noise=0.0)
    first, plate = cam.film(scene, traj)[0], cam.plate(scene)
    assert plate.shape == first.shape and plate.dtype == np.uint8
    uv = cam.image_points(scene, traj.states[0, :, :2])
    bodies = np.zeros(plate.shape[:2], bool)
    for u, v in uv:
        bodies[int(v) - 25 : int(v) + 26, int(u) - 25 : int(u) + 26] = True
    np.testing.assert_array_equal(first[~bodies], plate[~bodies])
    for u, v in np.rint(uv).astype(int):
        assert np.abs(first[v, u].astype(int) - plate[v, u]).sum() > 60
    np.testing.assert_array_equal(plate, cam.plate(Scene("empty", (), scene.bounds)))


def test_noise_light_and_flicker_change_the_picture_as_asked() -> None:
    scene = probe_scene()
    traj = probe_trajectory(scene)
    quiet = CameraRenderer(64, noise=0.0, flicker=0.0).film(scene, traj).astype(float)
    noisy = CameraRenderer(64, noise=0.05, flicker=0.0).film(scene, traj).astype(float)
    assert np.std(noisy - quiet) / 255 == pytest.approx(0.05, rel=0.15)
    flicker = CameraRenderer(64, noise=0.0, flicker=0.3).film(scene, traj).astype(float)
    level = flicker.mean(axis=(1, 2, 3)) / quiet.mean(axis=(1, 2, 3))
    assert level.std() > 0.01 and level[0] == pytest.approx(1, abs=0.3)
    flat = CameraRenderer(64, **CLEAN).plate(scene).astype(float)  # type: ignore[arg-type]
    lit = CameraRenderer(64, **{**CLEAN, "light": 0.5}).plate(scene).astype(float)  # type: ignore[arg-type]
    assert flat.std() < 1 and lit.std() > 5


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("background", "sky", "background = 'sky': expected one of texture, clutter, plain"),
        ("tilt", 95, r"tilt = 95: expected a number in \(-90, 90\)"),
        ("subframes", 0, r"subframes = 0: expected a whole number in \[1, 256\]"),
        ("noise", -0.1, r"noise = -0.1: expected a number in \[0, 1\]"),
        ("crf", 60, r"crf = 60"),
        ("shutter", 1.5, r"shutter = 1.5"),
        ("view", [0, 0, 1], r"view = \[0, 0, 1\]: expected \[xmin, ymin, xmax, ymax\]"),
        ("view", [2, 0, 1, 1], r"with xmin < xmax"),
    ],
)
def test_bad_options_are_named(option: str, value: object, message: str) -> None:
    with pytest.raises(RenderError, match=message):
        CameraRenderer(64, **{option: value})  # type: ignore[arg-type]


def test_poses_and_lenses_that_cannot_film_the_scene_are_refused() -> None:
    scene = probe_scene()
    with pytest.raises(RenderError, match=r"tilt = 80\.0, yaw = 60\.0: the camera looks along"):
        CameraRenderer(64, tilt=80, yaw=60).render(scene, probe_trajectory(scene))
    folds = r"k1 = -0\.9, k2 = 0\.0: with fov = 50 the distortion folds"
    with pytest.raises(RenderError, match=folds):
        CameraRenderer(64, k1=-0.9).plate(scene)
    with pytest.raises(RenderError, match="do not match the scene's bodies"):
        CameraRenderer(64).render(scene, probe_trajectory(one_body((1.0, 1.0))))


def test_an_h264_round_trip_changes_pixels_but_keeps_the_picture(tmp_path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("av")
    scene = probe_scene()
    traj = probe_trajectory(scene)
    raw = CameraRenderer(160, seed=1).film(scene, traj).astype(float)
    coded = CameraRenderer(160, seed=1, bitrate=1_000_000).film(scene, traj).astype(float)
    assert coded.shape == raw.shape and (coded != raw).mean() > 0.2
    psnr = 10 * np.log10(255**2 / np.mean((coded - raw) ** 2))
    assert 30 < psnr < 60
    odd = CameraRenderer((25, 33), crf=23).film(scene, traj)  # H.264 needs even sizes: padded
    assert odd.shape == (scene.frames, 25, 33, 3)


def test_write_encodes_the_clip_at_the_trajectory_times(tmp_path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("av")
    from physbench.video.reader import VideoReader

    scene = probe_scene()
    traj = probe_trajectory(scene)
    cam = CameraRenderer(96)
    write_clip(cam, tmp_path / "clip.mkv", scene, traj)
    frames = list(VideoReader(tmp_path / "clip.mkv").frames())
    assert len(frames) == scene.frames
    np.testing.assert_allclose([f.time for f in frames], traj.times, atol=2e-3)
    first = frames[0].image.astype(float)
    assert 10 * np.log10(255**2 / np.mean((first - cam.film(scene, traj)[0]) ** 2)) > 30


def test_polygons_turn_with_the_body() -> None:
    box = Box(0.8, 0.3)
    scene = one_body((2.0, 1.5), box)
    cam = CameraRenderer(160, **CLEAN)  # type: ignore[arg-type]
    plate = cam.plate(scene)
    flat = blob(cam.film(scene, still(scene))[0], plate)
    turned = Trajectory(scene.body_names, np.zeros(1), np.array([[[2.0, 1.5, np.pi / 2, 0, 0, 0]]]))
    upright = blob(cam.film(scene, turned)[0], plate)
    assert flat.any(axis=0).sum() > 2 * flat.any(axis=1).sum()
    assert upright.any(axis=1).sum() > 2 * upright.any(axis=0).sum()


@parametrize_with_checks(
    [
        CameraRenderer,
        Subject(
            CameraRenderer,
            {"tilt": 30, "yaw": -10, "k1": 0.1, "background": "clutter", "bitrate": 300_000},
            requires=("av",),
            id="ObliqueEncodedCamera",
        ),
    ]
)
def test_the_renderer_kit_passes(component: Subject, check: Check) -> None:
    check(component)
