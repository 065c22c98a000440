"""Calibration: pixels to metres by a scale, a known body size, or a homography through point
pairs of an oblique view; lens distortion; the TOML file; bad input named."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.calibration import (
    Calibration,
    CalibrationError,
    Lens,
    load_calibration,
    loads_calibration,
)


def oblique_camera() -> np.ndarray:
    """An oblique, perspective view of a 4 x 3 m plane in a 640 x 480 image: the homography
    scene (x, y, 1) -> image (u, v, 1). The plane's rectangle images as a quadrilateral whose far
    side is shorter (foreshortening) and whose sides converge."""
    return np.array([[110.0, 25.0, 90.0], [-12.0, -95.0, 420.0], [0.03, 0.04, 1.0]])


def project(h: np.ndarray, xy: np.ndarray) -> np.ndarray:
    q = np.column_stack([xy, np.ones(len(xy))]) @ h.T
    return q[:, :2] / q[:, 2:]


CORNERS = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]])


def test_four_points_of_an_oblique_view_give_the_exact_homography() -> None:
    h = oblique_camera()
    uv = project(h, CORNERS)
    assert (uv > 0).all() and (uv[:, 0] < 640).all() and (uv[:, 1] < 480).all()
    cal = Calibration.from_points(uv, CORNERS)
    assert cal.reprojection_error < 1e-6
    inside = np.array([[1.0, 0.5], [2.5, 2.0], [3.9, 2.9]])
    np.testing.assert_allclose(cal.to_scene(project(h, inside)), inside, atol=1e-9)
    np.testing.assert_allclose(cal.to_image(inside), project(h, inside), atol=1e-6)


def test_marked_points_with_pixel_noise_fit_within_half_a_pixel() -> None:
    h = oblique_camera()
    rng = np.random.default_rng(0)
    xy = np.array([[x, y] for x in (0.0, 1.0, 2.0, 3.0, 4.0) for y in (0.0, 1.5, 3.0)])
    uv = project(h, xy) + rng.normal(0, 0.3, (len(xy), 2))  # a person clicking to 0.3 px
    cal = Calibration.from_points(uv, xy)
    assert cal.reprojection_error <= 0.5
    truth = np.array([[2.0, 1.0]])
    assert np.linalg.norm(cal.to_scene(project(h, truth)) - truth) < 0.005  # metres


def test_scale_and_body_size_flip_the_image_rows_into_y_up() -> None:
    cal = Calibration.from_scale(0.01, (320, 400))
    np.testing.assert_allclose(cal.to_scene([[320, 400], [420, 300]]), [[0, 0], [1.0, 1.0]])
    np.testing.assert_allclose(cal.to_image([[1.0, 1.0]]), [[420, 300]])
    assert cal.metres_per_pixel((100, 100)) == pytest.approx(0.01)
    ball = Calibration.from_body_size(pixels=22.0, metres=0.066, origin_pixel=(0, 480))
    assert ball.metres_per_pixel((10, 10)) == pytest.approx(0.003)


def test_lens_distortion_round_trips_and_is_undone_before_the_homography() -> None:
    lens = Lens(k1=-0.12, k2=0.02, centre=(320.0, 240.0), focal=800.0)
    pts = np.array([[10.0, 10.0], [320.0, 240.0], [630.0, 470.0], [500.0, 60.0]])
    np.testing.assert_allclose(lens.undistort(lens.distort(pts)), pts, atol=1e-8)
    h = oblique_camera()
    seen = lens.distort(project(h, CORNERS))
    cal = Calibration.from_points(seen, CORNERS, lens=lens)
    inside = np.array([[2.5, 2.0]])
    np.testing.assert_allclose(cal.to_scene(lens.distort(project(h, inside))), inside, atol=1e-8)
    plain = Calibration.from_points(seen, CORNERS)  # ignoring the lens costs real accuracy
    assert np.linalg.norm(plain.to_scene(lens.distort(project(h, inside))) - inside) > 1e-3


def test_toml_files_for_each_way_and_the_exact_round_trip(tmp_path) -> None:  # type: ignore[no-untyped-def]
    h = oblique_camera()
    uv = project(h, CORNERS)
    points = "\n".join(
        f"[[points]]\nimage = [{float(u)!r}, {float(v)!r}]\nscene = [{float(x)!r}, {float(y)!r}]"
        for (u, v), (x, y) in zip(uv, CORNERS, strict=True)
    )
    cal = loads_calibration(points + "\n[lens]\nk1 = 0.0\ncentre = [320, 240]\nfocal = 800\n")
    assert cal.lens is not None and cal.reprojection_error < 1e-6
    path = tmp_path / "cal.toml"
    path.write_text(cal.to_toml())
    back = load_calibration(path)
    np.testing.assert_array_equal(back.homography, cal.homography)
    assert back.lens == cal.lens and back.source == str(path)
    scale = loads_calibration("[scale]\nmetres_per_pixel = 0.002\norigin_pixel = [0, 480]\n")
    assert scale.metres_per_pixel((1, 1)) == pytest.approx(0.002)
    body = loads_calibration("[body]\npixels = 40\nmetres = 0.2\norigin_pixel = [0, 0]\n")
    assert body.metres_per_pixel((1, 1)) == pytest.approx(0.005)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "exactly one of [scale], [[points]], [body] or [homography], got none"),
        ("[scale]\nmetres_per_pixel = 0\norigin_pixel = [0, 0]", "metres_per_pixel = 0: expected"),
        (
            "[scale]\nmetres_per_pixel = 1\norigin_pixel = [0]",
            "origin_pixel = [0]: expected a pair",
        ),
        ("[scale]\nmetres = 1", "scale.metres: unknown key; known: metres_per_pixel, origin_pixel"),
        ("[zoom]\nx = 1", "zoom: unknown key"),
        ("[[points]]\nimage = [0, 0]\nscene = [0, 0]", "1 pairs given; a plane homography needs"),
        ("[lens]\nk1 = 0.1\n[scale]\nmetres_per_pixel = 1\norigin_pixel = [0, 0]", "lens: missing"),
        ("[scale", "not valid TOML"),
    ],
)
def test_bad_calibrations_are_named(text: str, message: str) -> None:
    with pytest.raises(CalibrationError, match=message.replace("[", r"\[").replace("]", r"\]")):
        loads_calibration(text)


def test_collinear_or_too_few_points_cannot_fix_the_plane(tmp_path) -> None:  # type: ignore[no-untyped-def]
    line = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])
    with pytest.raises(CalibrationError, match=r"scene points .* lie on one line"):
        Calibration.from_points(project(oblique_camera(), line), line)
    good = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(CalibrationError, match=r"image points .* lie on one line"):
        Calibration.from_points(line * 10, good)
    with pytest.raises(CalibrationError, match="pairs of"):
        Calibration.from_points(good, good[:3])
    with pytest.raises(CalibrationError, match="does not exist"):
        load_calibration(tmp_path / "missing.toml")
    (tmp_path / "latin1.toml").write_bytes(b"# \xe9\n")
    with pytest.raises(CalibrationError, match="cannot read as UTF-8"):
        load_calibration(tmp_path / "latin1.toml")


def test_a_csv_of_point_pairs_is_the_points_calibration(tmp_path) -> None:  # type: ignore[no-untyped-def]
    h = oblique_camera()
    xy = np.vstack([CORNERS, [[2.0, 1.5], [1.0, 2.5]]])
    uv = project(h, xy)
    rows = [
        ",".join(repr(float(c)) for c in (x, y, u, v))
        for (u, v), (x, y) in zip(uv, xy, strict=True)
    ]
    path = tmp_path / "points.csv"
    path.write_text("# measured in an image viewer\nx,y,u,v\n" + "\n".join(rows) + "\n")
    cal = load_calibration(path)
    toml = Calibration.from_points(uv, xy)
    np.testing.assert_allclose(cal.homography, toml.homography, rtol=1e-9, atol=1e-12)
    assert cal.reprojection_error < 1e-6 and cal.source == str(path)
    assert np.allclose(cal.to_scene(uv), xy, atol=1e-9)
    for text, message in [
        ("u,v,x\n1,2,3\n", "expected the columns u, v, x, y"),
        ("u,v,x,y\n1,2,3\n", "line 2: 3 values"),
        ("u,v,x,y\n1,2,3,a\n", "not a number"),
        ("u,v,x,y\n0,0,0,0\n1,0,1,0\n0,1,0,1\n", "3 pairs given"),
        ("", "empty"),
    ]:
        path.write_text(text)
        with pytest.raises(CalibrationError, match=message):
            load_calibration(path)
