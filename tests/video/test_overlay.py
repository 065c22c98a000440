"""Overlays: tracks drawn on the frames, written as mp4 or gif; other suffixes are refused."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.video.overlay import OverlayError, draw_tracks, write_overlay
from physbench.video.reader import VideoReader
from physbench.video.writer import write_video


def test_tracks_are_drawn_and_written(tmp_path) -> None:
    frames = [np.full((48, 64, 3), 40, np.uint8) for _ in range(5)]
    write_video(tmp_path / "in.mp4", frames, fps=10)
    rows = np.array([[k / 10, 20 + 3 * k, 24.0] for k in range(5)])
    img = draw_tracks(frames[0], {"ball": rows}, 0.3)
    assert (img[24, 29] != 40).any() and (frames[0] == 40).all()  # a copy, marked at u=29
    for name in ("out.mp4", "out.gif"):
        out = write_overlay(tmp_path / name, tmp_path / "in.mp4", {"ball": rows})
        assert len(list(VideoReader(out, fps=10).frames())) == 5
    with pytest.raises(OverlayError, match=r"expected a \.mp4 or \.gif file"):
        write_overlay(tmp_path / "out.png", tmp_path / "in.mp4", {"ball": rows})


def test_a_slow_motion_overlay_marks_every_frame_and_plays_as_the_file(tmp_path) -> None:
    frames = [np.full((48, 64, 3), 40, np.uint8) for _ in range(5)]
    write_video(tmp_path / "slow.mp4", frames, fps=10)  # filmed at 80 frames/s
    rows = np.array([[k / 80, 20 + 3 * k, 24.0] for k in range(5)])  # real seconds
    out = write_overlay(tmp_path / "o.mp4", tmp_path / "slow.mp4", {"ball": rows}, capture_fps=80)
    got = list(VideoReader(out).frames())
    assert [round(f.time, 3) for f in got] == [0.0, 0.1, 0.2, 0.3, 0.4]  # as the file plays
    for k, f in enumerate(got):
        assert (np.abs(f.image[24, 20 + 3 * k].astype(int) - 40) > 60).any(), k  # marked
