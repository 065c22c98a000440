"""Network inputs: observed and simulated sequences concatenated along time."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.estimators.resnet3d.inputs import make_input, resize, time_indices  # noqa: E402


def test_inputs_concatenate_observed_and_simulated_along_time() -> None:
    obs = np.zeros((30, 2, 64, 64), np.float32)
    sim = np.ones((30, 2, 64, 64), np.float32)
    x = make_input(obs, sim, frames=15, resolution=32)
    assert x.shape == (2, 30, 32, 32) and x.dtype == np.float32
    assert x[:, :15].max() == 0 and x[:, 15:].min() == 1
    assert list(time_indices(30, 15))[:3] == [0, 2, 4] and time_indices(30, 15)[-1] == 29
    block = np.arange(16, dtype=float).reshape(4, 4)
    assert resize(block, 2).tolist() == [[2.5, 4.5], [10.5, 12.5]]
