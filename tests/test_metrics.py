"""The paper's metric helpers: image MSE, running best, mean ± std formatting."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.metrics import format_mean_std, image_mse, mean_std, running_best


def test_metrics() -> None:
    assert running_best([3.0, 1.0, 1.0, 0.5, 2.0]) == [0, 1, 1, 3, 3]
    assert image_mse(np.ones((2, 2)), np.zeros((2, 2))) == 1.0
    assert mean_std([1.0, 3.0]) == (2.0, pytest.approx(2**0.5))
    assert format_mean_std(0.011, 0.003) == "(1.1 ± 0.3)e-02"
