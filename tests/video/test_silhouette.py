"""Disc centres from their outline: a lit sphere's shading and highlight do not move them, nor a
rod joined to the disc; edges are found along rays and fitted on the plane."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.calibration import Calibration
from physbench.codec import h264_round_trip
from physbench.scene import Body, Circle, Scene
from physbench.video.reader import Frame
from physbench.video.segment import difference
from physbench.video.silhouette import Rays, edge_points, fit_disc
from physbench.video.spheres import Sphere, expose, paint, wall
from physbench.video.track import track_frames

CAL = Calibration.from_scale(0.01, (0.0, 239.0))


def _track(sphere: Sphere, seed: int, extra=None) -> tuple[np.ndarray, np.ndarray]:
    """Centre errors ``(T, 2)`` (px) of ``sphere`` drifting over a wall for 12 coded frames, and
    the weighted centroids' errors of the same blobs, for comparison."""
    from physbench.video.detect import find_blobs

    rng = np.random.default_rng(seed)
    plate = wall((240, 320), seed)
    truth = np.array([120.3, 115.6]) + np.outer(np.arange(12), [0.41, 0.23])
    frames = [expose(plate.astype(np.float64), rng, noise=0.0)]
    for c in truth:
        img = plate.astype(np.float64)
        if extra is not None:
            extra(img, c)
        paint(img, sphere, [c])
        frames.append(expose(img, rng))
    frames = h264_round_trip(np.stack(frames), 30.0, 0, 23)
    plate, frames = frames[0], frames[1:]
    x, y = CAL.to_scene(truth[0])
    body = Body(
        "ball", Circle(0.01 * sphere.radius), (float(x), float(y)), velocity=(0.123, -0.069)
    )
    scene = Scene("s", (body,), bounds=(0.0, 0.0, 3.2, 2.4), gravity=(0.0, 0.0), frames=12)
    result = track_frames(
        [Frame(k, k / 30, f) for k, f in enumerate(frames)], scene.validate(), CAL, plate
    )
    fitted = result.pixels["ball"][:, 1:] - truth
    centroids = []
    for img, c in zip(frames, truth, strict=True):
        blobs = find_blobs(difference(img, plate), 20.0, 60.0)
        _, u, v, w = min(blobs, key=lambda b: np.hypot(*(b[0].centre - c)))
        centroids.append([w @ u / w.sum(), w @ v / w.sum()])
    return fitted, np.array(centroids) - truth


@pytest.mark.parametrize(
    ("radius", "colour", "light"),
    [
        (13, (0.45, 0.47, 0.50), (-0.45, -0.55, 0.70)),  # a steel ball lit from the upper left
        (22, (0.45, 0.47, 0.50), (0.60, -0.30, 0.74)),
        (17, (0.85, 0.15, 0.10), (0.0, -0.80, 0.60)),  # a red one from above
        (22, (0.65, 0.65, 0.65), (-0.85, 0.10, 0.52)),  # light grey, from the left
    ],
)
def test_a_lit_sphere_with_a_highlight_is_centred_within_a_fifth_of_a_pixel(
    radius, colour, light
) -> None:
    sphere = Sphere(radius, colour, light, ambient=0.2, specular=0.7, shininess=25.0)
    fitted, centroid = _track(sphere, seed=radius)
    toward = sphere.highlight()
    assert len(fitted) == 12
    assert abs(np.mean(fitted @ toward)) <= 0.2  # the bias along the highlight's direction
    assert np.hypot(*fitted.T).max() <= 0.5
    if colour[0] < 0.8:  # the weighted centroid leans away from the highlight by 0.7-3 px
        assert np.mean(centroid @ toward) < -0.5


def test_a_rod_joined_to_a_bob_leaves_its_centre_alone() -> None:
    # A pendulum's rod drawn up from the bob: one blob, whose centroid the rod pulls up by
    # pixels; the outline's rays along the rod find no edge and drop out of the fit.
    def rod(img: np.ndarray, c: np.ndarray) -> None:
        img[: int(c[1]), int(c[0]) - 2 : int(c[0]) + 3] = (0.15, 0.15, 0.15)

    sphere = Sphere(14.0, (0.85, 0.15, 0.10))
    fitted, centroid = _track(sphere, seed=3, extra=rod)
    assert np.hypot(*fitted.T).max() <= 0.3
    assert np.mean(-centroid[:, 1]) > 2.0  # the centroid: pulled up the rod


def test_rays_that_never_leave_the_foreground_add_nothing() -> None:
    # Part of a disc's outline is hidden by a larger foreground region beside it: the fit uses
    # the rest and keeps the centre; with too little of the outline it gives none.
    img = np.zeros((100, 120), np.float32)
    vv, uu = np.mgrid[0:100, 0:120]
    img[np.hypot(uu - 50.3, vv - 49.6) <= 15] = 100.0
    img[38:62, 62:110] = 100.0  # a box touching the disc's right side
    edges = edge_points(img, (0, 0), [Rays(np.array([52.0, 50.0]), 15.0, 22.0)], 20.0)
    assert 0.5 < len(edges.uv) / 24 < 0.95  # the rays towards the box are gone
    fit = fit_disc(edges, 15.0, Calibration.from_scale(1.0, (0.0, 0.0)), 1.0)
    assert fit is not None and np.hypot(*(fit.uv - [50.3, 49.6])) < 0.15
    img[50:, :] = 100.0  # a floor hiding the lower half: too little outline to fit a circle
    edges = edge_points(img, (0, 0), [Rays(np.array([52.0, 50.0]), 15.0, 22.0)], 20.0)
    assert fit_disc(edges, 15.0, Calibration.from_scale(1.0, (0.0, 0.0)), 1.0) is None


def test_a_disc_seen_over_too_little_of_its_outline_is_fitted_with_its_known_radius() -> None:
    # The lower half hidden by a floor: with the radius known from earlier frames, the upper
    # half fixes the centre (0.18 px off, towards the visible edges).
    img = np.zeros((100, 120), np.float32)
    vv, uu = np.mgrid[0:100, 0:120]
    img[np.hypot(uu - 50.3, vv - 49.6) <= 15] = 100.0
    img[50:, :] = 100.0
    edges = edge_points(img, (0, 0), [Rays(np.array([52.0, 50.0]), 15.0, 22.0)], 20.0)
    cal = Calibration.from_scale(1.0, (0.0, 0.0))
    assert fit_disc(edges, 15.0, cal, 1.0) is None
    fit = fit_disc(edges, 15.0, cal, 1.0, known=15.0)
    assert fit is not None and fit.fixed and fit.radius == 15.0
    assert np.hypot(*(fit.uv - [50.3, 49.6])) < 0.25


def test_a_smear_turned_by_a_bounce_is_fitted_along_its_own_direction() -> None:
    # After a bounce the track's last direction of motion is the one before it (on the field
    # camera's bouncing ball, 113 degrees off): a stadium along it fitted a 12 px disc's smear
    # with a radius of 18 px at 3.8 px RMS. The smear's own direction is searched instead.
    from physbench.video.silhouette import fit_discs

    cal = Calibration.from_scale(1.0, (0.0, 0.0))
    centre, radius, half = np.array([60.3, 49.6]), 12.0, 6.0
    way = np.array([np.cos(np.radians(55.0)), np.sin(np.radians(55.0))])
    sub = (np.arange(4) + 0.5) / 4 - 0.5
    vv, uu = np.mgrid[0:100, 0:120].astype(float)
    img = np.zeros((100, 120), np.float32)
    for du in sub:
        for dv in sub:
            q = np.stack([uu + du - centre[0], vv + dv - centre[1]], -1)
            t = np.clip(q @ way, -half, half)
            img += 100.0 / 16 * (np.hypot(*(q - t[..., None] * way).transpose(2, 0, 1)) <= radius)
    start = centre + np.array([1.0, -1.0])
    edges = edge_points(img, (0, 0), [Rays(start, radius, 21.0)], 20.0)
    before = np.radians(-58.0)  # the direction before the bounce, in the image
    ends = cal.to_scene(np.array([centre, centre + np.array([np.cos(before), np.sin(before)])]))
    along = (ends[1] - ends[0]) / np.hypot(*(ends[1] - ends[0]))
    fit = fit_discs(edges, [radius], cal, [1.0], [None], [along])[0]
    assert fit is not None
    assert abs(fit.radius - radius) < 0.5  # 11.9 (18.2 along the old direction)
    assert fit.rms_px < 0.5  # 0.39 (3.8)
    assert np.hypot(*(fit.uv - centre)) < 0.1  # 0.07 px (0.18)


def test_a_coloured_rim_bled_by_coding_is_left_out_of_the_fit() -> None:
    # A yellow ball of 13 px lit from above, H.264 at 4:2:0 (as benchmarks/track_shading.py's
    # wall 2): its colour, stored at half the resolution, bleeds past the rim, most on the lit
    # side, and the centre leaned 0.34 px towards the highlight; with the halo left out, 0.14.
    rng = np.random.default_rng(2)
    plate = wall((240, 320), 2)
    sphere = Sphere(13.0, (0.90, 0.80, 0.10), (0.0, -0.80, 0.60), ambient=0.2, specular=0.7)
    truth = np.array([110.6, 110.2]) + np.outer(np.arange(16), [0.37, 0.21])
    frames = []
    for c in truth:
        img = plate.astype(np.float64)
        paint(img, sphere, [c])
        frames.append(expose(img, rng))
    clean = expose(plate.astype(np.float64), rng, noise=0.0)
    coded = h264_round_trip(np.stack([clean, *frames]), 30.0, 0, 23)
    x, y = CAL.to_scene(truth[0])
    ball = Body("ball", Circle(0.13), (float(x), float(y)), velocity=(0.111, -0.063))
    scene = Scene("s", (ball,), bounds=(0.0, 0.0, 3.2, 2.4), gravity=(0.0, 0.0), frames=16)
    toward = sphere.highlight()
    bias = {}
    for subsampled in (False, True):
        result = track_frames(
            [Frame(k, k / 30, f) for k, f in enumerate(coded[1:])],
            scene.validate(),
            CAL,
            coded[0],
            subsampled=subsampled,
        )
        px = result.pixels["ball"]
        assert len(px) == 16
        bias[subsampled] = float(np.mean((px[:, 1:] - truth) @ toward))
    assert bias[False] > 0.3 and abs(bias[True]) < 0.2


def test_halo_edges_are_kept_where_the_disc_does_not_fit_without_them() -> None:
    from physbench.video.silhouette import Edges, fit_discs

    # Half of a disc's outline is faint (against a wall of its brightness) and taken for a
    # halo: without it too little of the outline is left to fit, so it counts.
    theta = np.arange(24) * (2 * np.pi / 24)
    uv = np.column_stack([50.3 + 15 * np.cos(theta), 49.6 + 15 * np.sin(theta)])
    halo = np.cos(theta) > 0.05
    edges = Edges(uv, theta, np.full(24, 80.0), np.ones(24), np.full(24, 15.0),
                  np.zeros(24, dtype=np.intp), halo)  # fmt: skip
    cal = Calibration.from_scale(1.0, (0.0, 0.0))
    assert fit_discs(edges.select(~halo), [15.0], cal, [1.0], [None])[0] is None
    fit = fit_discs(edges, [15.0], cal, [1.0], [None], halos=True)[0]
    assert fit is not None and np.hypot(*(fit.uv - [50.3, 49.6])) < 0.01
