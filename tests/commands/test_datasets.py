"""``physbench datasets`` and ``discover --dataset``: the shipped data sets reach the command line
without Python code (issue 28)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from physbench.cli import main


def test_the_listing_names_every_data_set_with_its_runs(capsys: pytest.CaptureFixture[str]) -> None:
    from physbench.datasets import dataset_names

    assert main(["datasets"]) == 0
    out = capsys.readouterr().out
    for name in dataset_names():
        assert any(line.startswith(f"{name}  (") for line in out.splitlines()), name
    assert "ball_drops  (22 runs: baseball, " in out and "discover --dataset NAME/RUN" in out


def test_a_run_selection_lists_its_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasets", "ball_drops/whiffle_ball_1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(":")[0] for line in lines] == ["whiffle_ball_1/1", "whiffle_ball_1/2"]
    assert "ball (y), 54 samples over 3.54 s" in lines[0]
    assert main(["datasets", "ball_drops/whiffle_ball_1/2"]) == 0
    assert capsys.readouterr().out.startswith("whiffle_ball_1/2: ")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["datasets", "nope"], "unknown data set 'nope'; known data sets: ball_drops, billiards"),
        (["datasets", "ball_drops/nope"], "data set 'ball_drops' has no run 'nope'; its runs: "),
        (["datasets", "--out", "x"], "--out 'x': name the DATASET to write out"),
    ],
)
def test_bad_selections_are_named(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_runs_written_out_are_what_discover_reads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from physbench.datasets import select
    from physbench.discover import load_runs

    assert main(["datasets", "ball_drops/whiffle_ball_1", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert f"wrote {tmp_path / 'whiffle_ball_1_1.csv'}" in captured.err
    assert f"physbench discover {tmp_path / 'whiffle_ball_1_1'}.csv --scene" in captured.out
    original = select("ball_drops/whiffle_ball_1/1")[0]
    (run,) = load_runs(tmp_path / "whiffle_ball_1_1.csv", tmp_path / "whiffle_ball_1_1.toml")
    assert run.scene == original.scene
    assert run.recording is not None and run.recording.fields == ("y",)
    assert run.recording.track("ball").y.tolist() == original.recording.track("ball").y.tolist()


def test_discover_takes_a_data_set_instead_of_files(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.commands import discover as command
    from physbench.errors import PhysbenchError

    seen: list[Any] = []

    def stop(runs: list[Any], *rest: Any) -> None:  # before any fit: the runs are what matters
        seen.extend(runs)
        raise PhysbenchError("stopped before fitting")

    monkeypatch.setattr(command, "check_size", stop)
    assert main(["discover", "--dataset", "ball_drops/whiffle_ball_1"]) == 2
    assert "stopped before fitting" in capsys.readouterr().err
    assert [r.name for r in seen] == ["whiffle_ball_1/1", "whiffle_ball_1/2"]
    assert seen[0].scene.name == "ball_drop_whiffle_ball_1_1"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["r.csv", "--dataset", "ball_drops"], "leave out RECORDING"),
        (["--scene", "ball_drop", "--dataset", "ball_drops"], "leave out --scene"),
        (["--dataset", "ball_drops", "--run", "x"], "leave out --run"),
        (["--scene", "ball_drop"], "give a RECORDING and its --scene"),
        (["r.csv"], "give a RECORDING and its --scene"),
    ],
)
def test_discover_needs_a_recording_and_scene_or_a_data_set(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    assert main(["discover", *argv]) == 2
    assert message in capsys.readouterr().err
