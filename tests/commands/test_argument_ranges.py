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
