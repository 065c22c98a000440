"""``physbench scene new`` and a teacher's Tracker project through ``physbench discover``: the
hand marks of a throw with drag, saved in Tracker's format (centimetres, tilted axes), give the
scene from a few answers and then the drag."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from physbench.cli import main as cli
from physbench.effects import LinearDrag
from physbench.errors import PhysbenchWarning
from physbench.scene import Body, Circle, Scene
from physbench.scene_toml import load_scene
from physbench.simulators.pymunk_sim import PymunkSimulator

ORIGIN, ANGLE, SCALE = (80.5, 400.5), 1.5, (2.2, 2.2)  # px, degrees, px per cm


@pytest.fixture
def throw(tmp_path, trk, trk_image):  # type: ignore[no-untyped-def]
    """A ball thrown with linear drag, marked by hand (0.2 px of jitter) in every other frame of
    a 30 fps clip, saved as a .trz."""
    scene = Scene(
        "throw",
        (Body("ball", Circle(0.03), (0.0, 0.0), velocity=(2.4, 3.6), mass=0.5),),
        bounds=(-1.0, -1.0, 3.0, 2.0),
        fps=15.0,
        frames=14,
        substeps=40,
    )
    traj = PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.6)])
    rng = np.random.default_rng(3)
    marks = {}
    for k, (x, y) in enumerate(traj.states[:, 0, :2]):
        u, v = trk_image((100 * x, 100 * y), ORIGIN, ANGLE, SCALE)  # cm
        marks[5 + 2 * k] = (u + rng.normal(0, 0.2), v + rng.normal(0, 0.2))
    text = trk(
        origin=ORIGIN,
        angle=ANGLE,
        scale=SCALE,
        unit="cm",
        marks={"ball": marks},
        mass=500.0,
        mass_unit="g",
        start_frame=5,
        delta_t=1000 / 30,
    )
    path = tmp_path / "throw.trz"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("throw_throw.trk", text)
    return path, traj


def test_a_tracker_project_gives_the_scene_and_its_drag(tmp_path, throw, capsys) -> None:  # type: ignore[no-untyped-def]
    path, traj = throw
    scene_file = tmp_path / "s.toml"
    assert (
        cli(
            [
                "scene",
                "new",
                "flight",
                "--radius",
                "0.03",
                "--from",
                str(path),
                "--out",
                str(scene_file),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "mass 0.5 kg from the Tracker project" in out and "first 5 samples" in out
    scene = load_scene(scene_file)
    (ball,) = scene.bodies
    assert scene.fps == pytest.approx(15.0) and scene.frames == 14  # every other frame at 30 fps
    # a starting guess (the fit leaves out the drag it is meant to find): discover refits it
    assert ball.position == pytest.approx((0.0, 0.0), abs=0.02)
    assert ball.velocity == pytest.approx(tuple(traj.states[0, 0, 3:5]), rel=0.1)
    verdict = tmp_path / "v.json"
    argv = ["discover", str(path), "--scene", str(scene_file), "-q", "--out", str(verdict)]
    assert cli([*argv, "--effects", "linear_drag", "quadratic_drag", "constant_force"]) == 0
    found = json.loads(verdict.read_text())
    assert found["causes"] == ["linear_drag"]
    (chosen,) = [c for c in found["candidates"] if c["chosen"]]
    assert chosen["name"] == "linear_drag" and chosen["params"]["c"] == pytest.approx(0.6, rel=0.1)


def test_answers_without_a_recording(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    cal = tmp_path / "cal.toml"
    cal.write_text("[scale]\nmetres_per_pixel = 0.002\norigin_pixel = [100, 400]\n")
    out = tmp_path / "p.toml"
    argv = ["scene", "new", "pendulum", "--radius", "0.02", "--pixel", "250", "150"]
    argv += ["--calibration", str(cal), "--pivot", "0.3", "0.9", "--fps", "60", "--frames", "90"]
    assert cli([*argv, "--out", str(out)]) == 0
    scene = load_scene(out)
    assert scene.bodies[0].position == pytest.approx((0.3, 0.5))
    assert scene.joints[0].anchor == (0.3, 0.9) and scene.gravity == (0.0, -9.81)
    assert "starts at rest" in capsys.readouterr().out
    bad = [
        (["scene", "new", "puck", "--radius", "0.02", "--out", str(out)], "frame rate is unknown"),
        (
            ["scene", "new", "puck", "--radius", "0.02", "--pixel", "1", "2", "--out", str(out)],
            "--pixel needs --calibration",
        ),
    ]
    for argv, message in bad:
        assert cli(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("physbench scene: error:") and message in err, err


def test_a_folder_of_images_is_a_video_with_the_frame_rate_given(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    from PIL import Image

    folder = tmp_path / "frames"
    folder.mkdir()
    for k in range(6):
        Image.new("RGB", (80, 60), (90, 90, 90)).save(folder / f"f{k:02d}.png")
    cal = tmp_path / "cal.toml"
    cal.write_text("[scale]\nmetres_per_pixel = 0.01\norigin_pixel = [0, 59]\n")
    out = tmp_path / "f.toml"
    argv = ["scene", "new", "flight", "--radius", "0.02", "--video", str(folder)]
    argv += ["--calibration", str(cal), "--pixel", "40", "30", "--out", str(out)]
    assert cli(argv) == 2
    err = capsys.readouterr().err
    assert "is a folder of images" in err and "--fps" in err, err
    assert cli([*argv, "--fps", "12"]) == 0
    scene = load_scene(out)
    assert scene.fps == 12 and scene.frames == 6
    assert scene.bounds == pytest.approx((-0.005, -0.005, 0.795, 0.595))


def test_discover_names_a_track_the_scene_lacks(tmp_path, throw, capsys) -> None:  # type: ignore[no-untyped-def]
    path, _ = throw
    scene_file = tmp_path / "s.toml"
    assert (
        cli(
            [
                "scene",
                "new",
                "flight",
                "--radius",
                "0.03",
                "--from",
                str(path),
                "--body",
                "ball",
                "--out",
                str(scene_file),
            ]
        )
        == 0
    )
    scene_file.write_text(scene_file.read_text().replace('name = "ball"', 'name = "stone"'))
    capsys.readouterr()
    assert cli(["discover", str(path), "--scene", str(scene_file)]) == 2
    err = capsys.readouterr().err
    assert "no Tracker track is a body of scene" in err
    assert "tracks: 'ball'; bodies: stone" in err


def test_a_project_with_more_tracks_than_the_scene_keeps_the_scenes(tmp_path, trk) -> None:  # type: ignore[no-untyped-def]
    """A project that marks more than the scene models (both ends of a spinning diabolo, a
    second ball) gives the tracks named after the scene's bodies, and says which it left out."""
    from physbench.discover.data import load_runs

    ball = {5 + 2 * k: (100.0 + 3 * k, 200.0 - 2 * k) for k in range(10)}
    hand = {5 + 2 * k: (300.0, 100.0 + k) for k in range(10)}
    text = trk(
        origin=ORIGIN, angle=ANGLE, scale=SCALE, unit="cm", marks={"ball": ball, "hand": hand}
    )
    two = tmp_path / "two.trk"
    two.write_text(text)
    scene = Scene("throw", (Body("ball", Circle(0.03), (1.0, 1.0)),), fps=15.0, frames=14)
    with pytest.warns(PhysbenchWarning, match="Tracker track 'hand' left out: not a body of scene"):
        (run,) = load_runs(two, scene)
    assert run.recording is not None
    assert run.recording.bodies == ("ball",)
    assert len(run.recording.track("ball").t) == 10
