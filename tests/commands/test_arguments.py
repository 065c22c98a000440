"""The arguments several commands share: ``KEY=VALUE`` options parse as JSON or stay text and
errors name the flag; the renderer choice defaults to the default renderer with no options, and
builds the renderer with the parsed resolution and render mode."""

from __future__ import annotations

import argparse

import pytest

from physbench.commands.arguments import (
    RENDER_MODES,
    add_renderer_arguments,
    add_renderer_choice,
    make_renderer_from,
    parse_key_values,
    renderer_choice,
)
from physbench.errors import PhysbenchError
from physbench.render.base import DEFAULT_RENDERER, MODES


def _parse(*argv: str, resolution: int = 64) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    add_renderer_arguments(p, resolution=resolution)
    return p.parse_args(list(argv))


def test_values_parse_as_json_else_stay_text() -> None:
    items = ["n=5", "x=0.25", "flag=true", "none=null", "xs=[1, 2]", "name=cmaes", "t= 2 "]
    assert parse_key_values(items, "--option") == {
        "n": 5,
        "x": 0.25,
        "flag": True,
        "none": None,
        "xs": [1, 2],
        "name": "cmaes",
        "t": 2,
    }


def test_keys_are_stripped_text_keeps_its_equals_signs_and_the_last_value_wins() -> None:
    got = parse_key_values([" gain =0.5", "expr=a=b", "gain=1", "empty="], "-R")
    assert got == {"gain": 1, "expr": "a=b", "empty": ""}


@pytest.mark.parametrize("item", ["startup", "=5", " =5"])
def test_an_item_without_a_key_names_the_flag(item: str) -> None:
    with pytest.raises(PhysbenchError) as err:
        parse_key_values(["ok=1", item], "--renderer-option")
    assert str(err.value) == (
        f"--renderer-option {item!r}: expected KEY=VALUE, e.g. --renderer-option startup=5"
    )


def test_renderer_choice_defaults_to_the_default_renderer_without_options() -> None:
    args = _parse()
    assert renderer_choice(args) == (DEFAULT_RENDERER, {})
    assert (args.resolution, args.render_mode) == (64, None)  # None: the renderer's first mode
    assert _parse(resolution=32).resolution == 32


def test_renderer_choice_reads_the_name_and_repeated_options() -> None:
    args = _parse("--renderer", "squares", "-R", "size=3", "--renderer-option", "tag=big")
    assert renderer_choice(args) == ("squares", {"size": 3, "tag": "big"})
    bad = _parse("-R", "size")
    with pytest.raises(PhysbenchError, match=r"^--renderer-option 'size': expected KEY=VALUE"):
        renderer_choice(bad)


def test_the_choice_alone_adds_no_resolution_or_mode() -> None:
    p = argparse.ArgumentParser()
    add_renderer_choice(p, renderer_help="only this")
    assert vars(p.parse_args([])) == {"renderer": None, "renderer_option": []}


def test_render_modes_are_the_renderers_and_mode_is_an_alias() -> None:
    assert RENDER_MODES == MODES
    assert _parse("--mode", "mask").render_mode == "mask"
    with pytest.raises(SystemExit):
        _parse("--render-mode", "depth")


def test_make_renderer_from_uses_the_resolution_and_mode() -> None:
    ren = make_renderer_from(_parse("--resolution", "24", "--render-mode", "instance"))
    assert (ren.name, ren.resolution, ren.mode) == (DEFAULT_RENDERER, 24, "instance")


def test_without_a_mode_each_renderer_gets_its_first_layout() -> None:
    assert make_renderer_from(_parse("--resolution", "24")).mode == "mark"
    camera = make_renderer_from(_parse("--renderer", "camera", "--resolution", "24"))
    assert (camera.name, camera.mode) == ("camera", "rgb")
    with pytest.raises(PhysbenchError, match="renderer 'camera' supports modes rgb"):
        make_renderer_from(_parse("--renderer", "camera", "--render-mode", "mark"))
