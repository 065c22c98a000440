"""The probe before a run: an unknown that moves no pixel is named, a visible one is not."""

from __future__ import annotations

import pytest

from physbench.components import create
from physbench.experiment import RunConfig, config_space, run_config
from physbench.loop import History, draw_problem
from physbench.posterior.identifiability import describe, probe, unseen
from physbench.render.raster import RasterRenderer
from physbench.scenes.generator import resolve_scene


def _probes(scene_name: str, params: tuple[str, ...]):  # type: ignore[no-untyped-def]
    config = RunConfig(scene=scene_name, params=params)
    scene = resolve_scene(scene_name)
    space = config_space(config, scene)
    _, initial = draw_problem(space, 0)
    renderer = RasterRenderer(resolution=32)
    return probe(scene, space, create("simulator", "pymunk"), renderer, initial)


def test_a_free_fall_does_not_show_its_mass() -> None:
    probes = _probes("ball_drop", ("mass",))
    assert unseen(probes) == ("ball.mass",)
    assert probes[0].change == 0.0 and probes[0].low < probes[0].at < probes[0].high
    sentence = describe(probes)
    assert sentence is not None and sentence.startswith("ball.mass (tried ")
    assert "cannot identify it" in sentence


def test_colliding_masses_and_elasticities_are_seen() -> None:
    probes = _probes("three_circles", ("mass", "elasticity"))
    assert len(probes) == 4 and unseen(probes) == ()
    assert describe(probes) is None
    assert all(p.change > 0 for p in probes)


def test_a_run_records_the_unseen_and_says_so_before_the_loop() -> None:
    said: list[str] = []
    history = run_config(
        RunConfig(scene="ball_drop", iterations=1, resolution=32), notice=said.append
    )
    assert history.unseen == ("ball.mass",) and len(said) == 1
    assert History.from_dict(history.to_dict()).unseen == ("ball.mass",)
    quiet = run_config(RunConfig(scene="ball_drop", iterations=1, resolution=32), probe=False)
    assert quiet.unseen == ()


def test_the_cli_warns_and_marks_the_estimate(capsys: pytest.CaptureFixture[str]) -> None:
    from physbench.cli import main

    assert main(["run", "--scene", "ball_drop", "--iterations", "1", "--resolution", "32"]) == 0
    out, err = capsys.readouterr()
    assert "physbench run: warning: ball.mass (tried" in err
    assert "(unseen: a guess)" in out
    assert main(["run", "--iterations", "1", "--resolution", "32"]) == 0
    out, err = capsys.readouterr()
    assert "warning" not in err and "unseen" not in out
