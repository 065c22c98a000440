"""The pymunk adapter: its batched state reads."""

from __future__ import annotations

import pytest

from physbench.scene import Scene
from physbench.simulators.pymunk_sim import PymunkSimulator


def test_pymunk_batch_read_matches_per_body_read(
    monkeypatch: pytest.MonkeyPatch, busy_scene: Scene
) -> None:
    """pymunk's experimental batch reader is a pure speed-up: without it, the same trajectory."""
    import physbench.simulators.pymunk_sim as pymunk_sim

    scene = busy_scene
    world = PymunkSimulator().build(scene)
    assert world._batch is not None  # in use with the pinned pymunk 7
    fast = PymunkSimulator().simulate(scene)
    monkeypatch.setattr(pymunk_sim._BatchReader, "for_world", classmethod(lambda cls, w: None))
    assert PymunkSimulator().build(scene)._batch is None
    slow = PymunkSimulator().simulate(scene)
    assert fast.states.tobytes() == slow.states.tobytes()
