"""The model discovery fits: parameters, initial state, effects (physbench/discover/model.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.discover import Run, make_split
from physbench.discover.model import (
    FitParameter,
    Model,
    Problem,
    apply_initial,
    body_params,
    chain_parents,
    effect_params,
    nuisance_params,
)
from physbench.effects import LinearDrag, QuadraticDrag
from physbench.parameter import Parameter
from physbench.recording import Recording, Track
from physbench.scene import Body, Box, Joint, Scene, body_unknown
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = [PymunkSimulator, Box2DSimulator]


def double_pendulum() -> Scene:
    a = Body("upper", Box(0.04, 0.4), (1.0, 1.3), mass=0.5)
    b = Body("lower", Box(0.04, 0.3), (1.0, 0.95), mass=0.3)
    return Scene(
        "dp",
        (a, b),
        bounds=(0, 0, 2, 2),
        gravity=(0.0, 0.0),
        fps=100.0,
        frames=3,
        substeps=10,
        joints=(Joint("upper", (1.0, 1.5)), Joint("lower", (1.0, 1.1), "upper")),
    ).validate()


def test_initial_angles_move_the_whole_chain_rigidly():
    scene = double_pendulum()
    assert chain_parents(scene) == {"upper": (None, 0), "lower": ("upper", 1)}
    moved = apply_initial(
        scene,
        {"upper": {"angle0": 0.3, "omega0": 1.0}, "lower": {"angle0": -0.2, "omega0": 2.0}},
        {},
    )
    up, lo = moved.bodies
    elbow = np.array([1.0, 1.5]) + 0.4 * np.array([math.sin(0.3), -math.cos(0.3)])
    assert np.allclose(moved.joints[1].anchor, elbow)
    assert np.allclose(
        up.position, np.array([1.0, 1.5]) + 0.2 * np.array([math.sin(0.3), -math.cos(0.3)])
    )
    assert np.allclose(lo.position, elbow + 0.15 * np.array([math.sin(-0.2), -math.cos(-0.2)]))
    v_elbow = 1.0 * 0.4 * np.array([math.cos(0.3), math.sin(0.3)])
    assert np.allclose(
        lo.velocity, v_elbow + 2.0 * 0.15 * np.array([math.cos(-0.2), math.sin(-0.2)])
    )
    for sim in ENGINES:  # a consistent state: without gravity the joints do not jerk the rates
        tr = sim().simulate(moved.validate())
        assert abs(tr.states[1, 0, 5] - 1.0) < 0.05 and abs(tr.states[1, 1, 5] - 2.0) < 0.05
        jerked = sim().simulate(
            apply_initial(scene, {"upper": {"angle0": 0.3, "omega0": 1.0}}, {}).validate()
        )
        # lower keeps its own rate (0)
        assert jerked.states[1, 1, 5] == pytest.approx(0.0, abs=0.05)


def test_fit_parameters_are_parameters_owned_by_a_body_an_effect_or_a_run(slide):
    scene = slide(mass=5.0, unknowns=(body_unknown("ball", "mass", 0.5, 2.0),))
    (mass,) = body_params(scene)
    assert isinstance(mass, Parameter) and isinstance(mass, FitParameter)
    assert (mass.key, mass.owner, mass.name, mass.kind, mass.unit) == (
        "ball.mass",
        "ball",
        "mass",
        "body",
        "kg",
    )
    assert mass.default == 2.0 and mass.scale == pytest.approx(0.03)  # clipped into range

    drag = effect_params(LinearDrag(label="drag_a", c=0.3), {})
    assert [(p.key, p.owner, p.kind, p.default) for p in drag] == [
        ("drag_a.c", "drag_a", "effect", 0.3)
    ]
    assert drag[0].unit == LinearDrag.param("c").unit
    assert effect_params(LinearDrag(), {"c": 0.1})[0].default == 0.1

    rec = Recording({"ball": Track(np.arange(5) * 0.05, np.zeros(5), np.zeros(5))})
    run = Run("r1", scene, recording=rec)
    keys = [(p.key, p.owner, p.name, p.run, p.unit) for p in nuisance_params(run, 2, "r1/")]
    assert keys[:2] == [("r1/ball.x0", "ball", "x0", 2, "m"), ("r1/ball.y0", "ball", "y0", 2, "m")]
    assert keys[2][0] == "r1/ball.vx0" and keys[2][4] == "m/s"


def test_a_model_without_an_effect_keeps_the_other_values(slide, noisy):
    scene = slide()
    run = Run("r", scene, recording=noisy(PymunkSimulator().simulate(scene)))
    problem = Problem([run], make_split([run]), PymunkSimulator())
    lin, quad = LinearDrag(), QuadraticDrag()
    model = Model(problem, [lin, quad], [*effect_params(lin), *effect_params(quad)])
    model.values.update({"linear_drag.c": 0.2, "quadratic_drag.c": 0.1})
    rest = model.without("linear_drag")
    assert rest.effects == [quad] and list(rest.values) == ["quadratic_drag.c"]
    assert rest.values["quadratic_drag.c"] == 0.1
    assert model.values["linear_drag.c"] == 0.2  # the original is untouched
