"""Scene generators: the decorator names and describes a ``(seed) -> Scene`` function without
wrapping it, and ``resolve_scene`` finds a registered generator's instance for a seed, or loads a
scene file (by its ``.toml`` suffix or because the path is a file)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from physbench.errors import UnknownNameError
from physbench.scene import Scene
from physbench.scene_toml import save_scene
from physbench.scenes import second_order, three_circles
from physbench.scenes.generator import resolve_scene, scene_generator


def test_the_decorator_names_and_describes_the_function_itself() -> None:
    def make(seed: int = 0) -> Scene:
        return second_order.generate(seed)

    gen = scene_generator("mine", "second order, under another name")(make)
    assert gen is make
    assert (gen.name, gen.description) == ("mine", "second order, under another name")
    assert gen(3) == second_order.generate(3)


def test_a_registered_name_gives_the_generators_instance_for_the_seed() -> None:
    assert resolve_scene("three_circles") == three_circles.generate(0)
    assert resolve_scene("three_circles", 4) == three_circles.generate(4)
    assert resolve_scene("three_circles", 4) != three_circles.generate(5)


def test_a_scene_file_is_loaded_and_the_seed_ignored(tmp_path: Path) -> None:
    scene = dataclasses.replace(second_order.generate(2), name="from_file")
    path = tmp_path / "mine.toml"
    save_scene(scene, path)
    assert resolve_scene(str(path)) == scene
    assert resolve_scene(str(path), seed=7) == scene
    plain = tmp_path / "mine_scene"  # a file without the suffix is a file all the same
    plain.write_text(path.read_text())
    assert resolve_scene(str(plain)) == scene


def test_an_unknown_name_lists_the_known_scenes() -> None:
    with pytest.raises(UnknownNameError, match=r"unknown scene 'nope'; known scenes: .*three_c"):
        resolve_scene("nope")
