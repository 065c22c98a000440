"""ParamSpace: the unknowns of a run, their order, ranges and the paper's normalized MSE."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.scene import Body, Circle, Scene, body_unknown
from physbench.testing import toy_task
from physbench.unknowns import ParamSpace


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
