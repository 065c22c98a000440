"""``physbench run`` fits scene-level unknowns: g from a camera's video of a ball toss, a drag
coefficient from a drag flight, and the flags' errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from physbench.cli import main

TOSS = """
name = "toss"
bounds = [0.0, 0.0, 4.0, 3.0]
fps = 30.0
frames = 30

[[bodies]]
name = "ball"
shape = { kind = "circle", radius = 0.1 }
position = [0.5, 0.5]
velocity = [2.5, 5.0]
mass = 0.2
"""


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["run", *argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def toss(tmp_path: Path) -> Path:
    path = tmp_path / "toss.toml"
    path.write_text(TOSS, encoding="utf-8")
    return path


def best(history_json: Path) -> dict[str, float]:
    h = json.loads(history_json.read_text(encoding="utf-8"))
    return h["iterations"][h["iterations"][-1]["best_iteration"]]["params"]


@pytest.fixture(scope="module")
def filmed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """A 1 s ball toss filmed by a phone on a tripod, a little oblique: motion blur, noise, H.264;
    the scene file, the clip and the four corners of the bounds (scene metres) with the pixels a
    user clicks for them."""
    from physbench.components import create
    from physbench.render.camera import CameraRenderer
    from physbench.scene_toml import load_scene
    from physbench.video.writer import write_clip

    tmp = tmp_path_factory.mktemp("toss")
    (tmp / "toss.toml").write_text(TOSS, encoding="utf-8")
    scene = load_scene(tmp / "toss.toml")
    camera = CameraRenderer(
        640, tilt=12.0, shutter=0.5, subframes=8, noise=0.02, bitrate=1_500_000, seed=3
    )
    write_clip(camera, tmp / "toss.mp4", scene, create("simulator", "pymunk").simulate(scene))
    np.save(tmp / "corners.npy", camera.image_points(scene, CORNERS))
    return tmp / "toss.toml", tmp / "toss.mp4", tmp / "corners.npy"


CORNERS = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]])


def calibrate(pixels: Path, out: Path, *, metre: float = 1.0) -> Path:
    """A four-point calibration from the corners' pixels whose metre is ``metre`` true metres."""
    from physbench.calibration import Calibration

    out.write_text(Calibration.from_points(np.load(pixels), CORNERS / metre).to_toml())
    return out


def test_a_filmed_ball_toss_gives_g(
    capsys: pytest.CaptureFixture[str], filmed: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    toss, clip, pixels = filmed
    code, out, _ = run(
        capsys,
        *("--video", str(clip), "--scene", str(toss)),
        *("--calibration", str(calibrate(pixels, tmp_path / "cal.toml"))),
        *("--params", "gravity", "--iterations", "30", "--out", str(tmp_path / "h.json"), "-q"),
    )
    assert code == 0 and "no truth: observation from" in out
    g = -best(tmp_path / "h.json")["gravity"]
    assert abs(g / 9.81 - 1) < 0.01, g


def test_a_calibration_off_by_five_per_cent_is_measured_by_the_camera_scale(
    capsys: pytest.CaptureFixture[str], filmed: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    toss, clip, pixels = filmed
    # What this calibration calls 1 m is truly 1.05 m.
    cal = calibrate(pixels, tmp_path / "cal.toml", metre=1.05)
    code, _, _ = run(
        capsys,
        *("--video", str(clip), "--scene", str(toss), "--calibration", str(cal)),
        *("--params", "camera.scale", "--iterations", "30", "--out", str(tmp_path / "h.json")),
        "-q",
    )
    assert code == 0
    scale = best(tmp_path / "h.json")["camera.scale"]
    assert abs(scale / 1.05 - 1) < 0.005, scale


def test_the_drag_key_gives_the_drag_of_a_drag_flight(
    capsys: pytest.CaptureFixture[str], toss: Path, tmp_path: Path
) -> None:
    obs = tmp_path / "flight.npz"
    simulate = ["simulate", "--scene", str(toss), "--effect", "linear_drag:c=0.1", "--out"]
    assert main([*simulate, str(obs), "-q"]) == 0
    capsys.readouterr()
    code, out, err = run(
        capsys,
        *("--observation", str(obs), "--effect", "linear_drag"),
        *("--params", "linear_drag.c=0:0.5", "--iterations", "30"),
        *("--out", str(tmp_path / "h.json"), "-q"),
    )
    assert code == 0, err
    # The file states the scene and engine, not the effect's value: image MSE only, said so.
    assert "does not state the true linear_drag.c" in err and "no truth" in out
    c = best(tmp_path / "h.json")["linear_drag.c"]
    assert abs(c / 0.1 - 1) < 0.1, c


def test_scene_level_unknowns_have_a_truth_in_a_simulated_run(
    capsys: pytest.CaptureFixture[str], toss: Path
) -> None:
    code, out, _ = run(
        capsys,
        *("--scene", str(toss), "--params", "gravity=-11:-9", "camera.scale"),
        *("--iterations", "3", "--resolution", "32", "--json", "-q"),
    )
    h = json.loads(out)
    assert code == 0 and h["keys"] == ["gravity", "camera.scale"]
    assert -11 <= h["truth"]["gravity"] <= -9 and 0.9 <= h["truth"]["camera.scale"] <= 1.1
    assert h["iterations"][0]["nmse"] is not None


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--params", "mass"],
            "unknown parameter 'mass' of scene 'toss'; known parameters of scene 'toss': "
            "camera.clock, camera.scale, gravity",
        ),
        (["--params", "linear_drag.c"], "unknown parameter 'linear_drag.c'"),
        (["--params", "gravity=-9:-11"], "the range needs finite ends with LOW < HIGH"),
        (["--params", "camera.scale=0:2"], "the range must lie in [0.1, 10]"),
        (["--effect", "linear_drag:c=x"], "--effect 'linear_drag:c=x': expected NAME[:KEY=NUMBER"),
        (["--effect", "linear_drag:c=20"], "linear_drag.c = 20.0: must lie in [0, 10] N·s/m"),
        (
            ["--params", "gravity", "--estimator", "resnet3d"],
            "estimator 'resnet3d' corrects one marked body at a time, so it cannot fit gravity "
            "(it belongs to no body)",
        ),
    ],
)
def test_bad_scene_level_settings_are_named(
    capsys: pytest.CaptureFixture[str], toss: Path, argv: list[str], message: str
) -> None:
    code, _, err = run(capsys, "--scene", str(toss), "--iterations", "2", *argv)
    assert code == 2 and message in err, err
