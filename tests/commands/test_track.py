"""``physbench track``: a clip becomes a recording CSV and a preview; bad input gets a clear error
and the input file is never changed."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from PIL import Image

from physbench.calibration import load_calibration
from physbench.cli import main
from physbench.components import create
from physbench.recording import read_recording
from physbench.render.camera import CameraRenderer
from physbench.scenes import resolve_scene
from physbench.video.writer import write_clip


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("track")
    scene = resolve_scene("bouncing_balls", 4)
    traj = create("simulator", "pymunk").simulate(scene)
    cam = CameraRenderer(640, bitrate=1_500_000, seed=4)
    write_clip(cam, tmp / "clip.mp4", scene, traj)
    Image.fromarray(cam.plate(scene)).save(tmp / "plate.png")
    cal = cam.calibration(scene).homography
    rows = "\n".join(f"[{', '.join(repr(float(x)) for x in r)}]," for r in cal)
    (tmp / "cal.toml").write_text(f"[homography]\nmatrix = [\n{rows}\n]\n")
    return tmp, scene, traj


def digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_clip_becomes_a_recording_and_a_preview(clip, capsys) -> None:
    tmp, scene, traj = clip
    cam = CameraRenderer(640, bitrate=1_500_000, seed=4)  # the clip's camera: its projection
    before = digest(tmp / "clip.mp4")
    args = ["track", str(tmp / "clip.mp4"), "--scene", "bouncing_balls", "--seed", "4"]
    args += ["--calibration", str(tmp / "cal.toml"), "--background", str(tmp / "plate.png")]
    args += ["--out", str(tmp / "out" / "rec.csv"), "--preview", str(tmp / "ov.mp4")]
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert "tracked" in out and "reprojection error" in out and "wrote" in err
    rec = read_recording(tmp / "out" / "rec.csv", bodies=scene)
    assert rec.bodies == scene.body_names
    tr = rec.track("test")
    frame = np.round(tr.t * scene.fps).astype(int)  # its collision frames are left out
    assert len(frame) >= len(traj.times) - 3 and "collision frame" in out
    got = np.column_stack([tr.x, tr.y])
    assert np.abs(got - traj.states[frame, 0, :2]).max() < 0.01  # metres, 1.5 px
    assert (tmp / "ov.mp4").stat().st_size > 0 and digest(tmp / "clip.mp4") == before
    # the measured pixel centres, beside the metres: through the calibration they are the rows
    text = (tmp / "out" / "rec.pixels.csv").read_text()
    assert text.startswith("# pixel centres") and "pixel centres at integers" in text
    rows = [r.split(",") for r in text.splitlines()[2:] if r.split(",")[1] == "test"]
    px = {float(t): (float(u), float(v)) for t, _, u, v in rows}
    assert len(px) >= len(tr.t)  # collision frames are measured, then left out of the metres
    cal = load_calibration(tmp / "cal.toml")
    metres = cal.to_scene(np.array([px[t] for t in tr.t]))
    # the blob's centre in the image; the metres are its pixels' centre in the plane, which a
    # perspective view moves by hundredths of a pixel (measured: 0.017 px at most)
    assert np.abs(metres - got).max() < 0.05 * cal.metres_per_pixel((320, 240))
    truth_px = cam.image_points(scene, traj.states[frame, 0, :2])
    assert np.median(np.hypot(*(np.array([px[t] for t in tr.t]) - truth_px).T)) < 0.5


def test_bad_input_gets_a_clear_error(clip, capsys) -> None:
    tmp, _, _ = clip
    before = digest(tmp / "clip.mp4")
    data = (tmp / "clip.mp4").read_bytes()
    (tmp / "cut.mp4").write_bytes(data[: len(data) // 2])
    (tmp / "junk.mp4").write_bytes(b"\x00" * 1000)
    (tmp / "bad.png").write_text("no image")
    base = ["--scene", "bouncing_balls", "--seed", "4", "--out", str(tmp / "r.csv")]
    cases = [
        (["track", str(tmp / "junk.mp4"), *base], "not a video FFmpeg can read"),
        (["track", str(tmp / "cut.mp4"), *base], "cut.mp4"),
        (["track", str(tmp / "clip.mp4"), *base, "--start", "20"], "has no frames after 20 s"),
        (["track", str(tmp / "clip.mp4"), "--scene", "three_circles", *base[4:]], "not in the"),
        (["track", str(tmp / "clip.mp4"), *base, "--background", str(tmp / "bad.png")], "bad.png"),
        (["track", str(tmp / "clip.mp4"), *base[:4], "--out", str(tmp / "clip.mp4")], "input"),
        (["track", str(tmp / "clip.mp4"), *base, "--preview", str(tmp / "p.png")], ".gif"),
    ]
    for argv, message in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("physbench track: error:") and message in err, err
    with pytest.raises(SystemExit):
        main(["track", str(tmp / "clip.mp4"), *base, "--transfer", "gamma2.4"])
    err = capsys.readouterr().err
    assert "'gamma2.4'" in err and "'srgb', 'bt709'" in err, err
    assert digest(tmp / "clip.mp4") == before


@pytest.fixture(scope="module")
def hidden(clip):
    """The clip as a folder of images in which the test ball is hidden from frame 8 on: the
    plate shows where it is."""
    from physbench.video.reader import VideoReader

    tmp, scene, traj = clip
    folder = tmp / "hidden"
    folder.mkdir(exist_ok=True)
    cam = CameraRenderer(640, bitrate=1_500_000, seed=4)
    plate = np.array(Image.open(tmp / "plate.png"))
    for fr in VideoReader(tmp / "clip.mp4").frames():
        img = fr.image.copy()
        if fr.index >= 8:
            u, v = cam.image_points(scene, traj.states[fr.index, :1, :2])[0].astype(int)
            img[v - 40 : v + 40, u - 40 : u + 40] = plate[v - 40 : v + 40, u - 40 : u + 40]
        Image.fromarray(img).save(folder / f"f{fr.index:03d}.png")
    return folder


def test_a_lost_body_fails_the_command_and_says_when(clip, hidden, capsys) -> None:
    tmp, scene, _ = clip
    args = ["track", str(hidden), "--scene", "bouncing_balls", "--seed", "4"]
    args += ["--calibration", str(tmp / "cal.toml"), "--background", str(tmp / "plate.png")]
    out_csv = tmp / "lost" / "rec.csv"
    assert main([*args, "--out", str(out_csv)]) == 2
    out, err = capsys.readouterr()
    assert "test: seen in 8/30 frames; lost from 0.27 to 0.97 s" in out  # never "1 gap"
    assert "gap" not in out.replace("--allow-gaps", "")
    assert err.startswith("physbench track: error: body 'test' was lost in 22 of the 30 frames")
    assert "--allow-gaps" in err and not out_csv.exists()
    assert main([*args, "--out", str(out_csv), "--allow-gaps"]) == 0
    assert len(read_recording(out_csv, bodies=scene).track("test")) <= 8
    # The same words wherever a video feeds a run.
    common = ["--scene", "bouncing_balls", "--seed", "4", "--calibration", str(tmp / "cal.toml")]
    common += ["--background", str(tmp / "plate.png")]
    assert main(["discover", str(hidden), *common]) == 2
    assert "body 'test' was lost in 22 of the 30 frames" in capsys.readouterr().err
    assert main(["run", "--video", str(hidden), *common, "--iterations", "2"]) == 2
    assert "body 'test' was lost in 22 of the 30 frames" in capsys.readouterr().err
    from physbench.discover import load_runs

    (run,) = load_runs(hidden, scene, calibration=tmp / "cal.toml", background=tmp / "plate.png",
                       allow_gaps=True)  # fmt: skip
    assert run.recording is not None and len(run.recording.track("test")) <= 8


def test_a_folder_of_images_gets_its_preview_at_the_scenes_frame_rate(clip, hidden, capsys):
    """A folder of images carries no frame rate: the preview is drawn at the scene's, as the
    tracking was (it had failed after writing the recording)."""
    tmp, scene, _ = clip
    args = ["track", str(hidden), "--scene", "bouncing_balls", "--seed", "4", "--allow-gaps"]
    args += ["--calibration", str(tmp / "cal.toml"), "--background", str(tmp / "plate.png")]
    gif = tmp / "folder.gif"
    assert main([*args, "--out", str(tmp / "folder.csv"), "--preview", str(gif)]) == 0
    assert "wrote" in capsys.readouterr().err
    with Image.open(gif) as im:
        assert im.n_frames == len(list(hidden.glob("*.png")))
        assert abs(im.info["duration"] - 1000 / scene.fps) < 10  # GIF counts centiseconds
