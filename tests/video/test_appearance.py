"""A body's appearance: a detection of another size or colour is not the body."""

from __future__ import annotations

import numpy as np

from physbench.video.appearance import Appearance, Look


def test_another_size_or_colour_is_named_and_shading_is_not() -> None:
    red = Appearance.first(Look(1.0, np.array([180.0, 30.0, 25.0])))
    assert red.mismatch(Look(1.2, np.array([120.0, 20.0, 17.0]))) is None  # in the shade
    assert red.mismatch(Look(3.0, np.array([180.0, 30.0, 25.0]))) == "3.00 times its size"
    skin = Look(1.1, np.array([205.0, 160.0, 130.0]))
    assert red.mismatch(skin).startswith("another colour")  # a hand
    grey = Appearance.first(Look(1.0, np.array([120.0, 120.0, 125.0])))
    assert grey.mismatch(Look(1.0, np.array([30.0, 30.0, 32.0]))).endswith("its brightness")
    for _ in range(30):  # it follows slow changes
        red.update(Look(1.3, np.array([160.0, 35.0, 30.0])))
    assert abs(red.size - 1.3) < 0.02


def test_a_body_of_a_few_pixels_is_judged_by_its_size_alone() -> None:
    # A 3.7 px ball on a brick wall: its first look was 0-3 grey levels, the next 90-170; judged
    # by colour it was rejected in 39 of 41 frames of a filmed projectile.
    speck = Appearance.first(Look(0.9, np.array([3.0, 1.0, -1.0]), pixels=3.7))
    assert speck.mismatch(Look(0.8, np.array([155.0, 131.0, 120.0]), pixels=3.7)) is None
    assert speck.mismatch(Look(9.0, np.array([3.0, 1.0, -1.0]), pixels=3.7)).endswith("its size")
    ball = Appearance.first(Look(0.9, np.array([3.0, 1.0, -1.0]), pixels=400.0))
    assert ball.mismatch(Look(0.8, np.array([155.0, 131.0, 120.0]), pixels=400.0)) is not None


def test_a_dark_body_is_judged_by_how_far_its_colour_moved_not_by_its_hue() -> None:
    # A black ball of 6 px in H.264-coded frames (benchmarks/track_shading.py, wall 1): its
    # colour moved from (31, 18, 0) to (12, 13, 19) as the wall behind it bled in, 0.46 apart
    # in direction; judged by hue it was rejected in 13 of 16 frames.
    black = Appearance.first(Look(1.0, np.array([31.0, 18.0, 0.0]), pixels=113.0))
    assert black.mismatch(Look(1.1, np.array([12.0, 13.0, 19.0]), pixels=113.0)) is None
    sleeve = Look(1.1, np.array([10.0, 15.0, 60.0]), pixels=113.0)  # dark blue, 62 levels off
    assert black.mismatch(sleeve).startswith("another colour")


def test_a_dark_ball_filmed_on_a_lit_wall_is_tracked_in_every_frame() -> None:
    # The shading benchmark's case: a black ball of 6 px radius, motion-blurred, H.264 at CRF 23,
    # on a warm wall (170, 135, 90). It stands 140-186 grey levels from the wall.
    from physbench.calibration import Calibration
    from physbench.codec import h264_round_trip
    from physbench.scene import Body, Circle, Scene
    from physbench.video.reader import Frame
    from physbench.video.spheres import Sphere, expose, paint, wall
    from physbench.video.track import track_frames

    rng = np.random.default_rng(1)
    plate = wall((240, 320), 1)
    sphere = Sphere(6.0, (0.08, 0.08, 0.08), (-0.85, 0.10, 0.52), ambient=0.2, specular=0.7)
    start, velocity = np.array([110.4, 110.7]), np.array([4.3, 1.7])
    frames, truth = [], []
    for k in range(16):
        img = plate.astype(np.float64)
        centre = start + velocity * k
        paint(img, sphere, centre + velocity * np.linspace(-0.25, 0.25, 9)[:, None])
        frames.append(expose(img, rng))
        truth.append(centre)
    clean = expose(plate.astype(np.float64), rng, noise=0.0)
    coded = h264_round_trip(np.stack([clean, *frames]), 30.0, 0, 23)
    cal = Calibration.from_scale(0.01, (0.0, 239.0))
    x0, y0 = cal.to_scene(truth[0])
    ball = Body("ball", Circle(0.06), (float(x0), float(y0)), velocity=(1.29, -0.51))
    scene = Scene("sphere", (ball,), bounds=(0, 0, 3.2, 2.4), gravity=(0, 0), fps=30.0, frames=16)
    res = track_frames(
        [Frame(k, k / 30.0, img) for k, img in enumerate(coded[1:])],
        scene.validate(),
        cal,
        coded[0],
    )
    px = res.pixels["ball"]
    assert len(px) == 16 and not res.summary.rejected
    assert np.hypot(*(px[:, 1:] - np.array(truth)).T).max() < 0.6
