"""``physbench simulate``: one scene instance to trajectory + frames and a preview; clear errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from physbench.cli import main


def test_unknown_scene_lists_known_ones(capsys) -> None:
    assert main(["simulate", "--scene", "no_such_scene"]) == 2
    err = capsys.readouterr().err
    assert (
        "unknown scene 'no_such_scene'" in err
        and "three_circles" in err
        and "bouncing_balls" in err
    )


def test_unknown_engine_lists_known_ones(capsys) -> None:
    assert main(["simulate", "--scene", "three_circles", "--engine", "bullet"]) == 2
    assert "known simulators: box2d, pymunk" in capsys.readouterr().err


def test_bad_override_is_explained(capsys) -> None:
    assert main(["simulate", "--scene", "three_circles", "--set", "a.mass"]) == 2
    assert "expected BODY.PARAM=NUMBER" in capsys.readouterr().err
    assert main(["simulate", "--scene", "three_circles", "--set", "a.mass=-1"]) == 2
    err = capsys.readouterr().err
    assert "a.mass" in err or "bodies[1].mass = -1.0" in err
    assert "mass must lie in [1e-06, 1e+06] kg" in err


def test_simulate_writes_npz_and_previews(tmp_path: Path, capsys) -> None:
    out, gif, png = tmp_path / "run.npz", tmp_path / "p.gif", tmp_path / "p.png"
    for engine in ("pymunk", "box2d"):
        assert (
            main(
                [
                    "simulate",
                    "--scene",
                    "three_circles",
                    "--engine",
                    engine,
                    "--seed",
                    "2",
                    "--out",
                    str(out),
                    "--preview",
                    str(gif),
                    "--resolution",
                    "32",
                ]
            )
            == 0
        )
        data = np.load(out)
        assert data["states"].shape[1:] == (3, 6)
        assert data["frames"].shape[0] == data["states"].shape[0] and data["frames"].shape[2:] == (
            32,
            32,
        )
        assert str(data["engine"]) == engine
    assert gif.stat().st_size > 0
    assert main(["simulate", "--scene", "three_circles", "--preview", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_simulate_a_toml_scene(tmp_path: Path, capsys) -> None:
    assert main(["scenes", "--toml", "three_circles"]) == 0
    path = tmp_path / "tc.toml"
    path.write_text(capsys.readouterr().out)
    assert main(["simulate", "--scene", str(path)]) == 0
    assert "three_circles" in capsys.readouterr().out


def test_the_renderer_is_a_choice(tmp_path: Path, capsys, squares_renderer) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "sq.npz"
    argv = ["simulate", "--scene", "three_circles", "--renderer", "squares", "--out", str(out)]
    assert main([*argv, "--render-mode", "mask", "--resolution", "20"]) == 0
    frames = np.load(out)["frames"]
    assert frames.shape[1:] == (1, 20, 20) and set(np.unique(frames)) <= {0.0, 1.0}
    assert main([*argv, "-R", "size=0.5.1"]) == 2  # not a number: the plugin's own ValueError
    assert (
        "renderer 'squares' (plugin 'pb_squares', registered by PHYSBENCH_PLUGINS) refused "
        "options {'size': '0.5.1'}" in capsys.readouterr().err
    )
    assert main(["simulate", "--scene", "three_circles", "--renderer", "nope"]) == 2
    assert "unknown renderer 'nope'" in capsys.readouterr().err


def test_the_camera_films_a_video_file_and_its_plate(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("av")
    from PIL import Image

    from physbench.scenes import resolve_scene
    from physbench.video.reader import VideoReader

    clip, plate = tmp_path / "clip.mp4", tmp_path / "plate.png"
    argv = ["simulate", "--scene", "three_circles", "--renderer", "camera", "--resolution", "96"]
    assert main([*argv, "--out", str(clip), "--plate", str(plate)]) == 0
    assert f"wrote {clip}" in capsys.readouterr().err
    scene = resolve_scene("three_circles", 0)
    frames = list(VideoReader(clip).frames())
    assert len(frames) == scene.frames and frames[0].image.shape == (72, 96, 3)
    np.testing.assert_allclose(
        [f.time for f in frames], np.arange(scene.frames) * scene.dt, atol=1e-3
    )
    assert np.asarray(Image.open(plate)).shape == (72, 96, 3)


def test_video_and_plate_outputs_need_the_camera(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    base = ["simulate", "--scene", "three_circles", "--resolution", "16"]
    assert main([*base, "--out", str(tmp_path / "a.mp4")]) == 2
    err = capsys.readouterr().err
    assert "a video is filmed by --renderer camera; renderer 'raster' makes 'mark'" in err
    assert main([*base, "--plate", str(tmp_path / "p.png")]) == 2
    assert "a plate is filmed by --renderer camera" in capsys.readouterr().err
    assert main([*base, "--out", str(tmp_path / "a.txt")]) == 2
    assert "expected an .npz file, or a video file (.mp4, .mkv" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_effects_change_the_simulated_motion(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    assert main(["simulate", "--scene", "ball_drop", "--out", str(tmp_path / "free.npz")]) == 0
    argv = ["--effect", "linear_drag:c=0.5", "--out", str(tmp_path / "drag.npz")]
    assert main(["simulate", "--scene", "ball_drop", *argv]) == 0
    free, drag = np.load(tmp_path / "free.npz"), np.load(tmp_path / "drag.npz")
    fall = free["states"][0, 0, 1] - free["states"][-1, 0, 1]
    slowed = drag["states"][0, 0, 1] - drag["states"][-1, 0, 1]
    assert 0 < slowed < 0.5 * fall  # drag c = 0.5 kg/s on a light ball: a much shorter fall
    capsys.readouterr()
    for bad, message in (
        ("linear_drag:c", "expected NAME[:KEY=NUMBER,...]"),
        ("linear_drag:q=1", "does not take option 'q'; its options: bodies, label, c"),
        (
            "nope",
            "unknown effect 'nope'; known effects: axis_rotation, calibration_scale, clock_scale",
        ),
    ):
        assert main(["simulate", "--scene", "ball_drop", "--effect", bad]) == 2
        assert message in capsys.readouterr().err


def test_a_simulation_bigger_than_memory_is_refused_before_simulating(
    tmp_path: Path, capsys, huge_scene, monkeypatch
) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.delenv("PHYSBENCH_NO_SIZE_CHECK", raising=False)
    out = tmp_path / "o.npz"
    argv = ["simulate", "--scene", huge_scene, "--render-mode", "instance", "--resolution", "1024"]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "physbench simulate: error: this simulation (1 simulation of 100000 frames x 10000 "
        "substeps x 50 bodies at 1024 px) would need 41.9 TB of memory, more than the "
    )
    assert "set PHYSBENCH_NO_SIZE_CHECK=1 to run it anyway" in err and err.count("\n") == 1
    assert not out.exists()
