"""ParamSpace: the unknowns of a run, their order, ranges and the paper's normalized MSE."""

from __future__ import annotations

import re

import numpy as np
import pytest

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.scene import Body, Circle, Scene, body_unknown
from physbench.testing import toy_task
from physbench.unknowns import (
    ParamSpace,
    parse_unknown,
    scene_parameters,
    scene_values,
    simulate_seen,
    split_params,
)


def test_normalized_mse_divides_by_the_range_maximum() -> None:
    t = toy_task(("mass", "elasticity"), seed=0)
    est = {"a.mass": 4.0, "a.elasticity": 0.5, "b.mass": 10.0, "b.elasticity": 1.0}
    truth = {"a.mass": 2.0, "a.elasticity": 0.3, "b.mass": 10.0, "b.elasticity": 1.0}
    assert t.space.normalized_mse(est, truth) == pytest.approx(
        ((2 / 10) ** 2 + (0.2 / 1.0) ** 2) / 4
    )


def test_a_space_filters_the_scene_unknowns_and_maps_them_to_the_unit_cube() -> None:
    bodies = tuple(Body(n, Circle(0.2), (1.0 + i, 1.0)) for i, n in enumerate("abc"))
    unknowns = (
        body_unknown("a", "mass", 1.0, 3.0),
        body_unknown("b", "mass", 2.0, 4.0),
        body_unknown("b", "friction", 0.0, 1.0),
    )
    scene = Scene("s", bodies, unknowns=unknowns)
    space = ParamSpace.from_scene(scene, ["mass"])
    assert space.keys == ("a.mass", "b.mass") and space.bodies == ("a", "b")
    assert ParamSpace.from_scene(scene, bodies=["b"]).keys == ("b.mass", "b.friction")
    assert space.from_unit([0.5, 1.5]) == {"a.mass": 2.0, "b.mass": 4.0}  # clipped to the range
    np.testing.assert_allclose(space.to_unit({"a.mass": 1.5, "b.mass": 3.0}), [0.25, 0.5])
    assert space.clip({"a.mass": 9.0, "b.mass": 0.0}) == {"a.mass": 3.0, "b.mass": 2.0}
    draw = space.sample(np.random.default_rng(0))
    assert space.contains(draw) and not space.contains({"a.mass": 0.5, "b.mass": 3.0})
    with pytest.raises(UnknownNameError, match="unknown parameter 'moment'"):
        ParamSpace.from_scene(scene, ["moment"])
    with pytest.raises(UnknownNameError, match="unknown body 'c'"):
        ParamSpace.from_scene(scene, bodies=["c"])
    with pytest.raises(PhysbenchError, match="expected 2 values"):
        space.from_vector([1.0])


# --------------------------------------------------------------------------- scene-level unknowns


def _toss() -> Scene:
    """One free ball, no body unknowns: what a ball toss's scene file declares."""
    return Scene("toss", (Body("ball", Circle(0.1), (0.5, 0.5), velocity=(2.5, 5.0)),))


def test_items_parse_with_an_optional_range_and_plus_in_an_exponent_does_not_split() -> None:
    assert parse_unknown("gravity") == ("gravity", None)
    assert parse_unknown("gravity=-11:-9") == ("gravity", (-11.0, -9.0))
    assert parse_unknown("linear_drag.c=0:1e+2") == ("linear_drag.c", (0.0, 100.0))
    assert split_params("mass+linear_drag.c=0:1e+2,gravity") == (
        "mass",
        "linear_drag.c=0:1e+2",
        "gravity",
    )
    assert split_params("camera.scale+gravity") == ("camera.scale", "gravity")
    for bad in ("gravity=-9:-11", "gravity=1:x", "gravity=-11", "gravity=nan:1", "=1:2"):
        with pytest.raises(PhysbenchError, match=re.escape(repr(bad))):
            parse_unknown(bad)


def test_a_run_offers_gravity_the_camera_and_its_effects_parameters_by_key() -> None:
    from physbench.effects import LinearDrag

    offered = scene_parameters([LinearDrag()])
    assert [p.key for p in offered] == ["gravity", "camera.scale", "camera.clock", "linear_drag.c"]
    space = ParamSpace.from_scene(_toss(), ["gravity", "linear_drag.c"], offered=offered)
    assert space.keys == ("gravity", "linear_drag.c") and space.scene_keys == space.keys
    assert (space.unknowns[0].low, space.unknowns[0].high, space.unknowns[0].unit) == (
        -12.0,
        -8.0,
        "m/s²",
    )
    assert space.bodies == () and space.body_unknowns == ()
    # Without an offer (training sets) only the scene's body unknowns exist, as before.
    with pytest.raises(PhysbenchError, match=r"scene 'toss' declares no unknown parameters$"):
        ParamSpace.from_scene(_toss(), ["gravity"])
    with pytest.raises(
        UnknownNameError,
        match=r"unknown parameter 'mass' of scene 'toss'; .*: camera.clock, camera.scale, gravity",
    ):
        ParamSpace.from_scene(_toss(), ["mass"], offered=scene_parameters())
    with pytest.raises(PhysbenchError, match="declares no unknown parameters; name a scene-level"):
        ParamSpace.from_scene(_toss(), None, offered=scene_parameters())


def test_body_unknowns_keep_the_scene_order_and_scene_level_ones_follow_in_the_given_order() -> (
    None
):
    t = toy_task(("mass",))
    space = ParamSpace.from_scene(
        t.scene, ["camera.scale", "mass", "gravity"], offered=scene_parameters()
    )
    assert space.keys == ("a.mass", "b.mass", "camera.scale", "gravity")
    assert space.bodies == ("a", "b") and space.scene_keys == ("camera.scale", "gravity")
    assert space.subset("a").keys == ("a.mass",)
    only_b = ParamSpace.from_scene(t.scene, ["mass", "gravity"], ["b"], offered=scene_parameters())
    assert only_b.keys == ("b.mass", "gravity")
    with pytest.raises(PhysbenchError, match="'gravity' is named twice"):
        ParamSpace.from_scene(t.scene, ["gravity", "gravity=-11:-9"], offered=scene_parameters())


def test_ranges_override_the_defaults_within_what_each_parameter_can_take() -> None:
    from physbench.effects import LinearDrag, TableTilt

    offered = scene_parameters([LinearDrag(), TableTilt()])
    scene = toy_task().scene

    def space(*items: str) -> ParamSpace:
        return ParamSpace.from_scene(scene, list(items), offered=offered)

    got = space("mass=2:3", "gravity=-11:-9", "camera.scale=0.5:2", "linear_drag.c=0.1:50")
    assert [(u.key, u.low, u.high) for u in got.unknowns] == [
        ("a.mass", 2.0, 3.0),
        ("b.mass", 2.0, 3.0),
        ("gravity", -11.0, -9.0),
        ("camera.scale", 0.5, 2.0),
        ("linear_drag.c", 0.1, 50.0),  # a typical span: its high end may move
    ]
    assert space("table_tilt.ax=-5:5").unknowns[0].high == 5.0  # both ends of a tilt are open
    refused = {
        "elasticity=0:2": "elasticity=0:2: elasticity must lie in [0.0, 1.0]",
        "linear_drag.c=-1:1": "linear_drag.c=-1:1: the range must lie in [0, inf] N·s/m",
        "camera.scale=0:2": "camera.scale=0:2: the range must lie in [0.1, 10]",
        "gravity=-2e4:0": "gravity=-20000:0: the range must lie in [-10000, 10000] m/s²",
    }
    for item, message in refused.items():
        with pytest.raises(PhysbenchError, match=re.escape(message)):
            space(item)


def test_the_camera_changes_how_the_world_is_seen_and_the_rest_goes_to_the_simulator() -> None:
    from physbench.components import create
    from physbench.effects import LinearDrag, SensorOffset

    scene, sim = _toss(), create("simulator", "pymunk")
    plain = sim.simulate(scene, {"gravity": -9.0})
    seen, traj = simulate_seen(sim, scene, {"gravity": -9.0})
    assert seen is scene and np.array_equal(traj.states, plain.states)
    # The scale divides every length as a calibration off by it does, in the same frame.
    seen, traj = simulate_seen(sim, scene, {"gravity": -9.0, "camera.scale": 1.25})
    assert seen.bounds == scene.bounds and seen.bodies[0].shape.radius == pytest.approx(0.08)
    np.testing.assert_allclose(
        traj.states[..., [0, 1, 3, 4]], plain.states[..., [0, 1, 3, 4]] / 1.25
    )
    np.testing.assert_allclose(traj.states[..., 2], plain.states[..., 2])
    # The clock stretches time: frame k is the world at clock * k / fps.
    seen, slow = simulate_seen(sim, scene, {"camera.clock": 1.2})
    assert seen is scene
    np.testing.assert_allclose(slow.times, 1.2 * sim.simulate(scene).times)
    drag = LinearDrag()
    values = {"gravity": -9.0, "linear_drag.c": 0.2, "camera.scale": 1.1}
    assert scene_values(values, [drag]) == {"gravity": -9.0}
    _, dragged = simulate_seen(sim, scene, {"gravity": -9.0, "linear_drag.c": 0.2}, [drag])
    assert dragged.states[-1, 0, 3] < 0.9 * plain.states[-1, 0, 3]
    # A measurement effect measures what was simulated.
    _, shifted = simulate_seen(sim, scene, {"sensor_offset.dx": 0.3}, [SensorOffset()])
    np.testing.assert_allclose(shifted.states[:, 0, 0], sim.simulate(scene).states[:, 0, 0] + 0.3)


def test_the_normalized_error_of_gravity_divides_by_its_largest_magnitude() -> None:
    space = ParamSpace.from_scene(_toss(), ["gravity=-12:0"], offered=scene_parameters())
    assert space.normalized_mse({"gravity": -9.0}, {"gravity": -10.2}) == pytest.approx(0.01)
