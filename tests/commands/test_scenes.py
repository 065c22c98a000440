"""``physbench scenes``: the registered scenes with their unknowns, and one as TOML."""

from __future__ import annotations

from physbench.cli import main


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
    # issue 28: every range says its unit
    assert "unknown mass (kg): a [2, 8], b [2, 8]" in out
    assert "unknown moment (kg·m²): arm [1e-05, 0.001]" in out
    assert "unknown elasticity (dimensionless): a [0.4, 1], b [0.4, 1]" in out
    assert all("(" in line for line in out.splitlines() if line.strip().startswith("unknown "))


def test_toml_of_one_scene_round_trips(capsys) -> None:  # type: ignore[no-untyped-def]
    from physbench.scene_toml import loads_scene
    from physbench.scenes import resolve_scene

    assert main(["scenes", "--toml", "pendulum"]) == 0
    assert loads_scene(capsys.readouterr().out) == resolve_scene("pendulum", 0)
    assert main(["scenes", "--toml", "nope"]) == 2
    assert "unknown scene 'nope'" in capsys.readouterr().err
