"""docs/video.md's "your own footage" walkthrough, run as printed on a throw filmed square-on by the
second camera, with a Tracker project (written here in Tracker's format) as the calibration and
as hand marks: the scene from a pixel, tracking, the pixel centres against the hand marks, the
scene's initial state from the tracks."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from PIL import Image

from physbench.cli import main as cli
from physbench.recording import read_recording
from physbench.scene import Body, Circle, Scene
from physbench.scene_toml import load_scene
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.testing.field_camera import FieldCamera
from physbench.tracker_files import read_tracker_project
from physbench.trajectory import Trajectory
from physbench.video.writer import write_clip

#: Square-on, no lens distortion and steady light: Tracker's calibration is a scale and an angle.
#: A flat-lit ball: a lit sphere's centre is pulled from its highlight by the tracker of this
#: branch (0.46 px here; issue 26), which would hide the half pixel this test is about.
SQUARE_ON = {"oblique": 0.0, "k1": 0.0, "k2": 0.0, "drift": 0.0, "roll": 0.0}
FLAT = {"ambient": 1.0, "specular": 0.0}


def _toss() -> tuple[Scene, Trajectory, FieldCamera]:
    """A ball tossed at 30 fps in a 1.6 x 1.2 m view, its motion, and the square-on camera."""
    truth = Scene(
        "toss",
        (Body("ball", Circle(0.04), (0.2, 0.3), velocity=(2.0, 3.0), mass=0.06),),
        bounds=(0.0, 0.0, 1.6, 1.2),
        fps=30.0,
        frames=18,
        substeps=20,
    )
    return truth, PymunkSimulator().simulate(truth), FieldCamera(seed=11, **SQUARE_ON, **FLAT)


def test_the_walkthrough_from_a_clip_and_a_tracker_project(tmp_path, trk, capsys) -> None:  # type: ignore[no-untyped-def]
    truth, traj, cam = _toss()
    write_clip(cam, tmp_path / "clip.mp4", truth, traj)
    Image.fromarray(cam.plate(truth)).save(tmp_path / "plate.png")
    # The project a teacher saved: axes on the scene's origin, a scale, hand marks (Tracker's
    # pixel centres are at .5, so each mark is the true pixel + 0.5, clicked to 0.2 px).
    cal = cam.calibration(truth)
    mpp = cal.metres_per_pixel(cal.to_image([0.8, 0.6]))
    origin = cal.to_image([0.0, 0.0]) + 0.5
    rng = np.random.default_rng(0)
    true_px = cam.image_points(truth, traj.states[:, 0, :2])
    marks = {k: tuple(p + 0.5 + rng.normal(0, 0.2, 2)) for k, p in enumerate(true_px)}
    text = trk(
        origin=tuple(origin), scale=(1 / mpp, 1 / mpp), marks={"ball": marks}, delta_t=1000 / 30
    )
    (tmp_path / "toss.trk").write_text(text)
    project = str(tmp_path / "toss.trk")

    (u0, v0), (u1, v1) = true_px[:2]  # the ball's centre read off the first two frames
    step3 = ["scene", "new", "flight", "--radius", "0.04", "--pixel", str(u0), str(v0)]
    step3 += ["--pixel", str(u1), str(v1)]
    step3 += ["--calibration", project, "--video", str(tmp_path / "clip.mp4")]
    assert cli([*step3, "--out", str(tmp_path / "toss.toml")]) == 0
    scene = load_scene(tmp_path / "toss.toml")
    assert scene.frames == 18 and scene.fps == pytest.approx(30.0)
    assert scene.bodies[0].position == pytest.approx((0.2, 0.3), abs=0.003)
    assert scene.bodies[0].velocity == pytest.approx((2.0, 3.0), rel=0.02)

    step4 = ["track", str(tmp_path / "clip.mp4"), "--scene", str(tmp_path / "toss.toml")]
    step4 += ["--calibration", project, "--background", str(tmp_path / "plate.png")]
    assert cli([*step4, "--out", str(tmp_path / "rec.csv")]) == 0
    with open(tmp_path / "rec.pixels.csv") as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.startswith("#"))][1:]
    tracked = {round(float(t) * 30): (float(a), float(b)) for t, _, a, b in rows}
    hand = read_tracker_project(project).pixels()["ball"]
    gaps = [np.hypot(*(np.array(tracked[k]) - hand[k, 1:])) for k in tracked]
    # measured: 0.56 px at the median, the marks' own 0.2 px per axis with the tracker's 0.47 px
    # from the truth on this smeared ball; half a pixel of convention would add 0.7
    bias = np.mean([np.array(tracked[k]) - hand[k, 1:] for k in tracked], axis=0)
    # measured: no common offset (0.17 px); with Tracker's half pixel taken the wrong way (an
    # earlier tracker): 0.83 px apart, offset by 0.69 px
    assert len(tracked) == 18 and np.median(gaps) < 0.6 and np.hypot(*bias) < 0.25

    step5 = ["scene", "new", "flight", "--radius", "0.04", "--mass", "0.06"]
    assert (
        cli([*step5, "--from", str(tmp_path / "rec.csv"), "--out", str(tmp_path / "toss.toml")])
        == 0
    )
    (ball,) = load_scene(tmp_path / "toss.toml").bodies
    assert ball.velocity == pytest.approx((2.0, 3.0), rel=0.05) and ball.mass == 0.06
    rec = read_recording(tmp_path / "rec.csv")
    assert rec.track("ball").t[0] == 0.0 and "fitted to its first" in capsys.readouterr().out


@pytest.mark.parametrize("kind", ["trz", "images"])
def test_track_follows_a_tracker_projects_own_video_from_its_first_mark(  # type: ignore[no-untyped-def]
    tmp_path, trk, capsys, kind
) -> None:
    """``track PROJECT``: the clip inside a .trz (one of the two projects it holds, named after a
    colon), or the image sequence a .trk names, from the
    frame the teacher's marks start at (where ``scene new --from`` starts the scene), with the
    project's calibration, and the same centres as the hand marks."""
    import zipfile

    truth, traj, cam = _toss()
    cal = cam.calibration(truth)
    mpp = cal.metres_per_pixel(cal.to_image([0.8, 0.6]))
    true_px = cam.image_points(truth, traj.states[:, 0, :2])
    marks = {k: tuple(true_px[k] + 0.5) for k in range(4, 18)}  # marked from frame 4 on
    origin = tuple(cal.to_image([0.0, 0.0]) + 0.5)
    options = {"origin": origin, "scale": (1 / mpp, 1 / mpp), "marks": {"ball": marks}}
    Image.fromarray(cam.plate(truth)).save(tmp_path / "plate.png")
    if kind == "trz":
        write_clip(cam, tmp_path / "clip.mp4", truth, traj)
        project = tmp_path / "toss.trz"
        with zipfile.ZipFile(project, "w") as z:
            z.writestr("toss.trk", trk(**options, delta_t=1000 / 30))
            z.writestr("toss_other.trk", trk(**{**options, "marks": {"ball": {0: (1, 1)}}}))
            z.write(tmp_path / "clip.mp4", "videos/clip.mp4")
        project = tmp_path / "toss.trz:toss.trk"  # the archive holds two projects: name one
    else:
        (tmp_path / "videos").mkdir()
        for k, image in enumerate(cam.exposure(truth, traj)):
            Image.fromarray(image).save(tmp_path / "videos" / f"toss{k + 1:02d}.png")
        Image.fromarray(cam.plate(truth)).save(tmp_path / "videos" / "thumbnail.png")
        project = tmp_path / "toss.trk"
        project.write_text(trk(**options, delta_t=1000 / 30, video="videos/toss01.png"))
    new = ["scene", "new", "flight", "--radius", "0.04", "--from", str(project)]
    assert cli([*new, "--out", str(tmp_path / "toss.toml"), "-q"]) == 0
    track = ["track", str(project), "--scene", str(tmp_path / "toss.toml")]
    track += ["--background", str(tmp_path / "plate.png"), "--out", str(tmp_path / "rec.csv")]
    assert cli(track) == 0
    out = capsys.readouterr().out
    assert "from frame 4 (the first marked), calibrated by the project" in out, out
    with open(tmp_path / "rec.pixels.csv") as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.startswith("#"))][1:]
    tracked = {4 + round(float(t) * 30): (float(a), float(b)) for t, _, a, b in rows}
    assert sorted(tracked) == list(range(4, 18))
    gaps = [np.hypot(*(np.array(tracked[k]) - true_px[k])) for k in tracked]
    assert np.median(gaps) < 0.7  # measured 0.47 px; a frame off would be some 25 px
    rec = read_recording(tmp_path / "rec.csv")
    # t = 0 is frame 4: a frame later would be 67 mm on; the project's scale, a mean over the
    # view, is a few mm off at its edges (measured 5 mm at most)
    np.testing.assert_allclose(rec.track("ball").x, traj.states[4:, 0, 0], atol=0.01)
