"""One flag vocabulary across the subcommands (physbench.commands.arguments states it): every
parser is walked for ``--out``, ``--json``, ``--scene``, ``--params`` and ``-q/--quiet``; progress
reaches a terminal only, and every file written is echoed as ``wrote PATH`` on stderr."""

from __future__ import annotations

import argparse
import io
import json
import re
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from physbench.cli import COMMANDS, build_parser, main
from physbench.unknowns import split_params

#: commands that write files: all take --out for their result
WRITERS = {"run", "simulate", "track", "train", "bench", "plot", "discover", "datasets"}
#: the only other flags that name a file or folder to write
NAMED_OUTPUTS = {"--preview", "--plot", "--report", "--plate", "--track-out", "--save-observation"}
#: listings, instant, that print only their result
LISTINGS = {"scenes", "plugins", "datasets"}
#: commands with --json, and what it prints
JSON = {"run", "discover", "plugins"}
#: --scene is required where it must describe given data, else defaults to three_circles;
#: discover needs it with a RECORDING, not with a shipped --dataset (which brings its scenes)
SCENE_REQUIRED = {"track": True, "discover": None, "run": False, "simulate": False, "train": False}


def subparser(name: str) -> argparse.ArgumentParser:
    parser = build_parser(name)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[name]


def options(name: str) -> dict[str, argparse.Action]:
    return {s: a for a in subparser(name)._actions for s in a.option_strings}


def parse(name: str, *argv: str) -> argparse.Namespace:
    return build_parser(name).parse_args([name, *argv])


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_files_are_written_through_out_or_a_named_flag(name: str) -> None:
    opts = options(name)
    writes = {
        s for s, a in opts.items() if a.help and "write" in a.help and a.help != argparse.SUPPRESS
    }
    assert writes <= NAMED_OUTPUTS | {"--out"}, writes
    assert ("--out" in opts) == (name in WRITERS)
    if "--out" in opts:
        assert opts["--out"].metavar in {"FILE", "DIR", "REC.csv", "FILE.json"}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_but_the_listings_takes_q_and_quiet(name: str) -> None:
    opts = options(name)
    if name in LISTINGS:
        return
    assert opts["-q"] is opts["--quiet"] and opts["-q"].dest == "quiet"
    assert parse(name, *REQUIRED[name], "-q").quiet is True


#: the least each command needs to parse
REQUIRED: dict[str, list[str]] = {
    "scenes": [],
    "plugins": [],
    "simulate": [],
    "run": [],
    "train": [],
    "bench": ["spec.toml", "--out", "o"],
    "plot": ["o"],
    "compare": ["a", "b"],
    "datasets": [],
    "discover": ["r.csv", "--scene", "s.toml"],
    "track": ["v.mp4", "--scene", "s.toml", "--out", "r.csv"],
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_json_is_a_switch_for_stdout(name: str) -> None:
    opts = options(name)
    assert ("--json" in opts) == (name in JSON)
    if name in JSON:
        assert parse(name, *REQUIRED[name], "--json").json
        assert not parse(name, *REQUIRED[name]).json
        if name != "plugins":  # a listing has no file to point to
            assert "JSON on stdout" in opts["--json"].help and "--out" in opts["--json"].help


@pytest.mark.parametrize("name", sorted(SCENE_REQUIRED))
def test_scene_takes_a_name_or_a_toml_file(name: str) -> None:
    action = options(name)["--scene"]
    assert action.metavar == "NAME|FILE" and ".toml file" in action.help
    assert action.required is bool(SCENE_REQUIRED[name])
    if SCENE_REQUIRED[name] is None:
        assert action.default is None and "required with RECORDING" in action.help
    elif not action.required:
        assert action.default is None and "(default: three_circles)" in action.help
    rest = [a for a in REQUIRED[name] if a not in ("--scene", "s.toml")]
    for value in ("ball_drop", "drop.toml"):
        assert parse(name, *rest, "--scene", value).scene == value


@pytest.mark.parametrize("argv", [["mass+elasticity"], ["mass,elasticity"], ["mass", "elasticity"]])
@pytest.mark.parametrize("name", ["run", "train"])
def test_params_accepts_the_three_spellings(name: str, argv: list[str]) -> None:
    args = parse(name, "--params", *argv)
    assert split_params(args.params) == ("mass", "elasticity")
    assert parse(name).params == ["mass"]


@pytest.mark.parametrize("value", ["mass+elasticity", "mass,elasticity", "mass elasticity"])
def test_a_spec_unknown_set_takes_the_same_spellings(tmp_path: Path, value: str) -> None:
    from physbench.bench.spec import load_spec

    path = tmp_path / "s.toml"
    path.write_text(
        f'estimators = ["random"]\nseeds = 1\niterations = 2\n[[scenes]]\nname = "three_circles"'
        f'\nunknowns = ["{value}"]\n'
    )
    assert load_spec(path).scenes[0].unknowns == (("mass", "elasticity"),)


@pytest.mark.parametrize("value", ["", "mass+mass", " , "])
def test_a_bad_unknown_set_names_itself(value: str) -> None:
    from physbench.errors import PhysbenchError

    with pytest.raises(PhysbenchError, match=re.escape("mass+elasticity")):
        split_params(value)


def test_run_identifies_a_plus_joined_set(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["run", "--params", "mass+elasticity", "--iterations", "1", "--resolution", "32"]
    assert main([*argv, "--estimator", "random", "--json", "-q"]) == 0
    history = json.loads(capsys.readouterr().out)  # stdout holds the JSON alone
    assert {k.split(".")[1] for k in history["keys"]} == {"mass", "elasticity"}


def test_the_old_mode_spelling_parses_but_help_shows_one_name() -> None:
    assert parse("run", "--mode", "mask").render_mode == "mask"
    assert "--mode" not in subparser("run").format_help()
    assert "--render-mode" in subparser("run").format_help()


def test_discover_resolves_a_registered_scene_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The scene is found before the recording is read: the error is about the missing file.
    assert main(["discover", str(tmp_path / "none.csv"), "--scene", "ball_drop"]) == 2
    err = capsys.readouterr().err
    assert "recording file" in err and "does not exist" in err, err


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


RUN = ["run", "--iterations", "3", "--resolution", "32", "--estimator", "random"]


def test_progress_reaches_a_terminal_but_not_a_pipe(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    assert main(RUN) == 0
    assert "\r" not in capsys.readouterr().err  # capsys' stderr is no terminal
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(RUN) == 0
    assert "\r" in terminal.getvalue()
    terminal.truncate(0)
    assert main([*RUN, "-q"]) == 0
    assert "\r" not in terminal.getvalue()


@pytest.fixture
def recorded_stages(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The stage names a command reports to its progress display."""
    from physbench.commands import console

    seen: list[str] = []

    @contextmanager
    def record(args: argparse.Namespace, names: Sequence[str], desc: str) -> Iterator[Any]:
        seen.append(f"{desc}: {len(names)}")
        yield seen.append

    monkeypatch.setattr(console, "stages", record)
    return seen


def test_discover_reports_its_stages(
    tmp_path: Path, recorded_stages: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    from physbench.commands.discover import STAGES
    from physbench.recording import Recording, write_recordings
    from physbench.scene import Body, Circle, Scene
    from physbench.scene_toml import save_scene
    from physbench.simulators.pymunk_sim import PymunkSimulator

    scene = Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=(2.0, 0.5), mass=1.0),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=20.0,
        frames=21,
        substeps=4,
    ).validate()
    write_recordings(
        tmp_path / "r.csv", Recording.from_trajectory(PymunkSimulator().simulate(scene))
    )
    save_scene(scene, tmp_path / "s.toml")
    argv = ["discover", str(tmp_path / "r.csv"), "--scene", str(tmp_path / "s.toml")]
    assert main([*argv, "--effects", "linear_drag", "--json"]) == 0
    assert recorded_stages == [f"discover: {len(STAGES)}", *STAGES]
    verdict = json.loads(capsys.readouterr().out)  # --json: stdout holds the JSON alone
    assert verdict["causes"] == []


def test_plot_reports_its_stages_and_echoes_its_files(
    tmp_path: Path, recorded_stages: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("matplotlib")
    from physbench.bench.plots import FIGURE_GROUPS
    from physbench.bench.runner import run_sweep
    from physbench.bench.spec import parse_spec

    spec = parse_spec(
        {
            "name": "v",
            "estimators": ["random"],
            "seeds": 1,
            "iterations": 2,
            "resolution": 16,
            "scenes": ["three_circles"],
        }
    )
    run_sweep(spec, tmp_path / "sweep", executor="serial", progress=False)
    out = tmp_path / "elsewhere"
    argv = ["plot", str(tmp_path / "sweep"), "--out", str(out), "--landscape-seeds", "0"]
    assert main(argv) == 0
    assert recorded_stages == [f"plot: {len(FIGURE_GROUPS) + 1}", *FIGURE_GROUPS, "report"]
    captured = capsys.readouterr()
    written = [line.removeprefix("wrote ") for line in captured.err.splitlines()]
    assert written and all(Path(p).is_file() for p in written)
    assert {str(out / "report.html"), str(out / "win_rate.csv")} <= set(written)
    assert captured.out.count("\n") == 1  # the summary line only
    assert main([*argv, "-q"]) == 0  # quiet: the summary line alone, no 'wrote' lines
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out.count("\n") == 1, captured


def test_train_is_quiet_in_a_pipe_and_says_where_it_resumes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("torch")
    import physbench.estimators.resnet3d.train as train_module

    calls: list[dict] = []

    def fake_train(spec, net, cfg, out, *, resume, progress):  # type: ignore[no-untyped-def]
        calls.append({"resume": resume, "progress": progress})
        raise KeyboardInterrupt  # stop before the evaluation; what matters is what was passed

    monkeypatch.setattr(train_module, "train", fake_train)
    (tmp_path / "checkpoint.safetensors").write_bytes(b"")
    (tmp_path / "checkpoint.json").write_text(json.dumps({"samples": 2000}))
    assert main(["train", "--out", str(tmp_path), "--samples", "8000"]) == 130
    assert calls == [{"resume": True, "progress": False}]  # stderr is a pipe here
    err = capsys.readouterr().err
    assert f"resuming from {tmp_path / 'checkpoint.safetensors'} at 2000 of 8000 samples" in err
    assert main(["train", "--out", str(tmp_path), "--no-resume"]) == 130
    assert "resuming" not in capsys.readouterr().err


def test_run_echoes_every_file_it_writes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("matplotlib")
    # the plot goes into a folder that does not exist yet: it is created
    plot, out, obs = tmp_path / "new" / "c.png", tmp_path / "h.json", tmp_path / "o.npz"
    argv = [*RUN, "--plot", str(plot), "--out", str(out), "--save-observation", str(obs)]
    assert main(argv) == 0
    captured = capsys.readouterr()
    for path in (plot, out, obs):
        assert path.is_file() and f"wrote {path}\n" in captured.err
    assert "wrote" not in captured.out  # stdout holds only the result
    assert json.loads(out.read_text())["iterations"]
    assert main([*argv, "-q"]) == 0  # quiet: the final line alone
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out.startswith("normalized min MSE after 3 iterations")
    assert captured.out.count("\n") == 1


def test_simulate_echoes_on_stderr_and_is_silent_with_q(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "s.npz"
    assert main(["simulate", "--out", str(out), "--resolution", "16"]) == 0
    captured = capsys.readouterr()
    assert f"wrote {out}" not in captured.out and captured.err == f"wrote {out}\n"
    out.unlink()
    assert main(["simulate", "--out", str(out), "--resolution", "16", "-q"]) == 0
    assert capsys.readouterr() == ("", "") and out.is_file()
