"""The example plugin: physbench's estimator kit (one test per method x check), discovery through
the entry point, and a real ``physbench run``. Needs the package installed
(``pip install ./plugins/physbench-scipy``)."""

from __future__ import annotations

import numpy as np
import pytest
from physbench_scipy import ScipyMinimize

from physbench.cli import main
from physbench.plugins import build_registry
from physbench.testing import Check, Subject, parametrize_with_checks, run_toy

BAD_OPTIONS = [{"method": "bfgs"}, {"step": 0.0}, {"xatol": -1}]


@parametrize_with_checks(
    [
        Subject(ScipyMinimize, {"method": m}, {"bad_options": BAD_OPTIONS}, id=f"scipy-{m}")
        for m in ("nelder-mead", "powell")
    ]
)
def test_conformance(component: Subject, check: Check) -> None:
    check(component)


def test_found_through_the_entry_point() -> None:
    info = build_registry(env=False).info("estimator", "scipy")
    assert info.obj is ScipyMinimize
    assert info.package == "physbench-scipy"


@pytest.mark.parametrize("method", ["nelder-mead", "powell"])
def test_improves_on_the_initial_guess(method: str) -> None:
    runs = [
        run_toy(
            ScipyMinimize, {"method": method}, iterations=30, params=("mass", "elasticity"), seed=s
        )
        for s in range(6)
    ]
    assert all(h.min_loss < h.iterations[0].loss for h in runs)
    assert np.mean([h.best_nmse for h in runs]) < 0.5 * np.mean([h.initial_nmse for h in runs])


def test_restarts_after_converging() -> None:
    h = run_toy(ScipyMinimize, {"method": "nelder-mead", "xatol": 0.2}, iterations=30, seed=1)
    xs = np.array([[r.params[k] for k in h.keys] for r in h.iterations])
    assert len(np.unique(xs, axis=0)) > 10  # kept exploring instead of repeating one point


def test_physbench_run_uses_it(capsys: pytest.CaptureFixture[str]) -> None:
    argv = [
        "run",
        "--estimator",
        "scipy",
        "-o",
        "method=powell",
        "--iterations",
        "6",
        "--resolution",
        "32",
        "-q",
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "normalized min MSE after 6 iterations" in out
