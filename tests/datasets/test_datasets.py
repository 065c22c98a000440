"""The data set registry: names and lookup."""

from __future__ import annotations

import pytest

from physbench.datasets import dataset_names, load
from physbench.errors import UnknownNameError


def test_registry_names_the_data_sets_and_refuses_others():
    assert dataset_names() == ["ball_drops", "billiards", "pendulum_benard", "pendulum_kaheman"]
    with pytest.raises(UnknownNameError, match="'bouncing'"):
        load("bouncing")
