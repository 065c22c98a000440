"""Every knob of a discovery (physbench/discover/settings.py)."""

from __future__ import annotations

import pytest

from physbench.discover import DiscoverError, Settings


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({"min_gain": 1.5}, r"min_gain = 1\.5: expected a finite number in \[0, 1\)"),
        ({"ambiguity": True}, r"ambiguity = True"),
        ({"screen": 0}, r"screen = 0: expected a whole number >= 1"),
        ({"budget": 2.5}, r"budget = 2\.5"),
        ({"min_delta_bic": -1}, r"min_delta_bic = -1: expected a finite number >= 0"),
        ({"floor": float("nan")}, r"floor = nan: expected a finite number >= 0 \(m\)"),
        ({"min_delta_bic": float("inf")}, r"min_delta_bic = inf: expected a finite number >= 0"),
    ],
)
def test_bad_settings_are_named(bad, message):
    with pytest.raises(DiscoverError, match=message):
        Settings(**bad)


def test_settings_are_a_frozen_value():
    s = Settings()
    with pytest.raises(AttributeError):
        s.min_gain = 0.2  # type: ignore[misc]
