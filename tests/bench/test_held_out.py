"""Held-out evaluation of weights with the loop's metric."""

from __future__ import annotations

import pytest

pytest.importorskip("torch")

from physbench.bench.held_out import evaluate_weights
from physbench.estimators.resnet3d import weights


def test_evaluation_reports_the_best_so_far_error_per_iteration() -> None:
    info = weights.find("three_circles", ("mass",))
    rows = evaluate_weights(info.path, seeds=[0, 1], iterations=3, resolution=64)
    assert len(rows) == 2 and all(sorted(r) == [1, 2, 3] for r in rows)
    # best so far by image MSE: the error of the chosen iterate; iteration 1 is the initial guess
    assert all(r[1] > r[3] for r in rows), rows
    blurred = evaluate_weights(info.path, seeds=[0], iterations=2, resolution=64, blur=2.0)
    assert blurred[0] != rows[0] and set(blurred[0]) == {1, 2}
