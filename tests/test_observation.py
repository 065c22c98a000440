"""Observation files: the documented .npz round trip, and bad files explained."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.observation import (
    Observation,
    ObservationError,
    load_observation,
    save_observation,
    simulate_observation,
)
from physbench.testing import toy_task


def test_observation_files_round_trip_and_bad_files_are_explained(tmp_path) -> None:  # type: ignore[no-untyped-def]
    t = toy_task()
    path = tmp_path / "obs.npz"
    save_observation(path, Observation(t.observation.frames, marked=t.observation.marked))
    back = load_observation(path)
    assert back.truth is None and back.scene is None and back.engine == ""
    assert np.array_equal(back.frames, t.observation.frames)
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


def test_a_simulated_observation_file_carries_its_scene_truth_and_engine(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from physbench.components import create
    from physbench.effects.drag import LinearDrag
    from physbench.render.raster import RasterRenderer
    from physbench.scenes import resolve_scene

    scene = resolve_scene("three_circles", 3)
    truth = {"a.mass": 2.5, "b.elasticity": 0.4}
    obs = simulate_observation(
        scene,
        truth,
        create("simulator", "box2d"),
        RasterRenderer(resolution=16),
        effects=[LinearDrag(c=0.2)],
    )
    save_observation(tmp_path / "obs.npz", obs)
    back = load_observation(tmp_path / "obs.npz")
    assert back.scene == scene.with_params(truth) and back.engine == "box2d"
    assert back.effects == ("LinearDrag(c=0.2)",)
    assert back.truth is not None and {k: back.truth[k] for k in truth} == truth
    # every other body parameter at the scene's value (a moment from shape and mass)
    assert back.truth["b.mass"] == scene.bodies[2].mass == 5.0
    assert back.truth["a.moment"] == scene.with_params(truth).bodies[1].inertia()


def test_a_zip_member_that_is_not_npy_is_an_observation_error(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import zipfile

    path = tmp_path / "obs.npz"
    np.savez(path, frames=np.zeros((2, 1, 4, 4), np.float32))
    with zipfile.ZipFile(path, "a") as z:
        z.writestr("notes.txt", b"hello")
    with pytest.raises(ObservationError, match=r"member 'notes.txt' is not a .npy array"):
        load_observation(path)


@pytest.mark.parametrize(
    ("frames", "fragment"),
    [
        (np.full((2, 1, 4, 4), np.nan, np.float32), "NaN or inf"),
        (np.full((2, 1, 4, 4), np.inf, np.float32), "NaN or inf"),
        (np.full((2, 1, 4, 4), 2.0, np.float32), r"span \[2, 2\], expected values in \[0, 1\]"),
        (np.zeros((2, 1, 4, 4), "M8[s]"), "expected numeric frames"),
        (np.zeros((2, 1, 4, 4), [("a", "f4"), ("b", "i4")]), "expected numeric frames"),
    ],
    ids=["nan", "inf", "above 1", "datetime64", "structured"],
)
def test_discover_checks_npz_frame_values_on_loading(tmp_path, frames, fragment) -> None:  # type: ignore[no-untyped-def]
    from physbench.discover.data import load_runs

    path = tmp_path / "obs.npz"
    np.savez(path, frames=frames)
    with pytest.raises(ObservationError, match=rf"obs.npz \['frames'\]: .*{fragment}"):
        load_runs(path, toy_task().scene)
