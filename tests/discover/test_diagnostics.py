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


def test_a_body_the_scene_starts_at_rest_that_moves_from_the_first_samples_is_named(noisy):
    """A clip that begins after the release, against a scene that starts the ball at rest: the
    start is named (no effect suggested), with the initial velocity the data show; a ball
    that does start at rest, slowed by drag, gets no such finding."""
    from dataclasses import replace

    from physbench.discover import Run, Settings, fit_base
    from physbench.discover.phrasing import describe
    from physbench.effects import QuadraticDrag
    from physbench.scene import Body, Circle, Scene
    from physbench.simulators.pymunk_sim import PymunkSimulator

    ball = Body("ball", Circle(0.05), (1.0, 4.0), mass=0.2)
    scene = Scene("drop", (ball,), bounds=(-2, -6, 6, 6), fps=20.0, frames=21).validate()
    sim = PymunkSimulator()
    moving = replace(scene, bodies=(replace(ball, velocity=(0.4, -0.6)),))
    for truth, effects, named in ((moving, [], True), (scene, [QuadraticDrag(c=0.05)], False)):
        rec = noisy(sim.simulate(truth, effects=effects), sigma=0.002, seed=3)
        base = fit_base([Run("r", scene, recording=rec)], sim, Settings())
        starts = [f for f in diagnose(base).findings if f.kind == "start"]
        assert bool(starts) == named, starts
        if named:
            (f,) = starts
            assert f.suggests == () and f.body == "ball" and f.statistic == "vy0"
            assert abs(f.values["vy0"] + 0.6) < 3 * f.stderr and abs(f.size) > 3 * f.stderr
            assert abs(f.values["vx0"] - 0.4) < 0.2
            text = describe(f)
            assert "starts it at rest" in text and "ball.vx0" in text, text
