"""Developer sessions: ``nox -s tests``, ``nox -s lint``, ``nox -s bench``,
``nox -s regression``, ``nox -s fuzz``, ``nox -s extended``."""

from __future__ import annotations

from pathlib import Path

import nox

nox.options.sessions = ["lint", "tests"]
TORCH = "torch==2.13.0"  # a CPU wheel; a bare "torch" pulls a multi-GB CUDA build


@nox.session
def tests(session: nox.Session) -> None:
    session.install(TORCH)
    session.install("-e", ".[all]")
    session.install("./plugins/physbench-scipy")
    session.run("pytest", "tests", "plugins/physbench-scipy/tests", *session.posargs)


@nox.session
def extended(session: nox.Session) -> None:
    """The tests marked ``extended`` that CI's pytest leaves out to stay within 10 minutes on 2
    cores: the other engine's half of the hidden-effect and bound suites (CI runs each effect and
    scene on one engine, in turn)."""
    session.install(TORCH)
    session.install("-e", ".[all]")
    session.run("pytest", "tests", "-m", "extended", *session.posargs)


@nox.session
def fuzz(session: nox.Session) -> None:
    """The property tests (scene files, recordings, observation files, resnet3d weights) with 10x
    the examples the normal test run tries."""
    session.install(TORCH)
    session.install("-e", ".[all]")
    session.run(
        "pytest",
        "tests/test_fuzz_inputs.py",
        "tests/estimators/resnet3d/test_weights_hardening.py",
        *session.posargs,
        env={"PHYSBENCH_FUZZ_SCALE": "10"},
    )


@nox.session
def lint(session: nox.Session) -> None:
    session.install("ruff==0.17.6")  # the version pyproject pins: formatting differs between them
    session.run("ruff", "check", ".")
    session.run("ruff", "format", "--check", ".")


@nox.session
def bench(session: nox.Session) -> None:
    session.install(TORCH)
    session.install("-e", ".[all]")
    session.run("pytest", "benchmarks/test_speed.py", "--benchmark-only", *session.posargs)


@nox.session
def regression(session: nox.Session) -> None:
    """Rerun benchmarks/smoke.toml from scratch and compare it with results/baseline; fails when an
    estimator x scene x unknown set got significantly worse (see `physbench compare --help`).
    In an environment where physbench is already installed (CI):
    nox --no-venv --no-install -s regression."""
    session.install("-e", ".")
    out = Path(session.create_tmp()) / "smoke"
    # --fresh: resuming would reuse the cells of the last session instead of testing this code
    session.run(
        "physbench",
        "bench",
        "benchmarks/smoke.toml",
        "--out",
        str(out),
        "--fresh",
        "-q",
        external=True,
    )
    session.run("physbench", "compare", str(out), "results/baseline", external=True)
