"""The velocity-dependent restitution law and its contact hook."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.effects import (
    VelocityDependentRestitution,
    restitution_law,
)


def test_restitution_law_and_its_hook(ball_scene):
    assert restitution_law(0.0, 0.9, 0.1) == pytest.approx(0.9)
    assert restitution_law(2.0, 0.9, 0.1) == pytest.approx(0.7)
    assert restitution_law(-2.0, 0.9, 0.1) == pytest.approx(0.7)  # speed, not sign
    assert restitution_law(20.0, 0.9, 0.1) == 0.0
    np.testing.assert_allclose(
        restitution_law(np.array([0.0, 1.0, 3.0]), 1.0, 0.2), [1.0, 0.8, 0.4]
    )
    e = VelocityDependentRestitution(e0=0.95, k=0.1, statics_only=True)
    scene = ball_scene()
    e.setup(scene, {})
    assert e.restitution(1.5, 0, None) == pytest.approx(0.8)
    assert e.restitution(1.5, 0, 0) is None  # body-body contacts keep the scene's restitution
    f, tau = e.forces(0.0, np.zeros((1, 6)))
    assert not f.any() and not tau.any()
