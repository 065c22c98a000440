"""Residual statistics that point at causes, as numbers (physbench/discover/diagnostics.py)."""

from __future__ import annotations

import math

import numpy as np

from physbench.discover import Diagnosis, diagnose
from physbench.discover.diagnostics import _oscillation
from physbench.recording import Track


def test_envelope_diagnostic_tells_viscous_from_coulomb():
    t = np.arange(0, 12, 0.01)
    w = 2 * math.pi
    visc = Track(t, 0 * t, 0 * t, 1.0 * np.exp(-0.15 * t) * np.cos(w * t))
    coul = Track(t, 0 * t, 0 * t, np.maximum(1.0 - 0.06 * t, 0.0) * np.cos(w * t))
    sim = Track(t, 0 * t, 0 * t, np.cos(w * t))
    for track, want, trend in (
        (visc, "joint_viscous_damping", "linear"),
        (coul, "joint_coulomb_friction", "constant"),
    ):
        env = [f for f in _oscillation("r", "arm", track, sim) if f.kind == "envelope"]
        assert env and env[0].suggests == (want,) and env[0].trend == trend
        f = env[0]
        assert (f.run, f.body, f.event, f.statistic) == (
            "r",
            "arm",
            "jointed",
            "loss_per_half_swing",
        )
        v = f.values
        # the loss per half swing, from the first and last observed peaks
        assert f.size == (v["observed_first"] - v["observed_last"]) / (v["half_swings"] - 1)


def test_diagnose_measures_the_excess_deceleration_of_a_dragged_puck(puck, puck_base):
    values = dict(puck_base.model.values)
    d = diagnose(puck_base)
    assert isinstance(d, Diagnosis) and puck_base.model.values == values  # the model is untouched
    (free,) = [f for f in d.findings if f.kind == "free_flight"]
    assert (free.run, free.body, free.event) == (puck.run.name, "puck", "free")
    assert free.statistic == "excess_deceleration" and free.size == free.values[free.statistic]
    # drag c/m decelerates by about c/m · v (less what the fitted initial state absorbs)
    expected = puck.truth["c"] / puck.run.scene.bodies[0].mass * free.values["mean_speed"]
    assert 0.5 * expected < free.size < 1.5 * expected
    assert free.size > 3 * free.stderr and "linear_drag" in free.suggests
    assert set(d.breakdown.per_event["puck"]) == {"free"}
    assert d.breakdown.per_field["puck"]["x"] > d.breakdown.per_field["puck"]["y"]
