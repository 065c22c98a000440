"""Flags mean one thing everywhere: ``--bodies`` takes the spellings of ``--params``, a text option
never takes an empty value as "not given", a bad ``-R`` key lists only what ``-R`` can set, and
``-q`` leaves only the result."""

from __future__ import annotations

import argparse
import json

import pytest

from physbench.cli import COMMANDS, build_parser, main
from physbench.commands.arguments import check_renderer_options, split_bodies
from physbench.errors import OptionError, PhysbenchError

RUN = ["run", "--iterations", "1", "--resolution", "16", "--estimator", "random", "--json", "-q"]


@pytest.mark.parametrize("spelling", [["a b"], ["a+b"], ["a,b"], ["a", "b"], ["a", "b+"]])
def test_bodies_take_the_spellings_of_params(spelling: list[str]) -> None:
    assert split_bodies(spelling) == ("a", "b")


@pytest.mark.parametrize("spelling", [["a,b,a"], [""], [" + "]])
def test_a_bad_body_list_names_itself_and_the_spellings(spelling: list[str]) -> None:
    with pytest.raises(PhysbenchError, match=r"--bodies .*: expected body names such as a, a\+b"):
        split_bodies(spelling)


@pytest.mark.parametrize(("bodies", "keys"), [("a b", ["a.mass", "b.mass"]), ("b", ["b.mass"])])
def test_run_selects_the_bodies_spelled_like_params(
    bodies: str, keys: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*RUN, "--bodies", bodies]) == 0
    assert json.loads(capsys.readouterr().out)["keys"] == keys


def text_options(name: str) -> list[argparse.Action]:
    """The options of command ``name`` that take text (no numeric type, no fixed choices)."""
    parser = build_parser(name)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [
        a
        for a in sub.choices[name]._actions
        if a.option_strings and getattr(a.type, "__name__", "") == "text"
    ]


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_no_text_option_takes_an_empty_value(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    parser = build_parser(name)
    for action in text_options(name):
        flag = action.option_strings[-1]
        for empty in ("", "  "):
            with pytest.raises(SystemExit) as exc:
                parser.parse_args([name, flag, empty])
            assert exc.value.code == 2
            err = capsys.readouterr().err
            assert f"argument {'/'.join(action.option_strings)}: {empty!r} is empty" in err, err


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "--engine", ""],
        ["run", "--engine", ""],
        ["run", "--plot", ""],
        ["scenes", "--toml", ""],
        ["run", "--scene", ""],
    ],
)
def test_the_empty_values_that_used_to_mean_the_default_are_refused(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "'' is empty" in captured.err, captured


def test_every_command_refuses_empty_text_options_somewhere() -> None:
    # the walk above is not vacuous: the flags of the report are among those it checks
    flags = {name: {a.option_strings[-1] for a in text_options(name)} for name in COMMANDS}
    assert {"--engine", "--plot", "--renderer", "--estimator"} <= flags["run"]
    assert "--toml" in flags["scenes"] and "--engine" in flags["simulate"]


def test_a_bad_renderer_option_lists_only_what_r_can_set() -> None:
    with pytest.raises(OptionError) as exc:
        check_renderer_options("camera", {"tilt": 5, "focus_ring": 1})
    said = str(exc.value)
    assert said.startswith("-R focus_ring=1: renderer 'camera' (physbench's own) has no option")
    takes = said.split("the options -R can set: ")[1].split(", ")
    assert "tilt" in takes and "bitrate" in takes
    assert "resolution" not in said and "mode" not in takes  # set by --resolution/--render-mode
    with pytest.raises(OptionError, match=r"the options -R can set: none$"):
        check_renderer_options("raster", {"colour": "red"})
    check_renderer_options("camera", {"tilt": 5})  # a known option passes
    check_renderer_options("nope", {"x": 1})  # an unknown renderer is said where it is built


def test_simulate_names_only_the_r_options(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "-R", "colour=red"]) == 2
    err = capsys.readouterr().err
    assert "the options -R can set: none" in err and "besides" not in err, err
