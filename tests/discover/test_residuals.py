"""Residual layout, events and breakdowns (physbench/discover/residuals.py)."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.discover.residuals import Layout
from physbench.recording import Recording, Track
from physbench.scene import Body, Box, Circle, Scene


def test_layout_follows_the_residual_order_and_weights_angles():
    rec = Recording(
        {
            "b": Track(
                np.array([0.0, 0.1]),
                np.array([1.0, 2.0]),
                np.array([3.0, 4.0]),
                np.array([0.1, 0.2]),
            ),
            "a": Track(np.array([0.0]), np.array([5.0]), np.array([6.0]), np.array([0.3])),
        }
    )
    scene = Scene("s", (Body("a", Circle(0.1), (1, 1)), Body("b", Box(0.2, 0.4), (2, 2))))
    lay = Layout.of_recording(rec, scene)
    assert lay.body.tolist() == [0, 0, 0, 0, 0, 0, 1, 1, 1]  # recording order: b then a
    assert lay.field.tolist() == [0, 0, 1, 1, 2, 2, 0, 1, 2]
    assert lay.weight[4] == pytest.approx(Box(0.2, 0.4).extent()) and lay.weight[0] == 1.0
    assert lay.unit.startswith("m (angles")
