"""Checked estimator options: each helper returns the value or raises
:class:`EstimatorOptionError` naming the estimator, the option, the value and what is accepted."""

from __future__ import annotations

import numpy as np

from physbench.errors import PhysbenchError


class EstimatorOptionError(PhysbenchError, ValueError):
    """A bad estimator option; names the option, the value and what is accepted."""


def int_option(
    estimator: str, name: str, value: object, *, low: int, allow_none: bool = False
) -> int | None:
    """``value`` as an int ``>= low`` (or ``None`` when allowed), else
    :class:`EstimatorOptionError`."""
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
        extra = " or None" if allow_none else ""
        raise EstimatorOptionError(
            f"{estimator}: {name} = {value!r}: expected a whole number >= {low}{extra}"
        )
    return int(value)


def float_option(estimator: str, name: str, value: object, *, low: float, high: float) -> float:
    """``value`` as a float in ``(low, high]``, else :class:`EstimatorOptionError`."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float | np.floating)
        or not low < value <= high
    ):
        raise EstimatorOptionError(
            f"{estimator}: {name} = {value!r}: expected a number in ({low:g}, {high:g}]"
        )
    return float(value)


def choice_option(estimator: str, name: str, value: object, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise EstimatorOptionError(
            f"{estimator}: {name} = {value!r}: expected one of {', '.join(choices)}"
        )
    return str(value)
