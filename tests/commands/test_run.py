"""``physbench run``: output, JSON, observation files, reality gap, blur, plot, and clear errors."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from physbench.cli import main
from physbench.video.writer import write_clip

FAST = ["--iterations", "4", "--resolution", "32"]


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["run", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_table_and_final_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        capsys,
        "--estimator",
        "tpe",
        "--scene",
        "three_circles",
        "--params",
        "mass",
        *FAST,
        "--seed",
        "1",
    )
    assert code == 0
    lines = out.splitlines()
    assert lines[0].split()[:4] == ["iter", "a.mass", "b.mass", "image"]
    assert [ln.split()[0] for ln in lines[1:5]] == ["0", "1", "2", "3"]
    assert "per iteration: simulate" in out and "truth:" in out and "best (iteration" in out
    assert lines[-1].startswith("normalized min MSE after 4 iterations: ")


def test_quiet_prints_only_the_final_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "--estimator", "random", *FAST, "-q")
    assert code == 0 and err == ""
    assert out.count("\n") == 1 and out.startswith("normalized min MSE after 4 iterations")
    code, out, _ = run(capsys, "--estimator", "random", "--iterations", "1", "-q")
    assert code == 0 and out.startswith("normalized min MSE after 1 iteration: ")


def test_json_history_is_reproducible(capsys: pytest.CaptureFixture[str]) -> None:
    argv = (
        "--estimator",
        "optuna",
        "--params",
        "mass",
        "elasticity",
        *FAST,
        "--json",
        "-q",
        "--seed",
        "2",
    )
    _, out1, _ = run(capsys, *argv)
    _, out2, _ = run(capsys, *argv)
    a, b = json.loads(out1), json.loads(out2)
    assert (
        a["keys"] == ["a.mass", "a.elasticity", "b.mass", "b.elasticity"]
        and len(a["iterations"]) == 4
    )
    assert a["best_nmse"] == a["iterations"][-1]["best_nmse"] and a["truth"] is not None
    for d in (a, b):
        d.pop("timings"), d["meta"].pop("t_start")
        for r in d["iterations"]:
            for k in ("t_simulate", "t_render", "t_estimator"):
                r.pop(k)
    assert a == b


def test_observation_file_round_trip_and_wrong_shape(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "obs.npz"
    argv = ("--estimator", "random", *FAST, "-q", "--json")
    code, saved, _ = run(capsys, *argv, "--seed", "3", "--save-observation", str(path))
    assert code == 0 and path.exists()
    # the run's own observation, with its scene instance and truth: the same history
    code, again, _ = run(capsys, *argv, "--seed", "3", "--observation", str(path))
    a, b = json.loads(saved), json.loads(again)
    assert code == 0 and b["truth"] == a["truth"] and b["meta"]["observe_engine"] == "pymunk"
    assert [r["nmse"] for r in b["iterations"]] == [r["nmse"] for r in a["iterations"]]
    assert [r["loss"] for r in b["iterations"]] == [r["loss"] for r in a["iterations"]]
    # frames only (a camera's, or a file from before scenes were stored): no truth, as before
    frames = np.load(path)["frames"]
    np.savez(tmp_path / "frames.npz", frames=frames)
    code, out, _ = run(
        capsys, "--estimator", "random", *FAST, "-q", "--observation", str(tmp_path / "frames.npz")
    )
    assert code == 0 and out.startswith("min image MSE after 4 iterations") and "no truth" in out
    code, out, _ = run(
        capsys, "--estimator", "random", *FAST, "--observation", str(tmp_path / "frames.npz")
    )
    assert out.startswith(
        f"observation {tmp_path / 'frames.npz'}: frames only (no scene or truth in the file); "
        "modelled as scene three_circles by pymunk\n"
    )

    np.savez(tmp_path / "short.npz", frames=frames[:10])
    code, _, err = run(
        capsys, "--estimator", "random", *FAST, "--observation", str(tmp_path / "short.npz")
    )
    assert code == 2
    assert (
        f"frames have shape (10, 2, 32, 32), expected (T, C, H, W) = {frames.shape}" in err
        and "T 10 != " in err
    )
    code, _, err = run(
        capsys, "--estimator", "random", "--iterations", "4", "--observation", str(path)
    )
    assert (
        code == 2 and "H 32 != 64, W 32 != 64" in err
    )  # observed at 32 px, modelled at the default 64


def test_a_simulated_file_brings_its_scene_truth_and_engine(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    from physbench.experiment import RunConfig, observed_scene
    from physbench.observation import load_observation
    from physbench.scenes import resolve_scene

    path = str(tmp_path / "run.npz")
    made = ["simulate", "--scene", "three_circles", "--seed", "3", "--resolution", "32"]
    assert main([*made, "--engine", "box2d", "--set", "a.mass=2", "--out", path]) == 0
    capsys.readouterr()
    # the file's instance (seed 3, a.mass = 2), not three_circles at --seed 0
    scene = observed_scene(RunConfig(scene=None, observation=path), load_observation(path))
    assert scene == resolve_scene("three_circles", 3).with_params({"a.mass": 2.0})
    code, out, _ = run(capsys, "--estimator", "random", *FAST, "--observation", path)
    lines = out.splitlines()
    assert code == 0
    assert lines[0] == (
        f"observation {path}: scene three_circles, made by box2d; modelled by box2d"
    )
    assert "truth:   a.mass=2  b.mass=5" in lines
    assert lines[-1].startswith("normalized min MSE after 4 iterations: ")
    # an engine the user chooses models it, and the output says which
    code, out, _ = run(
        capsys, "--estimator", "random", *FAST, "--engine", "pymunk", "--observation", path
    )
    assert out.splitlines()[0].endswith("made by box2d; modelled by pymunk")
    code, out, _ = run(
        capsys, "--estimator", "random", *FAST, "-q", "--json", "--observation", path
    )
    meta = json.loads(out)["meta"]
    assert (meta["scene"], meta["simulator"], meta["observe_engine"]) == (
        "three_circles",
        "box2d",
        "box2d",
    )
    # a --scene naming the file's scene is fine; another scene is refused, naming both
    code, _, _ = run(
        capsys,
        "--estimator",
        "random",
        *FAST,
        "-q",
        "--scene",
        "three_circles",
        "--observation",
        path,
    )
    assert code == 0
    code, _, err = run(capsys, *FAST, "--scene", "stacked_boxes", "--observation", path)
    assert code == 2 and (
        f"--scene 'stacked_boxes' does not match the observation {path}, which shows scene "
        "'three_circles'; leave --scene out" in err
    )
    # unknowns the file's scene lacks are named as for any scene
    code, _, err = run(capsys, *FAST, "--params", "friction", "--observation", path)
    assert code == 2 and "unknown parameter 'friction' of scene 'three_circles'" in err
    # effects simulated besides the scene's physics are said
    assert main([*made, "--effect", "linear_drag:c=0.3", "--out", path]) == 0
    capsys.readouterr()
    code, out, _ = run(capsys, "--estimator", "random", *FAST, "--observation", path)
    assert out.splitlines()[0].endswith("made by pymunk with LinearDrag(c=0.3); modelled by pymunk")


def test_reality_gap_blur_and_plot(capsys: pytest.CaptureFixture[str], tmp_path) -> None:  # type: ignore[no-untyped-def]
    png = tmp_path / "conv.png"
    code, out, _ = run(
        capsys,
        "--estimator",
        "cmaes",
        *FAST,
        "-q",
        "--engine",
        "pymunk",
        "--observe-engine",
        "box2d",
        "--blur",
        "1.5",
        "--plot",
        str(png),
    )
    assert code == 0 and out.startswith("normalized min MSE")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_estimator_options(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        capsys,
        "--estimator",
        "optuna",
        "-o",
        "sampler=random",
        "-o",
        "startup=2",
        *FAST,
        "--json",
        "-q",
    )
    assert code == 0 and json.loads(out)["options"] == {"sampler": "random", "startup": 2}


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--estimator", "nope"],
            "unknown estimator 'nope'; known estimators: cmaes, gp, nevergrad, npe, optuna, "
            "random, resnet3d",
        ),
        (["--scene", "no_such_scene"], "unknown scene 'no_such_scene'"),
        (["--params", "friction"], "unknown parameter 'friction' of scene 'three_circles'"),
        (["--engine", "bullet"], "unknown simulator 'bullet'; known simulators: box2d, pymunk"),
        (["-o", "startup=-1"], "tpe: startup = -1: expected a whole number >= 0"),
        (
            ["-o", "temperature=3"],
            "estimator 'tpe' (physbench's own) does not take option 'temperature'; "
            "its options: startup, design, candidates, gamma",
        ),
        (["-o", "startup"], "--option 'startup': expected KEY=VALUE"),
        (["--observation", "x.npz", "--blur", "2"], "cannot apply to --observation frames"),
        (["--observation", "missing.npz"], "observation file 'missing.npz' does not exist"),
        (["--calibration", "c.toml"], "--calibration apply to a --video only"),
        (["--capture-fps", "240"], "--capture-fps apply to a --video only"),
        (["--observer-option", "tilt=5"], "but no observer: name the camera renderer"),
        (["--video", "v.mp4", "--observation", "x.npz"], "give one source of the observation"),
        # Found by fuzzing (issue 14): each was a traceback.
        (["--blur", "40"], "--blur 40: expected at most the frame width --resolution 32 pixels"),
        (["--scene", "x" * 300], "unknown scene 'xxx"),
    ],
)
def test_clear_errors(capsys: pytest.CaptureFixture[str], argv: list[str], message: str) -> None:
    extra = [] if "--iterations" in argv else ["--iterations", "2", "--resolution", "32"]
    code, _, err = run(capsys, *argv, *extra)
    assert code == 2
    assert err.startswith("physbench run: error: ") and message in err, err


def test_argument_parsing_imports_nothing_heavy() -> None:
    code = (
        "import sys\nfrom physbench.cli import "
        "build_parser\nbuild_parser('run').parse_args(['run', '--estimator', 'tpe'])\n"
        "print([m for m in ('numpy', 'physbench.loop', 'tqdm', 'pandas') if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_a_third_party_renderer_is_chosen_by_name(
    capsys: pytest.CaptureFixture[str], squares_renderer
) -> None:
    code, out, _ = run(capsys, "--renderer", "squares", "-R", "size=3", *FAST, "--json", "-q")
    history = json.loads(out)
    assert code == 0 and history["meta"]["renderer"] == "squares"
    assert history["meta"]["renderer_options"] == {"size": 3}
    # the observation, the shape check (a one-frame still: Squares has no shape()), the
    # identifiability probe (a reference and 2 per unknown: 5) and 4 model renders, all by the
    # plugin
    assert squares_renderer.CALLS.count(None) == 11
    code, raster, _ = run(capsys, *FAST, "--json", "-q")
    assert code == 0 and json.loads(raster)["meta"]["renderer"] == "raster"
    losses = [r["loss"] for r in history["iterations"]]
    assert losses != [r["loss"] for r in json.loads(raster)["iterations"]]


def test_bad_renderer_choices_are_named(
    capsys: pytest.CaptureFixture[str], squares_renderer
) -> None:
    code, _, err = run(capsys, "--renderer", "nope", *FAST)
    assert code == 2 and "unknown renderer 'nope'" in err and "raster" in err and "squares" in err
    code, _, err = run(capsys, "--renderer", "squares", "-R", "colour=red", *FAST)
    # only the options -R can set: not resolution and mode, which have flags of their own
    assert code == 2 and "has no option 'colour'; the options -R can set: size\n" in err
    code, _, err = run(capsys, "--renderer", "squares", "--render-mode", "instance", *FAST)
    assert code == 2 and "supports modes mark, mask" in err
    code, _, err = run(capsys, "-R", "resolution=8", *FAST)
    assert code == 2 and "--resolution" in err


def test_video_and_filmed_observations(capsys: pytest.CaptureFixture[str], tmp_path) -> None:  # type: ignore[no-untyped-def]
    from physbench.components import create
    from physbench.render.camera import CameraRenderer
    from physbench.scenes import resolve_scene

    # The visual gap: the simulated observation filmed, encoded, tracked and segmented.
    code, out, _ = run(
        capsys, *FAST, "--observer", "camera", "--observer-option", "tilt=10", "--json", "-q"
    )
    history = json.loads(out)
    assert code == 0 and history["meta"]["observer"] == "camera"
    assert history["meta"]["observer_options"] == {"tilt": 10}
    assert history["truth"] and history["iterations"][0]["nmse"] is not None
    # A user's video: the same scene filmed, no truth known.
    scene = resolve_scene("three_circles", 0)
    cam = CameraRenderer(640, seed=4)
    write_clip(cam, tmp_path / "clip.mp4", scene, create("simulator", "pymunk").simulate(scene))
    code, out, _ = run(capsys, *FAST, "--video", str(tmp_path / "clip.mp4"))
    assert code == 0 and f"no truth: observation from {tmp_path / 'clip.mp4'}" in out
    # A clip that ends before the scene does is refused by name, not padded.
    from physbench.trajectory import Trajectory

    traj = create("simulator", "pymunk").simulate(scene)
    short = Trajectory(traj.bodies, traj.times[:10], traj.states[:10])
    write_clip(cam, tmp_path / "short.mp4", scene, short)
    code, _, err = run(capsys, *FAST, "--video", str(tmp_path / "short.mp4"))
    # Over 10 frames the resting circles are part of the median: a plate is needed, and said so.
    assert code == 2 and "not in the first frame" in err and "film the empty scene" in err, err
    from PIL import Image

    Image.fromarray(cam.plate(scene)).save(tmp_path / "plate.png")
    plate = ["--background", str(tmp_path / "plate.png")]
    code, _, err = run(capsys, *FAST, "--video", str(tmp_path / "short.mp4"), *plate)
    assert code == 2 and "short.mp4: has 0.300 s of frames, but the scene needs" in err, err


def test_resnet3d_without_torch_names_the_extra_instead_of_a_traceback(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "torch", None)
    rc, out, err = run(capsys, "--estimator", "resnet3d", "--iterations", "1", "-q")
    assert rc == 2 and out == ""
    assert err.strip() == (
        "physbench run: error: estimator 'resnet3d' needs torch, which is not installed: "
        "pip install 'physbench[learn]'"
    )


def test_a_posterior_is_printed_warned_about_saved_and_plotted(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:  # type: ignore[no-untyped-def]
    common = ["--estimator", "smc", "--noise", "0.2", "--resolution", "16", "--seed", "1"]
    code, out, err = run(capsys, *common, "--iterations", "200", "--plot", str(tmp_path / "r.png"))
    assert code == 0
    assert "posterior (smc, 64 samples):" in out
    assert "a.mass: median" in out and "90 % [" in out and "truth" in out
    # 200 simulations do not finish tempering: said on stdout and as a warning.
    assert "incomplete posterior" in out and "warning: incomplete posterior" in err
    assert (tmp_path / "r.png").exists() and (tmp_path / "r.posterior.png").exists()
    code, out, _ = run(capsys, *common, "--iterations", "200", "--json")
    post = json.loads(out)["posterior"]
    assert post["method"] == "smc" and post["keys"] == ["a.mass", "b.mass"]
    assert len(post["samples"]) == 64 and len(post["quantiles"]["a.mass"]) == 5
    assert post["complete"] is False


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--iterations", "1000000000"],
            "this run (1000000003 simulations of 30 frames x 10 substeps x 3 bodies at 64 px) "
            "would need about 38.9 days of compute, more than the 24 h limit; make the iterations, "
            "the resolution or the scene's frames, substeps or bodies smaller, or set "
            "PHYSBENCH_NO_SIZE_CHECK=1 to run it anyway",
        ),
        (
            ["--scene", "HUGE"],
            "this run (14 simulations of 100000 frames x 10000 substeps x 50 bodies at 64 px) "
            "would need about 8.1 days of compute, more than the 24 h limit",
        ),
        (
            ["--scene", "HUGE", "--render-mode", "instance", "--resolution", "4096"],
            "TB of memory, more than the ",
        ),
    ],
    ids=["iterations", "scene", "memory"],
)
def test_a_run_this_machine_cannot_finish_is_one_sentence_at_once(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    huge_scene: str,
    argv: list[str],
    message: str,
) -> None:
    import time

    monkeypatch.delenv("PHYSBENCH_NO_SIZE_CHECK", raising=False)
    start = time.perf_counter()
    code, out, err = run(capsys, *(huge_scene if a == "HUGE" else a for a in argv))
    assert time.perf_counter() - start < 2
    assert code == 2 and out == ""
    assert err.startswith("physbench run: error: this run (") and err.count("\n") == 1
    assert message in err


def test_the_size_check_refuses_through_the_api_too(monkeypatch: pytest.MonkeyPatch) -> None:
    from physbench.cost import SizeError
    from physbench.experiment import RunConfig, run_config

    monkeypatch.delenv("PHYSBENCH_NO_SIZE_CHECK", raising=False)
    with pytest.raises(SizeError, match="1000000003 simulations"):
        run_config(RunConfig(iterations=10**9))


def test_smc_with_too_few_iterations_says_why_its_posterior_falls_short(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # 11 iterations for 64 particles: before, no posterior and not a word about why.
    code, out, err = run(capsys, "--scene", "ball_drop", "--estimator", "smc", "--resolution", "32")
    assert code == 0
    assert "posterior (smc, 10 samples):" in out
    assert "warning: incomplete posterior: too few iterations for 64 particles" in err
    assert "at least 65 iterations" in err and "--iterations 65" in err
    assert "do not determine" not in err  # 10 prior draws say nothing about the data


def test_npe_says_a_blurred_observation_is_outside_its_training_data(
    capsys: pytest.CaptureFixture[str],
) -> None:
    pytest.importorskip("torch")
    argv = ["--estimator", "npe", "--blur", "3", "--seed", "0"]
    code, out, err = run(capsys, *argv)
    assert code == 0
    # Before: "the data do not determine a.mass", while the frames pin it down.
    assert "outside npe's training data (blur? another engine?): use smc" in err
    assert "do not determine" not in err and "not determined" not in out
    code, out, _ = run(capsys, *argv, "--json")
    domain = json.loads(out)["posterior"]["domain"]
    assert domain["inside"] is False and domain["distance"] > 100 * domain["threshold"]
    code, out, err = run(capsys, "--estimator", "npe", "--seed", "0", "--json")
    h = json.loads(out)
    assert h["posterior"]["domain"]["inside"] is True
    assert h["predictive"]["reproduced"] is True and h["predictive"]["draws"] == 59
    assert "warning" not in err
