"""The ball drops loader on the shipped copy, and the direct check of the drag law on
synthetic drops with a known law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.datasets import DatasetError, DatasetRun, load
from physbench.datasets.ball_drops import (
    DRAG_LAWS,
    G,
    check_drag_laws,
    drag_exponent,
    drop_height,
    fit_drop,
    late_error,
    transfer_error,
)
from physbench.effects import QuadraticDrag
from physbench.errors import UnknownNameError
from physbench.simulators.pymunk_sim import PymunkSimulator

#: 3 s at 15 fps, as the recorded drops.
T = np.arange(46) / 15.0


def quadratic_fall(t: np.ndarray, h0: float, k: float) -> np.ndarray:
    """Height of a ball dropped from rest at ``h0`` with drag ``k v²`` (closed form)."""
    vt = math.sqrt(G / k)  # terminal speed
    return h0 - vt**2 / G * np.log(np.cosh(G * t / vt))


def linear_fall(t: np.ndarray, h0: float, c: float) -> np.ndarray:
    """Height of a ball dropped from rest at ``h0`` with drag ``c v`` (closed form)."""
    return h0 - G / c * t + G / c**2 * (1 - np.exp(-c * t))


@pytest.fixture(scope="module")
def drops() -> dict[str, DatasetRun]:
    return {r.name: r for r in load("ball_drops")}


def test_ball_drops_are_47_m_falls_clipped_like_the_authors(drops, check_run):
    assert len(drops) == 22
    for run in drops.values():
        check_run(run)
        tr = run.recording.track("ball")
        assert 45.5 < run.scene.bodies[0].position[1] < 49.6 and 45.5 < tr.y[0] < 49.6
        assert run.recording.fields == ("y",)
        if run.name != "bowling_ball/1":
            assert 2.7 < tr.t[-1] < 3.9 and 10.5 < tr.y[-1] < 15.0 and len(tr) >= 40
    assert len(drops["bowling_ball/1"].recording.track("ball")) == 14  # the provenance's count
    golf = drops["golf_ball/1"]
    assert golf.notes["mass_kg"] == pytest.approx(1.62 * 0.0283495)
    assert golf.scene.bodies[0].shape.radius == pytest.approx(0.138 / (2 * math.pi))
    assert drops["volleyball/1"].notes["mass_and_size_assumed"]


def test_ball_drops_show_drag_that_grows_for_light_balls(drops):
    def apparent_g(run: DatasetRun) -> float:
        tr = run.recording.track("ball")
        return -2 * np.polyfit(tr.t, tr.y, 2)[0]

    for name in ("golf_ball/1", "baseball/1", "bowling_ball/2"):
        assert 9.0 < apparent_g(drops[name]) < 9.8
    for name in (
        "whiffle_ball_1/1",
        "whiffle_ball_2/2",
        "yellow_whiffle_ball/1",
        "orange_whiffle_ball/2",
    ):
        assert 2.9 < apparent_g(drops[name]) < 4.7


def test_quadratic_drag_explains_the_whiffle_ball_drop(drops):
    run = drops["whiffle_ball_2/1"]
    sim = PymunkSimulator()
    plain = run.recording.rms(sim.simulate(run.scene))["y"]
    drag = QuadraticDrag(c=0.05 * run.notes["mass_kg"])  # k ≈ 0.05 1/m (provenance: 0.04-0.065)
    drag.setup(run.scene, {})
    with_drag = run.recording.rms(sim.simulate(run.scene, effects=[drag]))["y"]
    assert plain > 8.0 and with_drag < plain / 5  # the start state was fitted without drag


# --------------------------------------------------------------------------- drag law check


def test_drop_height_solves_each_law():
    np.testing.assert_allclose(drop_height(T, 47.0, 0.0, "none", 0.0), 47.0 - G * T**2 / 2)
    np.testing.assert_allclose(
        drop_height(T, 47.0, 0.0, "constant", 1.5), 47.0 - (G - 1.5) * T**2 / 2, atol=1e-7
    )
    np.testing.assert_allclose(
        drop_height(T, 47.0, 0.0, "linear", 0.6), linear_fall(T, 47.0, 0.6), atol=1e-7
    )
    np.testing.assert_allclose(
        drop_height(T, 47.0, 0.0, "quadratic", 0.05), quadratic_fall(T, 47.0, 0.05), atol=1e-7
    )
    with pytest.raises(UnknownNameError, match="'cubic'"):
        drop_height(T, 47.0, 0.0, "cubic", 1.0)


def test_fit_drop_recovers_the_start_and_the_drag():
    h = quadratic_fall(T, 47.0, 0.05)
    h0, v0, k = fit_drop(T, h, "quadratic")
    assert (h0, v0, k) == pytest.approx((47.0, 0.0, 0.05), abs=1e-5)
    h0, v0, k = fit_drop(T, h, "quadratic", k=0.04)  # a given drag: only the start is fitted
    assert k == 0.04 and h0 != pytest.approx(47.0, abs=1e-3)


def test_only_the_true_law_predicts_the_unseen_part():
    h = linear_fall(T, 47.0, 0.6)
    assert np.abs(late_error(T, h, "linear")).max() < 1e-4
    assert np.abs(late_error(T, h, "quadratic")).max() > 0.05
    assert np.abs(late_error(T, h, "none")).max() > 1.0
    assert np.abs(transfer_error(T, h, "linear", 0.6)).max() < 1e-4
    assert np.abs(transfer_error(T, h, "linear", 0.3)).max() > 1.0


@pytest.mark.parametrize(("law", "n"), [("quadratic", 2.0), ("linear", 1.0)])
def test_drag_exponent_of_a_known_law(law, n):
    # 4 s at 60 fps: windows of 0.25 s, in which the deceleration hardly changes
    t = np.arange(241) / 60.0
    h = quadratic_fall(t, 60.0, 0.05) if law == "quadratic" else linear_fall(t, 60.0, 0.6)
    assert drag_exponent(t, h) == pytest.approx(n, abs=0.01)
    # falling faster than g: no positive excess deceleration to fit
    assert math.isnan(drag_exponent(t, 60.0 - (G + 0.5) * t**2 / 2))


def test_check_drag_laws_on_two_quadratic_drops():
    drops = [(T, quadratic_fall(T, 47.0, 0.05)), (T[:40], quadratic_fall(T[:40], 45.0, 0.05))]
    check = check_drag_laws(drops)
    assert list(check.time_split) == list(DRAG_LAWS) == list(check.run_split)
    assert check.k["quadratic"] == pytest.approx([0.05, 0.05], abs=1e-5)
    assert check.time_split["quadratic"] < 1e-4 and check.run_split["quadratic"] < 1e-4
    for law in ("none", "linear", "constant"):
        assert check.time_split[law] > 100 * check.time_split["quadratic"]
    # at 15 fps each parabola spans 1 s, over which the deceleration grows: a little low
    assert all(1.8 < n < 2.0 for n in check.exponent)
    with pytest.raises(DatasetError, match="2 drops"):
        check_drag_laws(drops[:1])
