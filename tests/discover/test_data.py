"""Runs and the held-out split (physbench/discover/data.py)."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.discover import DiscoverError, Run, load_runs, make_split
from physbench.discover.data import sub_recording
from physbench.recording import Recording, Track, write_recordings
from physbench.scene_toml import save_scene


def test_splits_by_time_and_by_runs(slide):
    rec = Recording({"ball": Track(np.arange(21) * 0.1, np.zeros(21), np.zeros(21))})
    scene = slide(frames=21, fps=10.0)
    s = make_split([Run("r", scene, recording=rec)], holdout=0.3)
    assert s.kind == "time" and s.fit[0].size == 15 and s.held[0].size == 6
    runs = [Run(f"r{i}", scene, recording=rec) for i in range(4)]
    s = make_split(runs, holdout=0.3)
    assert s.kind == "runs" and s.train_runs == (0, 1, 2) and s.test_runs == (3,)
    assert s.lead[0].size == 6
    with pytest.raises(DiscoverError, match="leaves 2 samples to fit"):
        make_split([Run("short", scene, recording=sub_recording(rec, -1, 0.35))], holdout=0.5)
    with pytest.raises(DiscoverError, match=r"holdout = 0\.9"):
        make_split(runs, holdout=0.9)


def test_a_run_holds_exactly_one_of_a_recording_and_frames(slide):
    with pytest.raises(DiscoverError, match="exactly one of a recording and frames"):
        Run("r", slide())
    frames = np.zeros((5, 1, 8, 8), np.float32)
    run = Run("r", slide(frames=41), frames=frames)
    assert run.kind == "frames" and run.scene.frames == 5  # the scene covers the data


def test_load_runs_reads_one_run_per_label(tmp_path, slide):
    t = np.arange(21) * 0.05
    recs = [
        Recording({"ball": Track(t, 1 + 2 * t, 1 + 0.5 * t)}, run=label) for label in ("a", "b")
    ]
    write_recordings(tmp_path / "r.csv", recs)
    save_scene(slide(), tmp_path / "s.toml")
    runs = load_runs(tmp_path / "r.csv", tmp_path / "s.toml")
    assert [r.name for r in runs] == ["a", "b"] and runs[0].scene.frames == 21
    assert [r.name for r in load_runs(tmp_path / "r.csv", tmp_path / "s.toml", run="b")] == ["b"]


def test_video_options_apply_to_a_video_only(tmp_path, slide):
    t = np.arange(21) * 0.05
    write_recordings(tmp_path / "r.csv", Recording({"ball": Track(t, 1 + 2 * t, 1 + 0.5 * t)}))
    save_scene(slide(), tmp_path / "s.toml")
    with pytest.raises(DiscoverError, match=r"calibration, start apply to a video only"):
        load_runs(tmp_path / "r.csv", tmp_path / "s.toml", calibration="c.toml", start=1.0)
    with pytest.raises(DiscoverError, match=r"capture_fps apply to a video only"):
        load_runs(tmp_path / "r.csv", tmp_path / "s.toml", capture_fps=240.0)


def test_unknown_inputs_name_every_accepted_format(tmp_path, slide):
    save_scene(slide(), tmp_path / "s.toml")
    (tmp_path / "r.txt").write_text("hello")
    with pytest.raises(DiscoverError, match=r"\.csv.*\.npz.*\.mp4.*folder of images"):
        load_runs(tmp_path / "r.txt", tmp_path / "s.toml")
    with pytest.raises(DiscoverError, match=r"does not exist.*\.mp4"):
        load_runs(tmp_path / "missing.mp4", tmp_path / "s.toml")
