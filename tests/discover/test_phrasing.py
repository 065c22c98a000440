"""Findings in words (physbench/discover/phrasing.py): only the finding's numbers go in."""

from __future__ import annotations

import math

from physbench.discover import Finding, describe


def test_free_flight_in_words_with_the_speed_law():
    values = {"excess_deceleration": 0.3, "stderr": 0.01, "mean_speed": 1.5, "speed_exponent": 1.1}
    f = Finding(
        "free_flight", "r", "ball", "free", "excess_deceleration", 0.3, 0.01, "linear", values
    )
    assert describe(f) == (
        "ball: in free flight the observed speed falls 0.3 ± 0.01 m/s² faster than simulated "
        "(20.0% of the mean speed per second); the excess grows like speed^1.1: about "
        "proportional to the speed (linear drag)"
    )
    slower = Finding("free_flight", "r", "ball", "free", "excess_deceleration", -0.2, 0.01)
    assert describe(slower) == (
        "ball: in free flight the observed speed falls 0.2 m/s² slower than simulated "
        "(the model loses too much speed)"
    )


def test_impacts_drift_and_offsets_in_words():
    values = {
        "impacts": 4.0,
        "observed_speed_ratio": 0.7,
        "simulated_speed_ratio": 0.8,
        "shortfall_per_mps": 0.05,
    }
    f = Finding(
        "impacts", "r", "ball", "impact", "speed_ratio_shortfall", 0.1, 0.01, "growing", values
    )
    assert describe(f) == (
        "ball: across 4 impacts the observed speed keeps 70% where the model keeps 80%; the "
        "shortfall grows with the impact speed (+0.05 per m/s) (energy lost beyond what "
        "restitution allows)"
    )
    drift = Finding("drift", "r", "b", "", "ax", 0.25, 0.01, values={"ax": 0.25, "ay": -0.0123})
    assert describe(drift) == (
        "b: the residual drifts as if the model missed a uniform acceleration "
        "(x +0.25, y -0.0123 m/s²)"
    )
    offset = Finding("offset", "r", "arm", "", "dangle", 0.05, values={"dangle": 0.05})
    assert (
        describe(offset) == "arm: observed angle sits +0.05 rad from the simulated one throughout"
    )


def test_oscillations_in_words():
    values = {
        "observed_first": 1.0,
        "observed_last": 0.5,
        "simulated_first": 1.0,
        "simulated_last": 0.99,
        "half_swings": 11.0,
    }
    env = Finding(
        "envelope", "r", "arm", "jointed", "loss_per_half_swing", 0.05, math.nan, "constant", values
    )
    assert describe(env) == (
        "arm: the observed amplitude falls from 1 to 0.5 rad over 10 half swings, the simulated "
        "one from 1 to 0.99; the loss per swing is about constant (dry, Coulomb-like friction)"
    )
    period = Finding("period", "r", "arm", "jointed", "period_ratio", 1.01234, 0.001)
    assert describe(period) == "arm: the observed period is 1.0123 × the simulated one"
    centre = Finding("centre", "r", "arm", "jointed", "dangle", -0.02)
    assert describe(centre) == "arm: the observed swing is centred -0.02 rad from the simulated one"
