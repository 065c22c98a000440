"""Observation files: the documented .npz round trip, and bad files explained."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.observation import ObservationError, load_observation, save_observation
from physbench.testing import toy_task


def test_observation_files_round_trip_and_bad_files_are_explained(tmp_path) -> None:  # type: ignore[no-untyped-def]
    t = toy_task()
    path = tmp_path / "obs.npz"
    save_observation(path, t.observation)
    back = load_observation(path)
    assert back.truth is None and np.array_equal(back.frames, t.observation.frames)
    assert set(back.marked) == {"a", "b"}
    np.savez(tmp_path / "nokey.npz", images=t.observation.frames)
    with pytest.raises(ObservationError, match=r"no 'frames' array .*found: images"):
        load_observation(tmp_path / "nokey.npz")
    np.savez(tmp_path / "flat.npz", frames=t.observation.frames[0])
    with pytest.raises(ObservationError, match=r"shape \(2, 16, 16\); expected 4 axes"):
        load_observation(tmp_path / "flat.npz")
    with pytest.raises(ObservationError, match="does not exist"):
        load_observation(tmp_path / "missing.npz")
    (tmp_path / "junk.npz").write_text("not a zip")
    with pytest.raises(ObservationError, match=r"cannot read as \.npz"):
        load_observation(tmp_path / "junk.npz")
