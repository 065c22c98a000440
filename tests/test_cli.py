"""The command line itself: fast help that imports nothing heavy, and dispatch to the commands."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import pytest

from physbench.cli import COMMANDS, main

ROOT = Path(__file__).resolve().parents[1]


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "physbench.cli", *args],
        capture_output=True,
        text=True,
        env=os.environ,
    )


def test_help_is_fast_and_imports_nothing_heavy() -> None:
    code = (
        "import contextlib, io, sys, time; t = time.perf_counter(); from physbench.cli import "
        "main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n        main(['--help'])\n    except SystemExit:\n        pass\n"
        "heavy = [m for m in ('numpy', 'torch', 'optuna', 'hyperopt', 'dask', 'pandas', "
        "'matplotlib', 'pymunk', 'Box2D') if m in sys.modules]\n"
        "print(time.perf_counter() - t, heavy)"
    )
    best = min(
        float(
            subprocess.run(
                [sys.executable, "-c", code], capture_output=True, text=True, check=True
            ).stdout.split()[0]
        )
        for _ in range(3)
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip().endswith("[]"), out
    assert best < 0.5
    t = time.perf_counter()
    assert run_cli("--help").returncode == 0
    assert time.perf_counter() - t < 2.0  # includes interpreter start-up


def test_every_command_has_a_module_with_arguments_and_main(capsys) -> None:  # type: ignore[no-untyped-def]
    import importlib

    for module, help_ in COMMANDS.values():
        mod = importlib.import_module(f"physbench.commands.{module}")
        assert callable(mod.add_arguments) and callable(mod.main) and help_
    assert main([]) == 0 and "COMMAND" in capsys.readouterr().out
    assert main(["--version"]) == 0 and capsys.readouterr().out.startswith("physbench ")


def test_a_reader_that_leaves_early_ends_the_command_quietly() -> None:
    # `physbench run | head -1`: the pipe closes while run still prints its summary.
    code = (
        "import sys\n"
        "from physbench.cli import main\n"
        "sys.stdout.reconfigure(line_buffering=True)\n"
        "sys.exit(main(['run', '--iterations', '2', '--resolution', '32', '-q']))\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # the reader is gone before the first line
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141
    assert "Traceback" not in err and "BrokenPipeError" not in err, err


@pytest.mark.parametrize("delay", [0.3, 1.5])  # while importing and building, and while running
def test_ctrl_c_ends_the_command_with_one_line_and_status_130(delay: float) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "physbench", "run", "--iterations", "100000", "--resolution", "32"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        # A crash prints its C stack to stderr: CI once saw this run end by SIGSEGV (-11) with
        # nothing said, and 100 runs here at 1.2-2.0 s, 60 of them on a loaded machine, did not.
        env={**os.environ, "PYTHONFAULTHANDLER": "1"},
    )
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    # 130, or death by SIGINT (-2), which a shell reports as 130 too: `python -m` ends that way
    # in a window of a few ms while the command's modules are imported (measured at 0.15-0.17 s
    # here, 1 run in 12, and at 80 ms 1 run in 10; the `physbench` script never did), still with
    # the one line.
    assert proc.returncode in (130, -signal.SIGINT), (proc.returncode, err)
    assert err.endswith("physbench: interrupted\n") and "Traceback" not in err, err


def test_ctrl_c_while_the_command_is_imported_is_one_line_and_status_130() -> None:
    # What the console script does first, then a Ctrl-C while modules load (measured: a real
    # one lands there 10-80 ms after spawn, and used to print a KeyboardInterrupt traceback).
    code = (
        "import os, signal, time\n"
        "from physbench.__main__ import main\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "time.sleep(10)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=os.environ
    )
    assert (proc.returncode, proc.stderr) == (130, "physbench: interrupted\n")
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["physbench"] == "physbench.__main__:main"


def test_an_unexpected_error_is_one_line_saying_where_to_report_it(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import physbench.cli as cli
    import physbench.commands.plugins as command

    def broken(args: object) -> int:
        raise ValueError("an internal slip")

    monkeypatch.setattr(command, "main", broken)
    monkeypatch.setattr(cli, "issue_tracker", lambda: None)
    assert main(["plugins"]) == 70
    assert capsys.readouterr().err == (
        "physbench plugins: internal error: ValueError: an internal slip (please report it as "
        'the README\'s "Reporting a problem" says, with the command and the output of '
        "`physbench --version`; rerun with --debug for the traceback)\n"
    )
    readme = (ROOT / "README.md").read_text()
    assert "\n## Reporting a problem\n" in readme and "physbench --version" in readme
    monkeypatch.setattr(cli, "issue_tracker", lambda: "https://example.org/pb/issues")
    assert main(["plugins"]) == 70
    assert "please report it at https://example.org/pb/issues, with" in capsys.readouterr().err
    with pytest.raises(ValueError, match="an internal slip"):
        main(["--debug", "plugins"])


@pytest.mark.parametrize(
    ("override", "why"),
    [
        ("1", "PHYSBENCH_NO_SIZE_CHECK turned off the size check that refuses such a job"),
        ("", "more than the size check estimated"),
    ],
)
def test_running_out_of_memory_is_one_line_not_an_internal_error(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, override: str, why: str
) -> None:
    import physbench.commands.plugins as command

    def huge(args: object) -> int:
        raise MemoryError("Unable to allocate 26.8 TiB")

    monkeypatch.setattr(command, "main", huge)
    monkeypatch.setenv("PHYSBENCH_NO_SIZE_CHECK", override)
    assert main(["plugins"]) == 2
    assert capsys.readouterr().err == (
        "physbench plugins: error: out of memory: the job needed more memory than this machine "
        f"could give ({why}); make its sizes (frames, substeps, bodies, resolution, batch, seeds) "
        "smaller\n"
    )


def test_debug_shows_the_traceback_behind_a_reported_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["--debug", "run", "--estimator", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):")
    assert err.splitlines()[-1].startswith("physbench run: error: unknown estimator 'nope'")


def test_the_issue_tracker_comes_from_the_package_metadata(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import importlib.metadata as md

    from physbench.cli import issue_tracker

    class Meta:
        def __init__(self, urls: list[str]) -> None:
            self.urls = urls

        def get_all(self, key: str) -> list[str]:
            return self.urls if key == "Project-URL" else []

    urls = ["Homepage, https://example.org/pb", "Issues, https://example.org/pb/issues"]
    monkeypatch.setattr(md, "metadata", lambda name: Meta(urls))
    assert issue_tracker() == "https://example.org/pb/issues"
    monkeypatch.setattr(md, "metadata", lambda name: Meta(urls[:1]))
    assert issue_tracker() is None


@pytest.mark.parametrize(
    ("args", "status", "said"),
    [
        (("--version",), 0, "physbench "),
        (("bench", "no-such-spec.toml", "--out", "o"), 2, "spec file 'no-such-spec.toml' does"),
        (("bench", "no-such-spec.toml"), 2, "the following arguments are required: --out"),
        (("bench", "--help"), 0, "usage: physbench bench"),
    ],
)
def test_the_script_keeps_its_status_and_output_when_it_skips_the_teardown(
    args: tuple[str, ...], status: int, said: str, tmp_path: Path
) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "physbench", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env=os.environ,
        cwd=tmp_path,
    )
    assert proc.returncode == status, proc.stderr
    if status == 0:  # all of stdout arrived, not only what was flushed before the exit
        assert proc.stdout.startswith(said) and proc.stdout.endswith("\n"), proc.stdout
    else:
        assert "physbench bench: error: " + said in proc.stderr, proc.stderr


def test_python_warnings_reach_stderr_as_one_physbench_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    import warnings
    from pathlib import Path

    import physbench
    from physbench.cli import warnings_as_lines

    own = str(Path(physbench.__file__).parent / "estimators" / "resnet3d" / "weights.py")
    before = warnings.showwarning
    with warnings.catch_warnings(), warnings_as_lines("run"):
        warnings.simplefilter("always")
        warnings.warn_explicit("skipping weights 'w':\n  bad", UserWarning, own, 243)
        warnings.warn_explicit("overflow encountered in matmul", RuntimeWarning, "/x/numpy.py", 1)
    assert capsys.readouterr().err.splitlines() == [
        "physbench run: warning: skipping weights 'w': bad",
        "physbench run: warning: overflow encountered in matmul (RuntimeWarning)",
    ]
    assert warnings.showwarning is before  # restored afterwards


def test_a_ctrl_c_swallowed_by_a_finalizer_still_ends_the_command() -> None:
    # CI once hung here: the Ctrl-C landed inside pymunk's space finalizer (an ffi.gc callback),
    # Python printed "Exception ignored from callback for ffi.gc" and the run went on.
    code = (
        "import signal, sys, time\n"
        "import cffi\n"
        "import physbench.__main__ as entry\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "sys.unraisablehook = entry._redeliver_swallowed_interrupt\n"
        "ffi = cffi.FFI()\n"
        "def finalizer(_):\n"
        "    raise KeyboardInterrupt\n"
        "cell = ffi.gc(ffi.new('int *'), finalizer)\n"
        "del cell\n"
        "try:\n"
        "    time.sleep(20)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=os.environ
    )
    assert done.stdout == "interrupted\n", (done.stdout, done.stderr)
    assert "Exception ignored" not in done.stderr, done.stderr
