"""Numbers and names out of range are refused while parsing, with an argparse error that names the
flag, the value and what is accepted (issue 14: each of these was a traceback or was accepted).

Every numeric flag of every command goes through one parser (:class:`physbench.numeric.Number`,
issue 28: ``discover --floor nan`` was accepted and switched discovery off): the flags are read
from the parsers themselves, so a new one is covered without a change here, and each is fed
non-finite, huge, tiny and malformed values.
"""

from __future__ import annotations

import argparse
import math
import os

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from physbench.cli import COMMANDS, build_parser, main
from physbench.numeric import Number

LONG_SCENE = "x" * 100_000


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["scenes", "--seed", "-1"],
            "argument --seed: -1 is not a whole number in [0, 4294967295]",
        ),
        (
            ["simulate", "--seed", "-1"],
            "argument --seed: -1 is not a whole number in [0, 4294967295]",
        ),
        (["run", "--seed", "-1"], "argument --seed: -1 is not a whole number in [0, 4294967295]"),
        (["run", "--blur", "-1"], "argument --blur: -1 is not a finite number in [0, 4096]"),
        (["run", "--blur", "1e30"], "argument --blur: 1e30 is not a finite number in [0, 4096]"),
        (["run", "--blur", "nan"], "argument --blur: nan is not a finite number in [0, 4096]"),
        (
            ["run", "--resolution", "100000"],
            "argument --resolution: 100000 is not a whole number in [1, 4096]",
        ),
        (["run", "--resolution", "a"], "argument --resolution: 'a' is not a whole number in"),
        (["run", "--scene", LONG_SCENE], "(100000 characters) is longer than a scene name or path"),
        (["train", "--val-groups", "0"], "argument --val-groups: 0 is not a whole number >= 1"),
        (["train", "--eval-every", "0"], "argument --eval-every: 0 is not a whole number >= 1"),
        (["train", "--resolution", "0"], "argument --resolution: 0 is not a whole number in [1,"),
        (
            ["train", "--samples", str(10**12)],
            "argument --samples: 1000000000000 is not a whole number in [1, 1000000000]",
        ),
        (["train", "--samples", "0"], "argument --samples: 0 is not a whole number in [1,"),
        (["train", "--batch", "0"], "argument --batch: 0 is not a whole number in [1, 4096]"),
        (["train", "--batch", "1e9"], "argument --batch: '1e9' is not a whole number in [1,"),
        (["train", "--frames", "0"], "argument --frames: 0 is not a whole number in [2, 64]"),
        (["train", "--frames", "1000"], "argument --frames: 1000 is not a whole number in [2, 64]"),
        (["train", "--workers", "-1"], "argument --workers: -1 is not a whole number in [0, 64]"),
        (["train", "--workers", "10000"], "argument --workers: 10000 is not a whole number in [0,"),
        (["run", "--noise", "-0.1"], "argument --noise: -0.1 is not a finite number in [0, 1]"),
        (["run", "--noise", "inf"], "argument --noise: inf is not a finite number in [0, 1]"),
        (["run", "--noise", "5"], "argument --noise: 5 is not a finite number in [0, 1]"),
        (["run", "--iterations", "0"], "argument --iterations: 0 is not a whole number >= 1"),
        (["discover", "r.csv", "--iterations", "0"], "argument --iterations: 0 is not a whole"),
        (["discover", "r.csv", "--seed", "-1"], "argument --seed: -1 is not a whole number in [0,"),
        (
            ["discover", "r.csv", "--floor", "nan"],
            "argument --floor: nan is not a finite number >=",
        ),
        (
            ["discover", "r.csv", "--floor", "inf"],
            "argument --floor: inf is not a finite number >=",
        ),
        (["discover", "r.csv", "--min-delta-bic", "nan"], "argument --min-delta-bic: nan is not"),
        (["discover", "r.csv", "--min-gain", "1"], "argument --min-gain: 1 is not a finite number"),
        (
            ["discover", "r.csv", "--holdout", "0.95"],
            "--holdout: 0.95 is not a finite number in [0.05, 0.8]",
        ),
        (["compare", "a", "b", "--min-ratio", "inf"], "argument --min-ratio: inf is not a finite"),
        (["compare", "a", "b", "--alpha", "nan"], "argument --alpha: nan is not a finite number"),
        (["plot", "d", "--threshold", "inf"], "argument --threshold: inf is not a finite number"),
        (["track", "v.mp4", "--seed", "-1"], "argument --seed: -1 is not a whole number in [0,"),
        (["train", "--lr", "nan"], "argument --lr: nan is not a finite number in (0, 1]"),
        (["bench", "s.toml", "--workers", "0"], "argument --workers: 0 is not a whole number in"),
        (["run", "--start=-inf"], "argument --start: -inf is not a finite number >= 0 (s)"),
    ],
    ids=lambda v: " ".join(v)[:40] if isinstance(v, list) else None,
)
def test_out_of_range_values_are_argparse_errors(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert f"physbench {argv[0]}: error: " in err and message in err, err[-500:]


def test_train_limits_agree_with_the_training_code() -> None:
    """The parser repeats them so as not to import the trainer; they must be the same numbers."""
    from physbench.commands import train as command
    from physbench.estimators.resnet3d import sidecar
    from physbench.estimators.resnet3d import train as trainer

    assert command.MAX_SAMPLES == trainer.MAX_SAMPLES
    assert command.MAX_BATCH == trainer.MAX_BATCH
    assert command.MAX_WORKERS == trainer.MAX_WORKERS
    assert command.FRAMES == sidecar.FRAMES


#: The least each command needs to parse (a new command must be added here).
REQUIRED: dict[str, list[str]] = {
    "scenes": [],
    "plugins": [],
    "datasets": [],
    "simulate": [],
    "run": [],
    "train": [],
    "bench": ["spec.toml", "--out", "o"],
    "plot": ["o"],
    "compare": ["a", "b"],
    "discover": ["r.csv", "--scene", "s.toml"],
    "track": ["v.mp4", "--scene", "s.toml", "--out", "r.csv"],
}


def _actions(command: str) -> list[argparse.Action]:
    parser = build_parser(command)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return list(sub.choices[command]._actions)


def _numeric_flags() -> list[tuple[str, str, str, Number]]:
    """(command, flag, dest, range) of every option whose values are numbers."""
    return [
        (command, a.option_strings[-1], a.dest, a.type)
        for command in sorted(COMMANDS)
        for a in _actions(command)
        if isinstance(a.type, Number)
    ]


NUMERIC = _numeric_flags()
#: Values that broke or silently switched off options before: non-finite, beyond every range,
#: beyond float or int limits, below the smallest normal float, malformed.
EXTREMES = [
    "nan", "NaN", "-nan", "inf", "-inf", "Infinity", "-Infinity", "1e999", "-1e999", "1e308",
    "-1e308", "5e-324", "1e-320", "0", "-0", "-0.0", "-1", "1", "0.5", "1.5", "4294967296",
    str(2**63), str(-(2**63)), str(10**30), "9" * 5000, "", " ", "0x10", "1_000", "1e3", "True",
    "None", "½",
]  # fmt: skip


def _parse(command: str, flag: str, text: str) -> argparse.Namespace:
    return build_parser(command).parse_args([command, *REQUIRED[command], f"{flag}={text}"])


def test_every_numeric_option_is_found_and_none_parses_with_bare_int_or_float() -> None:
    assert sorted(REQUIRED) == sorted(COMMANDS)
    bare = [
        (command, a.option_strings or a.dest)
        for command in COMMANDS
        for a in _actions(command)
        if a.type in (int, float)
    ]
    assert not bare, f"numeric flags that bypass physbench.numeric: {bare}"
    found = {(c, f) for c, f, _, _ in NUMERIC}
    # a sample of what the parsers must expose (the walk itself finds every one)
    for expected in [
        ("discover", "--floor"),
        ("discover", "--min-delta-bic"),
        ("discover", "--holdout"),
        ("run", "--blur"),
        ("run", "--start"),
        ("train", "--lr"),
        ("bench", "--workers"),
        ("compare", "--min-ratio"),
        ("plot", "--threshold"),
        ("track", "--seed"),
    ]:
        assert expected in found
    assert len(NUMERIC) >= 40


@pytest.mark.parametrize(
    ("command", "flag", "dest", "number"), NUMERIC, ids=[f"{c} {f}" for c, f, _, _ in NUMERIC]
)
def test_extreme_values_of_every_numeric_option_are_refused_or_in_range(
    capsys: pytest.CaptureFixture[str], command: str, flag: str, dest: str, number: Number
) -> None:
    for text in EXTREMES:
        _check(capsys, command, flag, dest, number, text)


def _check(
    capsys: pytest.CaptureFixture[str],
    command: str,
    flag: str,
    dest: str,
    number: Number,
    text: str,
) -> None:
    """``flag=text`` either parses to a finite number in the flag's range, or is an argparse
    error (status 2) naming the flag, the value and the range."""
    try:
        args = _parse(command, flag, text)
    except SystemExit as exc:
        err = capsys.readouterr().err
        assert exc.code == 2, (command, flag, text)
        assert f"argument {flag}: " in err and number.describe() in err, err[-300:]
        return
    value = getattr(args, dest)
    assert number.accepts(value) and math.isfinite(value), (command, flag, text, value)
    if text.strip().lower().lstrip("-") in ("nan", "inf", "infinity", "1e999"):
        raise AssertionError(f"{command} {flag}={text} was accepted as {value!r}")


FUZZ = settings(
    max_examples=300 * int(os.environ.get("PHYSBENCH_FUZZ_SCALE", "1")),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)


@FUZZ
@given(
    st.sampled_from(NUMERIC),
    st.one_of(
        st.sampled_from(EXTREMES),
        st.floats(allow_nan=True, allow_infinity=True).map(repr),
        st.floats().map(lambda v: f"{v:.17g}"),
        st.integers().map(str),
        st.text(max_size=8),
    ),
)
def test_any_value_of_a_numeric_option_is_refused_or_in_range(
    capsys: pytest.CaptureFixture[str], option: tuple[str, str, str, Number], text: str
) -> None:
    if "\x00" in text:
        return  # not a value a shell can pass
    _check(capsys, *option, text)


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "--option", "startup=NaN"],
        ["run", "--renderer-option", "tilt=Infinity"],
        ["run", "--renderer-option", "tilt=-Infinity"],
        ["run", "--option", "x=1e999"],
        ["run", "--option", "x=[1, NaN]"],
        ["simulate", "--set", "a.mass=nan"],
        ["simulate", "--set", "a.mass=inf"],
        ["simulate", "--effect", "linear_drag:c=nan"],
        ["simulate", "--effect", "linear_drag:c=1e999"],
    ],
    ids=" ".join,
)
def test_numbers_inside_key_value_options_are_finite(
    capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    """The options whose values carry numbers as text (estimator and renderer options, scene and
    effect values) refuse non-finite ones too, naming the option."""
    assert main([*argv, "--iterations", "1"] if argv[0] == "run" else argv) == 2
    err = capsys.readouterr().err
    assert f"physbench {argv[0]}: error: {argv[1]} " in err and "finite" in err, err
