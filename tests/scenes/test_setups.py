"""Scenes of one's own setup from a few answers (``physbench/scenes/setups.py``): each kind's
initial state estimated from a recording's first samples, the scene file read back exactly, and
missing answers named."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from physbench.errors import PhysbenchWarning
from physbench.recording import Recording, Track
from physbench.scene_toml import loads_scene
from physbench.scenes.setups import (
    Answers,
    SetupError,
    build_setup,
    estimate,
    fit_circle,
    format_setup,
)
from physbench.simulators.pymunk_sim import PymunkSimulator


def noisy(rec: Recording, sigma: float, seed: int = 0) -> Recording:
    rng = np.random.default_rng(seed)
    tracks = {
        b: Track(tr.t, tr.x + rng.normal(0, sigma, len(tr)), tr.y + rng.normal(0, sigma, len(tr)))
        for b, tr in rec.tracks.items()
    }
    return Recording(tracks, fields=("x", "y"))


def test_a_flight_is_fitted_and_its_scene_replays_the_recording() -> None:
    t = np.arange(25) / 30
    x0, y0, vx, vy = 0.2, 1.1, 1.7, 2.6
    track = Track(t, x0 + vx * t, y0 + vy * t - 4.905 * t * t)
    rec = noisy(Recording({"ball": track}), 0.0005)
    est = estimate("flight", rec.track("ball"))
    assert est.position == pytest.approx((x0, y0), abs=0.002)
    assert est.velocity == pytest.approx((vx, vy), abs=0.03)
    assert est.samples == 10  # the first 0.3 s at 30 fps
    scene, notes = build_setup(Answers("flight", 0.03), rec)
    assert scene.fps == 30.0 and scene.frames == 25  # not 30.000000000000007 from the steps
    assert scene.body_names == ("ball",) and scene.bodies[0].mass == 1.0
    assert any("first 10 samples" in n for n in notes) and any("1 kg" in n for n in notes)
    traj = PymunkSimulator().simulate(scene)
    assert np.abs(traj.states[:, 0, 1] - track.y).max() < 0.01  # the scene replays the throw
    assert loads_scene(format_setup(scene, notes)) == scene


def test_first_samples_that_are_not_a_free_flight_are_said() -> None:
    """A start fitted to samples where the ball is still held or pulled is said: a ball pulled up
    a string (speeding up along its motion past gravity), and marks that scatter about the fit
    by several times the recording's accuracy. A falling paper cup, which drag holds to a fifth
    of g, and a clean throw are free flights and say nothing."""
    t = np.arange(25) / 30
    pulled = noisy(Recording({"ball": Track(t, 0.2 + t, 1.0 + t + 2.0 * t * t)}), 0.0005)
    with pytest.warns(PhysbenchWarning, match=r"not a free flight: they accelerate at \(-?0\.\d+, "
                      r"4\.\d+\) m/s², 9\.\d+ m/s² along the motion beyond gravity"):  # fmt: skip
        build_setup(Answers("flight", 0.03), pulled)
    throw = Track(t, 0.2 + 1.7 * t, 1.1 + 2.6 * t - 4.905 * t * t)
    jumpy = noisy(Recording({"ball": throw}), 0.02)
    jumpy = Recording(jumpy.tracks, fields=("x", "y"), accuracy=0.002)
    with pytest.warns(PhysbenchWarning, match=r"scatter \d+\.\d mm RMS about the fit, \d+ times"):
        build_setup(Answers("flight", 0.03), jumpy)
    cup = Recording({"cup": Track(t, 0.4 + 0.0 * t, 1.5 - 0.5 * t - 1.0 * t * t)}, accuracy=0.002)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        build_setup(Answers("flight", 0.05), cup)
        build_setup(Answers("flight", 0.03), Recording({"ball": throw}, accuracy=0.002))


def test_a_puck_and_a_ball_on_a_ramp() -> None:
    t = np.arange(40) / 60
    puck = Recording({"disc": Track(t, 1.0 + 0.8 * t, 2.0 - 0.3 * t)})
    scene, _ = build_setup(Answers("puck", 0.04, mass=0.2), puck)
    (b,) = scene.bodies
    assert scene.gravity == (0.0, 0.0) and b.name == "disc" and b.mass == 0.2
    assert b.position == pytest.approx((1.0, 2.0)) and b.velocity == pytest.approx((0.8, -0.3))
    # a ball rolling down a 10 degree ramp, accelerating along it
    a = math.radians(10.0)
    s = 0.5 * t + 0.8 * t * t
    ramp = Recording({"ball": Track(t, 0.3 + s * math.cos(a), 0.9 + s * math.sin(a))})
    scene, _ = build_setup(Answers("surface", 0.02, surface_angle=10.0), ramp)
    (b,) = scene.bodies
    assert b.velocity == pytest.approx((0.5 * math.cos(a), 0.5 * math.sin(a)), abs=1e-9)
    (floor,) = scene.statics
    d = np.subtract(floor.b, floor.a)
    assert math.degrees(math.atan2(d[1], d[0])) == pytest.approx(10.0)
    normal = np.array([-math.sin(a), math.cos(a)])
    assert float((np.subtract(b.position, floor.a)) @ normal) == pytest.approx(0.02)  # one radius
    assert loads_scene(format_setup(scene)) == scene


def test_a_pendulum_pivot_and_swing_from_the_samples_alone() -> None:
    truth, _ = build_setup(
        Answers(
            "pendulum",
            0.03,
            position=(1.3, 1.0),
            velocity=(0.0, 0.0),
            pivot=(1.0, 1.6),
            fps=50,
            frames=80,
        )
    )
    assert truth.joints[0].anchor == (1.0, 1.6)
    traj = PymunkSimulator().simulate(truth)
    rec = noisy(Recording.from_trajectory(traj, angle=False), 0.0003)
    cx, cy, r = fit_circle(rec.track("bob").x, rec.track("bob").y)
    assert (cx, cy) == pytest.approx((1.0, 1.6), abs=0.003)
    assert r == pytest.approx(math.hypot(0.3, 0.6), abs=0.003)
    # start the recording mid-swing: the bob then moves, and its speed is estimated too
    late = Recording(
        {
            "bob": Track(
                *(
                    a[20:]
                    for a in (
                        rec.track("bob").t - rec.track("bob").t[20],
                        rec.track("bob").x,
                        rec.track("bob").y,
                    )
                )
            )
        }
    )
    scene, notes = build_setup(Answers("pendulum", 0.03), late)
    (b,) = scene.bodies
    assert scene.joints[0].anchor == pytest.approx((1.0, 1.6), abs=0.003)
    assert b.position == pytest.approx(tuple(traj.states[20, 0, :2]), abs=0.003)
    assert b.velocity == pytest.approx(tuple(traj.states[20, 0, 3:5]), abs=0.05)
    assert any("pivot (circle" in n for n in notes)
    assert loads_scene(format_setup(scene)) == scene


def test_missing_answers_are_named() -> None:
    with pytest.raises(SetupError, match="frame rate is unknown"):
        build_setup(Answers("flight", 0.02, position=(0, 0)))
    with pytest.raises(SetupError, match="initial position is unknown"):
        build_setup(Answers("flight", 0.02, fps=30, frames=10))
    with pytest.raises(SetupError, match="pivot is unknown"):
        build_setup(Answers("pendulum", 0.02, position=(0, 0), fps=30, frames=10))
    with pytest.raises(SetupError, match="kind 'rocket'"):
        build_setup(Answers("rocket", 0.02))
    with pytest.raises(SetupError, match="radius = -1"):
        build_setup(Answers("puck", -1, position=(0, 0), fps=30, frames=10))
    two = Recording(
        {
            "a": Track(np.arange(5.0), np.zeros(5), np.zeros(5)),
            "b": Track(np.arange(5.0), np.ones(5), np.zeros(5)),
        }
    )
    with pytest.raises(SetupError, match="tracks 2 bodies"):
        build_setup(Answers("puck", 0.02), two)
    short = Recording({"a": Track(np.arange(3.0), np.zeros(3), np.zeros(3))})
    with pytest.raises(SetupError, match="needs at least 4"):
        build_setup(Answers("puck", 0.02), short)
