"""Synthetic recordings with a hidden effect (physbench/discover/synthetic.py)."""

from __future__ import annotations

import numpy as np

from physbench.discover.synthetic import SyntheticRun, make_case
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_a_synthetic_run_is_seeded_and_names_what_is_hidden():
    a = make_case("linear_drag", "puck", 3, PymunkSimulator())
    b = make_case("linear_drag", "puck", 3, PymunkSimulator())
    assert isinstance(a, SyntheticRun) and a.name == "linear_drag/puck/3" and a.run.name == a.name
    assert a.truth == b.truth and set(a.truth) == {"c"}
    assert a.run.recording is not None and b.run.recording is not None
    assert np.array_equal(a.run.recording.track("puck").x, b.run.recording.track("puck").x)
    control = make_case(None, "puck", 3, PymunkSimulator())
    assert control.effect is None and control.truth == {} and control.name == "control/puck/3"
