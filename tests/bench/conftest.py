"""A small sweep in which one estimator returns posteriors (``smc``) and one does not
(``random``), shared by the table, plot and report tests of calibration."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest

from physbench.bench.runner import run_sweep
from physbench.bench.spec import Spec, parse_spec
from physbench.plugins import get_registry, reset_registry

SMC = "smc(particles=16)"


@dataclass
class CalibratedSweep:
    spec: Spec
    out: Path
    table: pd.DataFrame


@pytest.fixture(scope="session")
def calibrated_sweep(tmp_path_factory: pytest.TempPathFactory) -> CalibratedSweep:
    """3 seeds of ``smc`` (16 particles, 40 simulations) and ``random`` on the two elasticities
    of three_circles at 16 px with stated noise: a few seconds. ``smc`` is registered through
    ``PHYSBENCH_PLUGINS`` where the installed metadata predates it."""
    out = tmp_path_factory.mktemp("calibrated")
    with pytest.MonkeyPatch.context() as mp:
        reset_registry()
        if "smc" not in get_registry().names("estimator"):
            mp.setenv("PHYSBENCH_PLUGINS", "physbench.estimators.smc")
            reset_registry()
        try:
            spec = parse_spec(
                {
                    "name": "calibrated",
                    "estimators": [{"name": "smc", "options": {"particles": 16}}, "random"],
                    "seeds": 3,
                    "iterations": 40,
                    "resolution": 16,
                    "noise": 0.05,
                    "scenes": [{"name": "three_circles", "unknowns": ["elasticity"]}],
                }
            )
            table = run_sweep(spec, out, executor="serial", progress=False).table
        finally:
            reset_registry()
    return CalibratedSweep(spec, out, table)
