"""physbench.cost: a job's memory and time from its sizes, and the refusal of what cannot finish."""

from __future__ import annotations

import pytest

from physbench import cost
from physbench.cost import Cost, SizeError
from physbench.scenes import resolve_scene


@pytest.fixture(autouse=True)
def checked(monkeypatch: pytest.MonkeyPatch) -> None:
    """The size check on, whatever the environment running the tests says."""
    monkeypatch.delenv(cost.OVERRIDE, raising=False)


def test_a_simulation_costs_its_frames_states_and_steps() -> None:
    c = cost.simulation(100, 10, 3, resolution=64, n_channels=2, held=3)
    frames = 100 * 2 * 64 * 64 * 4
    assert c.memory == 3 * frames + 100 * 3 * 6 * 8
    assert c.seconds == pytest.approx(
        100 * 10 * 3 * cost.STEP_SECONDS + 100 * 2 * 64 * 64 * cost.PIXEL_SECONDS
    )
    unrendered = cost.simulation(100, 10, 3)
    assert unrendered.memory == 100 * 3 * 6 * 8


def test_repeated_jobs_add_time_and_reuse_memory() -> None:
    one = Cost(memory=10.0, seconds=2.0)
    assert one.times(5) == Cost(10.0, 10.0)
    assert one + Cost(30.0, 1.0) == Cost(30.0, 3.0)


@pytest.mark.parametrize(("mode", "channels"), [("mark", 2), ("instance", 7), ("mask", 1)])
def test_channels_follow_the_render_mode(mode: str, channels: int) -> None:
    assert cost.channels(mode, 7) == channels


def test_a_scene_costs_its_frames_substeps_and_bodies() -> None:
    scene = resolve_scene("three_circles", 0)
    c = cost.of_scene(scene, resolution=32, mode="instance")
    assert c == cost.simulation(
        scene.frames, scene.substeps, 3, resolution=32, n_channels=3, held=1
    )
    assert cost.simulations(12, scene, 32) == (
        f"12 simulations of {scene.frames} frames x {scene.substeps} substeps x 3 bodies at 32 px"
    )


def test_a_job_within_the_limits_passes() -> None:
    cost.check(Cost(1e6, 60.0), "this job", "--n", memory=lambda: 1e9)


def test_more_memory_than_available_is_one_sentence_naming_estimate_limit_and_override() -> None:
    with pytest.raises(SizeError) as info:
        cost.check(Cost(3e12, 1.0), "this run (x)", "--resolution", memory=lambda: 16e9)
    message = str(info.value)
    assert message == (
        "this run (x) would need 3 TB of memory, more than the 16 GB available; make "
        "--resolution smaller, or set PHYSBENCH_NO_SIZE_CHECK=1 to run it anyway"
    )


def test_more_time_than_the_limit_is_refused() -> None:
    with pytest.raises(SizeError, match=r"about 4\.17 days of compute, more than the 24 h limit"):
        cost.check(Cost(1.0, 360_000.0), "this run", "--iterations", memory=lambda: 1e9)
    with pytest.raises(SizeError, match=r"about 2 h of compute, more than the 1 h limit"):
        cost.check(Cost(1.0, 7200.0), "this run", "--n", memory=lambda: 1e9, max_seconds=3600)


@pytest.mark.parametrize("value", ["1", "true", "YES"])
def test_the_override_lets_any_job_through(monkeypatch: pytest.MonkeyPatch, value: str) -> None:
    monkeypatch.setenv(cost.OVERRIDE, value)
    cost.check(Cost(1e20, 1e20), "this run", "--n", memory=lambda: 1.0)


def test_an_override_of_0_keeps_the_check(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(cost.OVERRIDE, "0")
    with pytest.raises(SizeError):
        cost.check(Cost(1e20, 1.0), "this run", "--n", memory=lambda: 1.0)


def test_available_memory_is_read_from_this_machine() -> None:
    assert 1e6 < cost.available_memory() < 1e15
