"""``physbench discover``: the verdict it prints and writes, frames input with a renderer chosen by
name, and bad recordings, scenes and options failing with named errors (exit code 2 and a message
that names the bad value and what would be accepted)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from physbench.cli import main as cli
from physbench.effects import LinearDrag
from physbench.recording import Recording, Track, write_recordings
from physbench.scene import Body, Circle, Scene
from physbench.scene_toml import save_scene
from physbench.simulators.pymunk_sim import PymunkSimulator

SCENE = """
name = "slide"
bounds = [-3.0, -3.0, 9.0, 6.0]
gravity = [0.0, 0.0]
fps = 20.0
frames = 21
substeps = 4

[[bodies]]
name = "ball"
shape = { kind = "circle", radius = 0.05 }
position = [1.0, 1.0]
velocity = [2.0, 0.5]
mass = MASS
"""


def recording(n: int = 21, body: str = "ball", t0: float = 0.0, run: str = "") -> str:
    rows = ["t,body,x,y" + (",run" if run else "")]
    for k in range(n):
        t = t0 + k / 20
        rows.append(f"{t!r},{body},{1 + 2 * t!r},{1 + 0.5 * t!r}" + (f",{run}" if run else ""))
    return "\n".join(rows) + "\n"


def write(tmp: Path, name: str, text: str | bytes) -> str:
    p = tmp / name
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text)
    return str(p)


def npz(tmp: Path, **arrays: np.ndarray) -> str:
    p = tmp / "frames.npz"
    np.savez(p, **arrays)
    return str(p)


GOOD_SCENE = SCENE.replace("MASS", "1.0")
CASES = [
    # id, files {name: text}, extra args, expected message (regex)
    ("missing recording", {}, ["nope.csv"], r"recording file .*nope\.csv' does not exist"),
    (
        "unknown format",
        {"r.txt": recording()},
        ["r.txt"],
        r"unknown format '\.txt'; expected \.csv",
    ),
    (
        "unknown body",
        {"r.csv": recording(body="ghost")},
        ["r.csv"],
        r"line 2 .*column 'body'.*unknown body 'ghost'",
    ),
    (
        "missing column",
        {"r.csv": "t,body,x\n0,ball,1\n"},
        ["r.csv"],
        r"missing required column.*'y'|column 'y'",
    ),
    ("negative time", {"r.csv": recording(t0=-0.1)}, ["r.csv"], r"t = -0\.1: times must be >= 0"),
    (
        "bad scene value",
        {"r.csv": recording(), "s.toml": SCENE.replace("MASS", "-1.0")},
        ["r.csv"],
        r"s\.toml:\d+: bodies\[0\]\.mass = -1\.0: mass must lie in \[1e-06, 1e\+06\] kg",
    ),
    (
        "missing scene",
        {"r.csv": recording()},
        ["r.csv", "--scene", "none.toml"],
        r"cannot read scene file",
    ),
    (
        "unknown effect",
        {"r.csv": recording()},
        ["r.csv", "--effects", "nope"],
        r"unknown effect 'nope'.*linear_drag",
    ),
    (
        "effect that does not apply",
        {"r.csv": recording()},
        ["r.csv", "--effects", "joint_viscous_damping"],
        r"none of the requested effects applies.*joint_viscous_damping.*needs a scene with joints",
    ),
    (
        "recording too short",
        {"r.csv": recording(n=6)},
        ["r.csv"],
        r"leaves \d samples to fit and \d to score",
    ),
    (
        "bad nuisance",
        {"r.csv": recording()},
        ["r.csv", "--nuisance", "ball.z0"],
        r"nuisance 'ball\.z0'.*x0, y0, angle0",
    ),
    ("no such run", {"r.csv": recording(run="a")}, ["r.csv", "--run", "b"], r"no run 'b'; runs: a"),
    (
        "unknown engine",
        {"r.csv": recording()},
        ["r.csv", "--engine", "nope"],
        r"unknown simulator 'nope'.*box2d",
    ),
    (
        "unknown estimator",
        {"r.csv": recording()},
        ["r.csv", "--estimator", "nope"],
        r"unknown estimator 'nope'",
    ),
    (
        "simulation leaves the world",
        {"r.csv": recording(n=400)},
        ["r.csv"],
        r"does not simulate over the recording.*left the world",
    ),
]
FRAME_CASES = [
    ("frames without frames key", {"x": np.zeros((4, 1, 8, 8))}, r"no 'frames' array \(found: x\)"),
    (
        "frames with three channels",
        {"frames": np.zeros((21, 3, 36, 48), np.float32)},
        r"frames have 3 channels",
    ),
    (
        "frames of the wrong size",
        {"frames": np.zeros((21, 1, 10, 48), np.float32)},
        r"\(C, H, W\) = \(1, 10, 48\).*\(1, 36, 48\)",
    ),
]


@pytest.mark.parametrize(
    ("files", "args", "message"), [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_bad_input_gives_a_named_error(tmp_path, monkeypatch, capsys, files, args, message):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "s.toml", GOOD_SCENE)
    for name, text in files.items():
        write(tmp_path, name, text)
    argv = ["discover", *args]
    if "--scene" not in argv:
        argv += ["--scene", "s.toml"]
    assert cli(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("physbench discover: error: ")
    assert re.search(message, err, re.S), err


@pytest.mark.parametrize(
    ("arrays", "message"), [c[1:] for c in FRAME_CASES], ids=[c[0] for c in FRAME_CASES]
)
def test_bad_frames_give_a_named_error(tmp_path, capsys, arrays, message):
    write(tmp_path, "s.toml", GOOD_SCENE)
    assert cli(["discover", npz(tmp_path, **arrays), "--scene", str(tmp_path / "s.toml")]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err, re.S), err


RENDERER_CASES = [
    ("unknown renderer", ["--renderer", "nope"], r"unknown renderer 'nope'.*raster"),
    (
        "option it does not take",
        ["-R", "nope=1"],
        r"-R nope=1: renderer 'raster' \(physbench's own\) has no option 'nope'; the options -R "
        "can set: none",
    ),
    (
        "mode against the channels",
        ["--render-mode", "mark"],
        r"\(C, H, W\) = \(1, 36, 48\) but the 'raster' renderer in 'mark' mode gives \(2, 36, 48\)",
    ),
    ("width against the frames", ["--resolution", "24"], r"gives \(1, 18, 24\)"),
]


@pytest.mark.parametrize(
    ("args", "message"), [c[1:] for c in RENDERER_CASES], ids=[c[0] for c in RENDERER_CASES]
)
def test_the_renderer_of_frames_is_checked_against_them(tmp_path, capsys, args, message):
    write(tmp_path, "s.toml", GOOD_SCENE)
    frames = npz(tmp_path, frames=np.zeros((21, 1, 36, 48), np.float32))
    assert cli(["discover", frames, "--scene", str(tmp_path / "s.toml"), *args]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err, re.S), err


def noisy(traj, sigma=0.002, seed=0) -> Recording:
    rng = np.random.default_rng(seed)
    rec = Recording.from_trajectory(traj)
    tracks = {
        b: Track(t.t, t.x + rng.normal(0, sigma, len(t)), t.y + rng.normal(0, sigma, len(t)))
        for b, t in rec.tracks.items()
    }
    return Recording(tracks, fields=("x", "y"))


def test_frames_input_uses_the_image_loss(tmp_path):
    from physbench.observation import Observation, save_observation
    from physbench.render.raster import RasterRenderer

    scene = Scene(
        "frames",
        (Body("ball", Circle(0.3), (1.0, 2.0), velocity=(2.5, 0.3), mass=1.0),),
        bounds=(0, 0, 6, 4),
        gravity=(0.0, 0.0),
        fps=10.0,
        frames=21,
        substeps=4,
    ).validate()
    r = RasterRenderer(resolution=32, mode="mask")
    frames = r.render(scene, PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.5)]))
    save_observation(tmp_path / "obs.npz", Observation(frames))
    save_scene(scene, tmp_path / "scene.toml")
    out = tmp_path / "v.json"
    argv = ["discover", str(tmp_path / "obs.npz"), "--scene", str(tmp_path / "scene.toml")]
    rc = cli([*argv, "--effects", "linear_drag", "rolling_resistance", "--json", str(out), "-q"])
    assert rc == 0
    d = json.loads(out.read_text())
    assert d["causes"] == ["linear_drag"] and d["unit"] == "pixel intensity"
    c = next(c for c in d["candidates"] if c["chosen"])
    assert c["params"]["c"] == pytest.approx(0.5, rel=0.15)


def test_cli_prints_the_verdict_and_the_table(tmp_path, capsys, slide):
    scene = slide
    rec = noisy(PymunkSimulator().simulate(scene))
    write_recordings(tmp_path / "r.csv", rec)
    save_scene(scene, tmp_path / "s.toml")
    argv = ["discover", str(tmp_path / "r.csv"), "--scene", str(tmp_path / "s.toml")]
    effects = ["linear_drag", "constant_force", "joint_viscous_damping"]
    rc = cli([*argv, "--effects", *effects, "--report", str(tmp_path / "rep")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "no cause found" in out and "linear_drag" in out and "held-out" in out
    assert out.startswith("discovery on 1 run [r] with pymunk; ")
    assert (tmp_path / "rep" / "index.html").is_file()
    # issue 28: the table's parameters carry their units, the untried candidates a reason in
    # words (not an exception's name)
    rows = {line.split()[1]: line for line in out.splitlines() if line[:5].strip().isdigit()}
    assert rows["linear_drag"].endswith(" N·s/m"), rows["linear_drag"]
    assert rows["constant_force"].count(" N") == 2, rows["constant_force"]  # fx and fy
    assert "not tried: joint_viscous_damping (needs a scene with joints; " in out
    assert "Error" not in out.partition("not tried:")[2]


def test_a_disagreement_below_the_floor_names_no_cause(tmp_path, slide):
    # Drag found in tracks accurate to 2 mm names nothing in data said to be good to a metre.
    scene = slide
    rec = noisy(PymunkSimulator().simulate(scene, effects=[LinearDrag(c=0.3)]))
    write_recordings(tmp_path / "r.csv", rec)
    save_scene(scene, tmp_path / "s.toml")
    argv = ["discover", str(tmp_path / "r.csv"), "--scene", str(tmp_path / "s.toml")]
    argv += ["--effects", "linear_drag", "constant_force", "-q", "--json"]
    verdicts = []
    for extra in ([], ["--floor", "1"]):
        out = tmp_path / f"d{len(extra)}.json"
        assert cli([*argv, str(out), *extra]) == 0
        verdicts.append(json.loads(out.read_text()))
    assert verdicts[0]["causes"] == ["linear_drag"]
    assert verdicts[1]["causes"] == []
    notes = [c["note"] for c in verdicts[1]["candidates"]]
    assert any("above the data's accuracy 1 " in n for n in notes), notes


def test_a_recording_tracked_in_y_only_is_fitted_in_y_only(tmp_path, slide):
    """The written CSV keeps the measured fields: the unseen x (filled with zeros by the tracker)
    is neither fitted nor blamed on a sensor offset."""
    from physbench.discover.data import load_runs

    scene = slide
    seen = Recording.from_trajectory(PymunkSimulator().simulate(scene), angle=False)
    tracks = {b: Track(t.t, np.zeros(len(t)), t.y) for b, t in seen.tracks.items()}
    write_recordings(tmp_path / "r.csv", Recording(tracks, fields=("y",)))
    save_scene(scene, tmp_path / "s.toml")
    (run,) = load_runs(tmp_path / "r.csv", tmp_path / "s.toml")
    assert run.recording is not None and run.recording.fields == ("y",)
    out = tmp_path / "v.json"
    argv = ["discover", str(tmp_path / "r.csv"), "--scene", str(tmp_path / "s.toml")]
    assert cli([*argv, "--json", str(out), "-q"]) == 0
    d = json.loads(out.read_text())
    assert d["residuals"]["base"]["per_field"] == {"ball": {"y": pytest.approx(0.0, abs=1e-9)}}
    assert d["causes"] == []


def test_a_discovery_this_machine_cannot_finish_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("PHYSBENCH_NO_SIZE_CHECK", raising=False)
    scene = write(tmp_path, "slide.toml", SCENE.replace("MASS", "1.0"))
    rec = write(tmp_path, "r.csv", recording())
    code = cli(["discover", rec, "--scene", scene, "--iterations", str(10**10)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("physbench discover: error: this discovery (1 x 10000000840 simulations")
    assert "more than the 24 h limit" in err and "PHYSBENCH_NO_SIZE_CHECK=1" in err
