"""Trajectory: states must match the bodies, the times and the six state fields; one body's states
and one field across bodies are views by name; an npz round trip is exact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from physbench.errors import UnknownNameError
from physbench.trajectory import STATE_FIELDS, Trajectory


def _traj(frames: int = 4, bodies: tuple[str, ...] = ("a", "b", "c")) -> Trajectory:
    # states[t, i, k] = 100 t + 10 i + k: every entry says where it is
    t, i, k = np.meshgrid(np.arange(frames), np.arange(len(bodies)), np.arange(6), indexing="ij")
    return Trajectory(bodies, np.arange(frames) / 30, 100.0 * t + 10 * i + k, engine="toy")


def test_states_hold_six_fields_per_body_and_frame() -> None:
    assert STATE_FIELDS == ("x", "y", "angle", "vx", "vy", "omega")
    traj = _traj()
    assert traj.frames == 4 and traj.states.shape == (4, 3, 6)


@pytest.mark.parametrize(
    ("bodies", "times", "states", "message"),
    [
        (("a", "b"), 3, (3, 3, 6), r"states \(3, 3, 6\) do not match 2 bodies and 3 times"),
        (("a",), 3, (3, 1, 5), r"states \(3, 1, 5\) do not match 1 body and 3 times"),
        (("a",), 4, (3, 1, 6), r"states \(3, 1, 6\) do not match 1 body and 4 times"),
    ],
)
def test_states_that_do_not_match_are_refused(
    bodies: tuple[str, ...], times: int, states: tuple[int, ...], message: str
) -> None:
    with pytest.raises(ValueError, match=message):
        Trajectory(bodies, np.zeros(times), np.zeros(states))


def test_body_and_field_select_by_name() -> None:
    traj = _traj()
    assert traj.body("b").shape == (4, 6)
    assert traj.body("b")[2].tolist() == [210.0, 211.0, 212.0, 213.0, 214.0, 215.0]
    assert traj.field("vy").shape == (4, 3)
    assert traj.field("vy")[3].tolist() == [304.0, 314.0, 324.0]
    assert np.shares_memory(traj.body("b"), traj.states)  # views, not copies


def test_an_unknown_body_or_field_is_named_with_the_known_ones() -> None:
    traj = _traj()
    with pytest.raises(UnknownNameError, match=r"'nope'.*a, b, c"):
        traj.body("nope")
    with pytest.raises(UnknownNameError, match=r"'z'.*angle"):
        traj.field("z")


def test_npz_round_trip_is_exact(tmp_path: Path) -> None:
    traj = _traj()
    np.savez(tmp_path / "t.npz", **traj.to_npz_dict())
    with np.load(tmp_path / "t.npz") as data:
        back = Trajectory.from_npz_dict(dict(data))
    assert back.bodies == ("a", "b", "c") and all(type(b) is str for b in back.bodies)
    assert back.engine == "toy"
    assert np.array_equal(back.times, traj.times) and np.array_equal(back.states, traj.states)
    assert back.states.dtype == np.float64


def test_a_file_without_an_engine_reads_as_no_engine() -> None:
    d = _traj().to_npz_dict()
    del d["engine"]
    back = Trajectory.from_npz_dict(d)
    assert back.engine == "" and back.bodies == ("a", "b", "c")
    ints = {**d, "states": d["states"].astype(int), "times": np.arange(4)}
    assert Trajectory.from_npz_dict(ints).states.dtype == np.float64
