"""Checked estimator options: each helper returns the value at the edges of what it accepts and
refuses just past them, naming the estimator, the option, the value and what is accepted."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.errors import PhysbenchError
from physbench.estimators.options import (
    EstimatorOptionError,
    choice_option,
    float_option,
    int_option,
)


def test_the_error_is_a_physbench_error_and_a_value_error() -> None:
    assert issubclass(EstimatorOptionError, PhysbenchError)
    assert issubclass(EstimatorOptionError, ValueError)


@pytest.mark.parametrize(("value", "expected"), [(2, 2), (7, 7), (np.int64(2), 2)])
def test_int_option_accepts_whole_numbers_from_low(value: object, expected: int) -> None:
    got = int_option("est", "n", value, low=2)
    assert got == expected and type(got) is int


@pytest.mark.parametrize("value", [1, 2.0, True, "3", None])
def test_int_option_refuses_below_low_and_anything_not_a_whole_number(value: object) -> None:
    with pytest.raises(
        EstimatorOptionError, match=rf"^est: n = {value!r}: expected a whole number >= 2$"
    ):
        int_option("est", "n", value, low=2)


def test_int_option_takes_none_only_when_allowed() -> None:
    assert int_option("est", "n", None, low=2, allow_none=True) is None
    with pytest.raises(
        EstimatorOptionError, match=r"^est: n = 1: expected a whole number >= 2 or None$"
    ):
        int_option("est", "n", 1, low=2, allow_none=True)


@pytest.mark.parametrize(("value", "expected"), [(1e-9, 1e-9), (1, 1.0), (np.float32(0.5), 0.5)])
def test_float_option_accepts_numbers_in_the_half_open_range(
    value: object, expected: float
) -> None:
    got = float_option("est", "x", value, low=0.0, high=1.0)
    assert got == expected and type(got) is float


@pytest.mark.parametrize("value", [0.0, 0, 1.0 + 1e-9, -1.0, True, "0.5", None, float("nan")])
def test_float_option_refuses_the_low_end_past_the_high_end_and_non_numbers(
    value: object,
) -> None:
    with pytest.raises(
        EstimatorOptionError, match=rf"^est: x = {value!r}: expected a number in \(0, 1\]$"
    ):
        float_option("est", "x", value, low=0.0, high=1.0)


def test_choice_option_accepts_only_the_choices() -> None:
    assert choice_option("est", "kind", "b", ("a", "b")) == "b"
    for value in ("c", "B", None):
        with pytest.raises(
            EstimatorOptionError, match=rf"^est: kind = {value!r}: expected one of a, b$"
        ):
            choice_option("est", "kind", value, ("a", "b"))
