"""Developer sessions: ``nox -s tests``, ``nox -s lint``, ``nox -s bench``."""

from __future__ import annotations

import nox

nox.options.sessions = ["lint", "tests"]
TORCH = "torch==2.13.0"  # a CPU wheel; a bare "torch" pulls a multi-GB CUDA build


@nox.session
def tests(session: nox.Session) -> None:
    session.install(TORCH)
    session.install("-e", ".[all]", "./plugins/physbench-scipy")
    session.run("pytest", "tests", "plugins/physbench-scipy/tests", *session.posargs)


@nox.session
def lint(session: nox.Session) -> None:
    session.install("ruff>=0.5")
    session.run("ruff", "check", "physbench", "tests", "benchmarks", "plugins")


@nox.session
def bench(session: nox.Session) -> None:
    session.install(TORCH)
    session.install("-e", ".[all]")
    session.run("pytest", "benchmarks/test_speed.py", "--benchmark-only", *session.posargs)
