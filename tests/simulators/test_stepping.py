"""Effects inside the stepping loop (physbench/simulators/stepping.py), in both engines: set up with
the scene as simulated, keyed by their labels, and asked for the restitution of new contacts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physbench.effects import LinearDrag, TableTilt, VelocityDependentRestitution
from physbench.errors import PhysbenchError
from physbench.scene import Body, Circle, Scene, Segment
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = [PymunkSimulator, Box2DSimulator]


def slide(v=(2.0, 0.5), mass=1.0, frames=41, fps=20.0) -> Scene:
    return Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=v, mass=mass),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=fps,
        frames=frames,
        substeps=4,
    ).validate()


@pytest.mark.parametrize("sim", ENGINES)
def test_simulate_sets_effects_up_with_the_scene_as_simulated(sim):
    # TableTilt's force is m·a: set up once with mass 1 but simulated with mass 3, the acceleration
    # must still be a, which needs setup() with the parameters applied inside simulate().
    scene = slide(v=(0.0, 0.0))
    tilt = TableTilt(ax=0.5)
    tilt.setup(scene, {})
    tr = sim().simulate(scene, {"ball.mass": 3.0, "table_tilt.ay": -0.25}, effects=[tilt])
    t = tr.times[-1]
    assert tr.body("ball")[-1, 3] == pytest.approx(0.5 * t, rel=1e-4)
    assert tr.body("ball")[-1, 4] == pytest.approx(-0.25 * t, rel=1e-4)
    assert tilt.values == {"ax": 0.5, "ay": -0.25}


@pytest.mark.parametrize("sim", ENGINES)
def test_two_instances_of_an_effect_need_labels(sim):
    scene = Scene(
        "two",
        (
            Body("a", Circle(0.05), (1, 1), velocity=(1, 0)),
            Body("b", Circle(0.05), (1, 3), velocity=(1, 0)),
        ),
        bounds=(0, 0, 6, 5),
        gravity=(0, 0),
        frames=31,
    )
    a, b = LinearDrag(bodies=["a"], label="drag_a"), LinearDrag(bodies=["b"], label="drag_b")
    tr = sim().simulate(scene, {"drag_a.c": 1.0, "drag_b.c": 0.0}, effects=[a, b])
    assert tr.body("a")[-1, 3] == pytest.approx(math.exp(-tr.times[-1]), rel=5e-3)
    assert tr.body("b")[-1, 3] == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(PhysbenchError, match="share the parameter key 'linear_drag'"):
        sim().simulate(scene, effects=[LinearDrag(), LinearDrag()])
    with pytest.raises(PhysbenchError, match="label"):
        LinearDrag(label="a.b")


@pytest.mark.parametrize("sim", ENGINES)
def test_contact_hook_applies_velocity_dependent_restitution(sim):
    # A ball dropped 1.25 m hits the floor at ~5 m/s: the rebound keeps e0 - k·v of the speed.
    scene = Scene(
        "drop",
        (Body("ball", Circle(0.1), (1.0, 1.35), elasticity=1.0),),
        statics=(Segment((-1, 0), (5, 0)),),
        bounds=(0, 0, 4, 4),
        fps=100.0,
        frames=71,
        substeps=10,
    )
    e0, k = 0.9, 0.08
    tr = sim().simulate(scene, effects=[VelocityDependentRestitution(e0=e0, k=k)])
    vy = tr.body("ball")[:, 4]
    i = int(np.argmax(np.diff(vy)))
    v_in, v_out = -vy[i], vy[i + 1]
    g_dt = 9.81 / scene.fps  # a frame of gravity on either side of the impact
    assert v_out / v_in == pytest.approx(e0 - k * v_in, abs=g_dt / v_in + 0.01)
    plain = sim().simulate(scene)
    assert plain.body("ball")[i + 1, 4] > v_out + 1.0  # without the effect: elastic


def test_restitution_hook_agrees_between_engines():
    # Normal speeds stay above Box2D's 1 m/s threshold, below which Box2D makes impacts inelastic.
    scene = Scene(
        "box",
        (
            Body(
                "puck", Circle(0.05), (0.5, 0.4), velocity=(4.0, 3.0), elasticity=1.0, friction=0.0
            ),
        ),
        statics=tuple(
            Segment(a, b)
            for a, b in (((0, 0), (2, 0)), ((2, 0), (2, 1)), ((2, 1), (0, 1)), ((0, 1), (0, 0)))
        ),
        bounds=(0, 0, 2, 1),
        gravity=(0.0, 0.0),
        fps=50.0,
        frames=41,
        substeps=10,
    )
    trs = [
        s().simulate(scene, effects=[VelocityDependentRestitution(e0=0.95, k=0.05)])
        for s in ENGINES
    ]
    vx, vy = ([abs(t.states[-1, 0, c]) for t in trs] for c in (3, 4))
    assert vx[0] == pytest.approx(vx[1], rel=1e-3) and vy[0] == pytest.approx(vy[1], rel=1e-3)
    # one side-wall impact at 4 m/s
    assert vx[0] == pytest.approx((0.95 - 0.05 * 4.0) * 4.0, rel=0.01)
    assert vy[0] < 0.85 * 3.0
