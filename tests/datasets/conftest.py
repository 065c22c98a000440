"""Shared checks of the data set tests: a run's scene covers its recording, and the early part of
a recording."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from physbench.datasets import DatasetRun
from physbench.recording import Recording, Track


def _check_run(run: DatasetRun) -> None:
    run.scene.validate()
    rec = run.recording
    assert set(rec.bodies) <= set(run.scene.body_names)
    assert rec.frames_for(run.scene.fps) <= run.scene.frames  # the scene covers the recording
    assert rec.fields is not None and run.expected_effects


def _early(rec: Recording, body: str, until: float) -> Recording:
    tr = rec.track(body)
    m = tr.t <= until
    return Recording(
        {body: Track(tr.t[m], tr.x[m], tr.y[m], None if tr.angle is None else tr.angle[m])},
        fields=rec.fields,
    )


@pytest.fixture
def check_run() -> Callable[[DatasetRun], None]:
    """Asserts that a loaded run is consistent: valid scene that covers its recording."""
    return _check_run


@pytest.fixture
def early() -> Callable[[Recording, str, float], Recording]:
    """``early(recording, body, until)``: ``body``'s samples up to ``until`` s."""
    return _early
