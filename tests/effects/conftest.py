"""Helpers shared by the effect tests, as factory fixtures: scenes with analytic solutions and
runs in both engines."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.scene import Body, Box, Circle, Joint, Scene
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.trajectory import Trajectory

ENGINES = [PymunkSimulator, Box2DSimulator]

G = 9.81

#: The pendulum arm: length, width, mass, initial angle (test_joints.py uses the same values).
L, W, M, THETA0 = 0.4, 0.03, 0.5, 0.2

PIVOT = (2.0, 3.0)


def _run_both(scene: Scene, make_effects) -> list[Trajectory]:
    """One trajectory per engine, each with freshly set-up effects."""
    out = []
    for sim in ENGINES:
        effects = make_effects()
        for e in effects:
            e.setup(scene, {})
        out.append(sim().simulate(scene, effects=effects))
    return out


def _assert_engines_agree(
    trajs: list[Trajectory], pose_tol: float = 5e-4, vel_tol: float = 1e-3
) -> None:
    """Both engines give the same poses (m, rad) and velocities, to Box2D's float32 precision."""
    a, b = trajs
    assert np.abs(a.states[:, :, :3] - b.states[:, :, :3]).max() <= pose_tol
    assert np.abs(a.states[:, :, 3:] - b.states[:, :, 3:]).max() <= vel_tol


def _assert_pose(
    tr: Trajectory, scene: Scene, field: int, expected: np.ndarray, tol: float
) -> None:
    """Pose column ``field`` (0 x, 1 y, 2 angle) of the first body matches ``expected`` within
    ``tol`` plus the engines' first-order integrator error, at most ``h·|v(t) - v(0)|``."""
    h = scene.dt / scene.substeps
    v = tr.states[:, 0, 3 + field]
    err = np.abs(tr.states[:, 0, field] - expected)
    slack = tol + h * np.abs(v - v[0])
    assert np.all(err <= slack), (
        f"[{tr.engine}] worst excess {np.max(err - slack):.3g} at frame {np.argmax(err - slack)}"
    )


def _ball_scene(
    velocity=(0.0, 0.0),
    gravity=(0.0, 0.0),
    seconds=3.0,
    fps=30,
    position=(1.0, 1.0),
    bounds=(0.0, 0.0, 20.0, 20.0),
    mass=2.0,
) -> Scene:
    return Scene(
        "ball",
        (Body("ball", Circle(0.05), position, velocity=velocity, mass=mass),),
        bounds=bounds,
        gravity=gravity,
        fps=fps,
        frames=int(seconds * fps) + 1,
        substeps=10,
    ).validate()


def _pendulum(seconds: float = 4.0, theta0: float = THETA0) -> Scene:
    centre = (PIVOT[0] + math.sin(theta0) * L / 2, PIVOT[1] - math.cos(theta0) * L / 2)
    arm = Body("arm", Box(W, L), centre, angle=theta0, mass=M)
    return Scene(
        "pendulum",
        (arm,),
        fps=60,
        frames=int(seconds * 60) + 1,
        substeps=10,
        joints=(Joint("arm", PIVOT),),
    ).validate()


def _peaks(tr: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of the angle maxima, refined by a parabola through each peak frame."""
    a, t = tr.field("angle")[:, 0], tr.times
    i = np.nonzero((a[1:-1] > a[:-2]) & (a[1:-1] >= a[2:]))[0] + 1
    y0, y1, y2 = a[i - 1], a[i], a[i + 1]
    d = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    return t[i] + d * (t[1] - t[0]), y1 - 0.25 * (y0 - y2) * d


@pytest.fixture(name="run_both")
def _run_both_fixture():  # type: ignore[no-untyped-def]
    return _run_both


@pytest.fixture(name="assert_engines_agree")
def _assert_engines_agree_fixture():  # type: ignore[no-untyped-def]
    return _assert_engines_agree


@pytest.fixture(name="assert_pose")
def _assert_pose_fixture():  # type: ignore[no-untyped-def]
    return _assert_pose


@pytest.fixture(name="ball_scene")
def _ball_scene_fixture():  # type: ignore[no-untyped-def]
    return _ball_scene


@pytest.fixture(name="pendulum")
def _pendulum_fixture():  # type: ignore[no-untyped-def]
    return _pendulum


@pytest.fixture(name="peaks")
def _peaks_fixture():  # type: ignore[no-untyped-def]
    return _peaks
