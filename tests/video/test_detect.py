"""Detection: anti-aliased discs give sub-pixel centres, touching discs split at their contact,
and moments give a long axis and a square's sides."""

from __future__ import annotations

import math

import numpy as np

from physbench.video.detect import Outline, find_blobs, split_blob


def disc(img: np.ndarray, u: float, v: float, r: float, level: float = 200.0) -> None:
    """Add an anti-aliased disc (4x4 supersampled coverage) to ``img``."""
    h, w = img.shape
    off = (np.arange(4) + 0.5) / 4 - 0.5
    vv, uu = np.mgrid[0:h, 0:w].astype(float)
    cov = np.zeros_like(img)
    for a in off:
        for b in off:
            cov += np.hypot(uu + a - u, vv + b - v) <= r
    img += level * cov / 16


def test_a_disc_centre_is_found_to_a_twentieth_of_a_pixel() -> None:
    for u, v in [(30.0, 20.0), (30.37, 19.81), (31.5, 22.25)]:
        img = np.zeros((48, 64))
        disc(img, u, v, 9.3)
        ((blob, *_),) = find_blobs(img, 20.0, 100.0)
        assert abs(blob.u - u) < 0.05 and abs(blob.v - v) < 0.05  # 4x4-sampled edges
        assert abs(blob.area - math.pi * 9.3**2) < 0.08 * math.pi * 9.3**2  # edges count from 0.6
        assert blob.elongation < 1.05


def test_touching_discs_split_at_their_contact() -> None:
    img = np.zeros((48, 80))
    disc(img, 30.2, 24.4, 10.0)
    disc(img, 50.3, 23.6, 10.0)
    blobs = find_blobs(np.minimum(img, 200), 20.0, 100.0, offset=(5, 7))
    assert len(blobs) == 1  # one blob for both
    _, u, v, w = blobs[0]
    guess = np.array([[28.0 + 7, 26.0 + 5], [52.0 + 7, 22.0 + 5]])  # a few px off
    a, b = split_blob(u, v, w, guess, [Outline(10.0), Outline(10.0)])
    assert np.hypot(a.u - 37.2, a.v - 29.4) < 0.3 and np.hypot(b.u - 57.3, b.v - 28.6) < 0.3


def test_moments_give_the_long_axis_and_a_squares_sides() -> None:
    vv, uu = np.mgrid[0:60, 0:60].astype(float)
    for angle in (0.2, -0.6, 1.1):
        c, s = math.cos(angle), math.sin(angle)
        lu, lv = c * (uu - 30) + s * (vv - 30), -s * (uu - 30) + c * (vv - 30)
        bar = 200.0 * ((np.abs(lu) < 15) & (np.abs(lv) < 4))
        ((blob, *_),) = find_blobs(bar, 20.0, 100.0)
        assert abs(blob.axis - angle) < 0.02 and blob.elongation > 5
        square = 200.0 * ((np.abs(lu) < 10) & (np.abs(lv) < 10))
        ((blob, *_),) = find_blobs(square, 20.0, 100.0)
        assert abs((blob.square - angle + math.pi / 4) % (math.pi / 2) - math.pi / 4) < 0.03


def test_a_long_body_seen_obliquely_is_measured_on_the_plane() -> None:
    from physbench.calibration import Calibration
    from physbench.video.detect import blob_from_pixels, plane_pose

    # A steep view: the far side of the plane is squeezed (points of a 4 m x 3 m board).
    scene = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]])
    image = np.array([[40.0, 460.0], [600.0, 460.0], [470.0, 60.0], [170.0, 60.0]])
    cal = Calibration.from_points(image, scene)
    # A 2.4 m x 0.2 m plank at 60 degrees, centred at (2, 1.5): the pixels it covers.
    vv, uu = np.mgrid[0:480, 0:640].astype(float) + 0.5
    xy = cal.to_scene(np.column_stack([uu.ravel(), vv.ravel()]))
    a = math.radians(60)
    along = (xy[:, 0] - 2) * math.cos(a) + (xy[:, 1] - 1.5) * math.sin(a)
    across = -(xy[:, 0] - 2) * math.sin(a) + (xy[:, 1] - 1.5) * math.cos(a)
    inside = (np.abs(along) <= 1.2) & (np.abs(across) <= 0.1)
    u, v = uu.ravel()[inside], vv.ravel()[inside]
    w = np.ones(u.size)
    pose = plane_pose(u, v, w, cal)
    assert np.hypot(*(pose.xy - [2.0, 1.5])) < 0.005 and abs(pose.axis - a) < 0.002  # 0.7 mm
    # Taken in the image and mapped, the centre is 33 cm off (the near end looks bigger).
    naive = cal.to_scene(blob_from_pixels(u, v, w).centre)
    assert np.hypot(*(naive - [2.0, 1.5])) > 0.03


def test_blobs_pixels_and_moments_are_numpys() -> None:
    """The compiled pass after labelling gives what NumPy gives: each blob's pixels in
    row-major order with :func:`coverage`, blobs in label order then by area, small ones
    dropped, and :func:`blob_from_pixels`' moments."""
    from scipy import ndimage

    from physbench.video.detect import CROSS, blob_from_pixels, coverage

    rng = np.random.default_rng(3)
    img = np.zeros((70, 90))
    for u, v, r in [(25.3, 30.1, 18.0), (70.2, 20.4, 6.0), (68.0, 55.0, 9.5)]:
        disc(img, u, v, r)
    specks = img + 25 * rng.random(img.shape)  # just above the threshold: blobs to drop
    # One blob of 6,300 px, most of them covered by 1e-8: summed in another order than
    # w.sum()'s, its area differs (by 4e-12).
    faint = img + 20 + 1e-4 * rng.random(img.shape)
    for diff in (specks, np.minimum(specks, 255).astype(np.uint8), faint):
        labels, n = ndimage.label(diff > 20.0, CROSS)
        want = []
        for label in range(1, n + 1):
            rows, cols = np.nonzero(labels == label)
            w = coverage(diff[rows, cols], 20.0, 250.0).astype(np.float64)
            if w.sum() >= 3.0:
                u, v = (cols + 9).astype(np.float64), (rows + 4).astype(np.float64)
                want.append((blob_from_pixels(u, v, w), u, v, w))
        want.sort(key=lambda b: -b[0].area)
        got = find_blobs(diff, 20.0, 250.0, offset=(4, 9), min_area=3.0)
        assert len(got) == len(want) == (1 if diff is faint else 3)
        assert n == 1 if diff is faint else n > 400  # hundreds of specks dropped
        for (blob, *pixels), (ref, *ref_pixels) in zip(got, want, strict=True):
            for a, b in zip(pixels, ref_pixels, strict=True):
                assert a.dtype == np.float64 and np.array_equal(a, b)
            assert blob.area == ref.area and blob.count == ref.count  # the same pairwise sum
            # The moments are BLAS dot products (NumPy's and SciPy's BLAS may differ in the
            # last bits).
            for field in ("u", "v", "axis", "elongation", "square"):
                got_, want_ = getattr(blob, field), getattr(ref, field)
                assert math.isclose(got_, want_, rel_tol=1e-9, abs_tol=1e-9)


def test_blobs_are_labelled_as_scipy_labels_them() -> None:
    from scipy import ndimage

    from physbench.video.detect import CROSS, label

    rng = np.random.default_rng(5)
    shapes = [(1, 1), (1, 9), (9, 1), (2, 2), (40, 31), (64, 64)]
    for k in range(600):
        h, w = shapes[k % len(shapes)] if k < 60 else rng.integers(1, 70, 2)
        mask = rng.random((h, w)) < rng.random()
        if k % 7 == 0:  # a spiral and a comb: blobs joined late in the scan
            mask = np.zeros((h, w), bool)
            mask[::2] = True
            mask[:, :: max(1, w - 1)] = True
        want, n = ndimage.label(mask, CROSS)
        got, m = label(mask)
        assert m == n and np.array_equal(got, want), (h, w)
