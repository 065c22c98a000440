"""Numbers and names out of range are refused while parsing, with an argparse error that names the
flag, the value and what is accepted (issue 14: each of these was a traceback or was accepted)."""

from __future__ import annotations

import pytest

from physbench.cli import main

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
        (["discover", "r.csv", "--iterations", "0"], "argument --iterations: 0 is not a whole"),
        (["discover", "r.csv", "--seed", "-1"], "argument --seed: -1 is not a whole number in [0,"),
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
