"""A data set's run: a recording with the scene that reproduces its setup, and its provenance."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from physbench.datasets.recorded_run import DatasetRun
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Scene


def test_a_run_holds_its_recording_scene_and_what_the_plain_model_misses() -> None:
    scene = Scene("s", (Body("ball", Circle(0.1), (1.0, 1.0)),))
    t = np.array([0.0, 0.1])
    rec = Recording({"ball": Track(t, np.ones(2), np.ones(2), np.zeros(2))}, run="r1")
    run = DatasetRun("r1", scene, rec, expected_effects=("quadratic_drag",), notes={"g": 9.81})
    assert run.expected_effects == ("quadratic_drag",) and run.notes == {"g": 9.81}
    assert DatasetRun("r2", scene, rec).expected_effects == ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.name = "other"  # type: ignore[misc]
