"""Tracker project files (``physbench/tracker_files.py``): the calibration (origin, axis angle in
degrees, scale and length unit, Tracker's pixel centres at .5) and the hand-marked points as a
recording, on projects written here in Tracker's XML layout (no third-party files)."""

from __future__ import annotations

import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

from physbench.calibration import load_calibration
from physbench.errors import PhysbenchWarning
from physbench.tracker_files import (
    MARK_ACCURACY_PX,
    PIXEL_OFFSET,
    TrackerFileError,
    parse_tracker_xml,
    read_tracker_project,
    tracker_path,
)

ORIGIN, ANGLE, SCALE = (212.5, 301.25), 30.0, (150.0, 150.0)  # px, degrees, px per cm
#: A throw in cm (Tracker's world units here), one point per frame from frame 3.
WORLD = {n: (10.0 * (n - 3), 40.0 * (n - 3) / 10 - 4.9 * ((n - 3) / 10) ** 2) for n in range(3, 12)}


def project(trk, trk_image, tmp_path: Path, name: str = "toss.trk", **options) -> Path:  # type: ignore[no-untyped-def]
    marks = {n: trk_image(xy, ORIGIN, ANGLE, SCALE) for n, xy in WORLD.items()}
    kw = {
        "origin": ORIGIN,
        "angle": ANGLE,
        "scale": SCALE,
        "unit": "cm",
        "marks": {"ball": marks},
        "start_frame": 2,
        "start_time": 500.0,
        "delta_t": 100.0,
        **options,
    }
    path = tmp_path / name
    path.write_text(trk(**kw), encoding="utf-8")
    return path


def test_marks_become_metres_and_seconds_from_the_first_marked_frame(
    trk, trk_image, tmp_path
) -> None:  # type: ignore[no-untyped-def]
    p = read_tracker_project(project(trk, trk_image, tmp_path))
    assert p.angle == ANGLE and p.unit == "cm" and p.metres_per_unit == 0.01
    rec = p.recording()
    tr = rec.track("ball")
    want = np.array([WORLD[n] for n in sorted(WORLD)]) * 0.01
    assert np.allclose(np.column_stack([tr.x, tr.y]), want, atol=1e-12)
    # frame 3 is 0.6 s on Tracker's clock (500 ms + (3 - 2) x 100 ms): recording time 0
    assert p.t0 == pytest.approx(0.6)
    assert np.allclose(tr.t, 0.1 * np.arange(len(WORLD)))
    assert rec.fields == ("x", "y") and rec.bodies == ("ball",)  # the model particle is not read
    assert rec.accuracy == pytest.approx(MARK_ACCURACY_PX * 0.01 / 150.0)


def test_the_angle_is_read_in_degrees(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    # A point on the world's x axis at 1 unit: at 90 degrees Tracker draws it straight up.
    path = tmp_path / "up.trk"
    up = trk_image((1.0, 0.0), (50.0, 50.0), 90.0, (10.0, 10.0))
    assert up == pytest.approx((50.0, 40.0))
    path.write_text(
        trk(origin=(50.0, 50.0), angle=90.0, scale=(10.0, 10.0), marks={"b": {0: up, 1: (50, 50)}})
    )
    tr = read_tracker_project(path).recording().track("b")
    assert (tr.x[0], tr.y[0]) == pytest.approx((1.0, 0.0))  # radians would give (0.45, -0.89)


def test_pixel_centres_are_shifted_by_half_a_pixel(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Tracker draws pixel (i, j) over [i, i + 1) x [j, j + 1): a person who puts the origin on the
    centre of pixel (120, 80) gets xorigin = 120.5, yorigin = 80.5. physbench's pixel (120, 80) is
    then the scene's origin, and one pixel to its right is one scale step along x."""
    assert PIXEL_OFFSET == 0.5
    path = tmp_path / "px.trk"
    path.write_text(trk(origin=(120.5, 80.5), scale=(100.0, 100.0), marks={"b": {0: (0, 0)}}))
    cal = load_calibration(path)
    assert cal.to_scene([120.0, 80.0]) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert cal.to_scene([121.0, 79.0]) == pytest.approx((0.01, 0.01), abs=1e-12)
    assert cal.to_image([0.0, 0.0]) == pytest.approx((120.0, 80.0), abs=1e-12)
    # and a mark on that pixel's centre is the origin in the recording
    path.write_text(
        trk(origin=(120.5, 80.5), scale=(100.0, 100.0), marks={"b": {0: (120.5, 80.5)}})
    )
    tr = read_tracker_project(path).recording().track("b")
    assert (tr.x[0], tr.y[0]) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert read_tracker_project(path).pixels()["b"][0].tolist() == [0.0, 120.0, 80.0]


def test_calibration_and_marks_agree_through_physbench_pixels(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = project(trk, trk_image, tmp_path)
    p = read_tracker_project(path)
    cal = load_calibration(path)
    rec = p.recording().track("ball")
    uv = p.pixels()["ball"][:, 1:]
    assert np.allclose(cal.to_scene(uv), np.column_stack([rec.x, rec.y]), atol=1e-12)
    assert cal.reprojection_error == 0.0 and "toss.trk" in cal.source


def test_a_trz_archive_holds_the_project(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    trk_path = project(trk, trk_image, tmp_path)
    trz = tmp_path / "toss.trz"
    with zipfile.ZipFile(trz, "w") as z:
        z.write(trk_path, "toss_toss.trk")
        z.writestr("toss_thumbnail.png", b"\x89PNG")
    from_trz = read_tracker_project(trz).recording().track("ball")
    from_trk = read_tracker_project(trk_path).recording().track("ball")
    assert np.array_equal(from_trz.x, from_trk.x) and np.array_equal(from_trz.t, from_trk.t)
    assert np.allclose(load_calibration(trz).homography, load_calibration(trk_path).homography)
    later = project(trk, trk_image, tmp_path, "later.trk", start_frame=0)
    with zipfile.ZipFile(trz, "a") as z:
        z.write(later, "runs/second.trk")
    with pytest.raises(TrackerFileError, match=r"holds 2 Tracker projects.*runs/second\.trk.*"
                       r"name one after a colon, as in '.*toss\.trz:toss_toss\.trk'"):  # fmt: skip
        read_tracker_project(trz)
    assert read_tracker_project(trz, member="runs/second.trk").start_frame == 0
    # ARCHIVE.trz:PROJECT names one, by its path in the archive or its file name, wherever a
    # project is read (the calibration too); a wrong name lists what the archive holds
    assert read_tracker_project(f"{trz}:second.trk").start_frame == 0
    assert read_tracker_project(f"{trz}:toss_toss.trk").start_frame == 2
    assert load_calibration(f"{trz}:second.trk").source == f"{trz}:runs/second.trk"
    with pytest.raises(TrackerFileError, match=r"no project 'third\.trk' in it; it holds"):
        read_tracker_project(f"{trz}:third.trk")
    assert tracker_path(f"{trz}:runs/second.trk") == (trz, "runs/second.trk")
    assert tracker_path(trk_path) == (trk_path, None)


def test_units_masses_and_a_missing_unit(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    p = read_tracker_project(
        project(trk, trk_image, tmp_path, unit="ft", mass=250.0, mass_unit="g")
    )
    assert p.metres_per_unit == 0.3048 and p.marks["ball"].mass == pytest.approx(0.25)
    with pytest.warns(PhysbenchWarning, match=r"toss\.trk: length_unit not stated: taken as m"):
        p = read_tracker_project(project(trk, trk_image, tmp_path, unit=None))
    assert p.metres_per_unit == 1.0 and any("taken as m" in n for n in p.notes)
    with pytest.raises(TrackerFileError, match="length_unit = 'furlong'"):
        read_tracker_project(project(trk, trk_image, tmp_path, unit="furlong"))


def test_what_cannot_be_read_is_named(trk, trk_image, tmp_path) -> None:  # type: ignore[no-untyped-def]
    moving = {0: (*ORIGIN, ANGLE, *SCALE), 5: (ORIGIN[0] + 3, ORIGIN[1], ANGLE, *SCALE)}
    with pytest.raises(TrackerFileError, match="changes at frame 5"):
        read_tracker_project(project(trk, trk_image, tmp_path, coords_frames=moving))
    # a key frame that repeats frame 0 is not a change
    same = {0: (*ORIGIN, ANGLE, *SCALE), 5: (*ORIGIN, ANGLE, *SCALE)}
    read_tracker_project(project(trk, trk_image, tmp_path, coords_frames=same))
    filtered = read_tracker_project(
        project(trk, trk_image, tmp_path, filters=("PerspectiveFilter",))
    )
    assert len(filtered.recording().track("ball")) == len(WORLD)  # marks and axes share a picture
    with pytest.raises(TrackerFileError, match="PerspectiveFilter"):
        filtered.homography()
    with pytest.raises(TrackerFileError, match="no point-mass track"):
        read_tracker_project(project(trk, trk_image, tmp_path, marks={})).recording()
    with pytest.raises(TrackerFileError, match="TrackerPanel"):
        parse_tracker_xml('<object class="java.awt.Color"/>')
    with pytest.raises(TrackerFileError, match="not readable as XML"):
        parse_tracker_xml("<object")
    (tmp_path / "junk.trz").write_bytes(b"not a zip")
    with pytest.raises(TrackerFileError, match="not a zip archive"):
        read_tracker_project(tmp_path / "junk.trz")
    with pytest.raises(TrackerFileError, match="does not exist"):
        read_tracker_project(tmp_path / "none.trk")
    assert math.isfinite(read_tracker_project(project(trk, trk_image, tmp_path)).t0)


def test_a_centre_of_mass_track_is_the_mass_weighted_mean_of_its_points(  # type: ignore[no-untyped-def]
    trk, trk_image, tmp_path
) -> None:
    """Both ends of a spinning bar marked (1 g and 3 g, the light end from frame 3, the heavy
    from frame 5), and Tracker's centre of mass of the two: read as a track of its own, where
    both ends are marked, at the bar's balance point, weighing 4 g."""
    spin = {n: (0.0 + 5 * math.cos(n), 50.0 + 5 * math.sin(n)) for n in range(3, 12)}
    light = {n: (WORLD[n][0] + 3 * dx, WORLD[n][1] + 3 * dy) for n, (dx, dy) in spin.items()}
    heavy = {n: (WORLD[n][0] - dx, WORLD[n][1] - dy) for n, (dx, dy) in spin.items() if n >= 5}
    marks = {
        name: {n: trk_image(xy, ORIGIN, ANGLE, SCALE) for n, xy in pts.items()}
        for name, pts in (("light end", light), ("heavy end", heavy))
    }
    options = {"marks": marks, "mass_unit": "g", "masses": {"light end": 1.0, "heavy end": 3.0}}
    p = read_tracker_project(
        project(trk, trk_image, tmp_path, centres={"cm": ["light end", "heavy end"]}, **options)
    )
    assert list(p.marks["cm"].frames) == list(range(5, 12))
    assert p.marks["cm"].mass == pytest.approx(0.004)
    cm = p.recording().track("cm")
    want = np.array([WORLD[n] for n in range(5, 12)]) / 100  # cm -> m: the bar's middle
    assert np.allclose(np.column_stack([cm.x, cm.y]), want, atol=1e-9)
    assert cm.t[0] == pytest.approx(0.2)  # frame 5, two frames after the first mark (frame 3)
    # An end with no mass stated weighs Tracker's default, 1 (here 1 g): the plain mean.
    p = read_tracker_project(
        project(
            trk,
            trk_image,
            tmp_path,
            centres={"cm": ["light end", "heavy end"]},
            **{**options, "masses": {"light end": 1.0, "heavy end": None}},
        )
    )
    plain = (np.array([light[n] for n in range(5, 12)]) + [heavy[n] for n in range(5, 12)]) / 2
    cm = p.recording().track("cm")
    assert np.allclose(np.column_stack([cm.x, cm.y]), plain / 100, atol=1e-9)
    # One that names no marked point mass shows no point in Tracker: left out, and said.
    with pytest.warns(PhysbenchWarning, match="'cm' left out"):
        p = read_tracker_project(
            project(trk, trk_image, tmp_path, centres={"cm": ["tip"]}, **options)
        )
    assert "cm" not in p.marks and "light end" in p.marks
    assert any("'cm' left out: it names 'tip', not a marked point mass" in n for n in p.notes)
    with pytest.raises(TrackerFileError, match="two tracks are named 'light end'"):
        read_tracker_project(
            project(trk, trk_image, tmp_path, centres={"light end": ["heavy end"]}, **options)
        )
