"""The command line: fast help, clear errors, scenes/plugins/simulate."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from physbench.cli import main


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "physbench.cli", *args],
        capture_output=True,
        text=True,
        env=os.environ,
    )


def test_help_is_fast_and_imports_nothing_heavy() -> None:
    code = (
        "import contextlib, io, sys, time; t = time.perf_counter(); from physbench.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n        main(['--help'])\n    except SystemExit:\n        pass\n"
        "heavy = [m for m in ('numpy', 'torch', 'optuna', 'hyperopt', 'dask', 'pandas', 'matplotlib', 'pymunk', 'Box2D') if m in sys.modules]\n"
        "print(time.perf_counter() - t, heavy)"
    )
    best = min(
        float(
            subprocess.run(
                [sys.executable, "-c", code], capture_output=True, text=True, check=True
            ).stdout.split()[0]
        )
        for _ in range(3)
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip().endswith("[]"), out
    assert best < 0.5
    t = time.perf_counter()
    assert run_cli("--help").returncode == 0
    assert time.perf_counter() - t < 2.0  # includes interpreter start-up


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
    assert "mass must be > 0" in err


def test_scenes_lists_unknowns(capsys) -> None:
    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    for name in (
        "three_circles",
        "second_order",
        "stacked_boxes",
        "bouncing_balls",
        "pendulum",
        "ball_drop",
    ):
        assert name in out
    assert "unknown mass:" in out


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
