"""Reading video: timestamps from the container (a variable frame rate survives), streaming,
trimming, GIFs and folders of images, and clear errors for files that are not usable."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("av")

from physbench.video.reader import VideoError, VideoReader
from physbench.video.writer import write_video


def frame(i: int, h: int = 48, w: int = 64) -> np.ndarray:
    """A frame whose bright square's column encodes its index."""
    img = np.zeros((h, w, 3), np.uint8)
    img[10:30, 2 + 3 * i : 12 + 3 * i] = 255
    return img


def column(img: np.ndarray) -> float:
    cols = img[:, :, 0].astype(float).sum(axis=0)
    return float((cols * np.arange(img.shape[1])).sum() / cols.sum())


def test_a_variable_frame_rate_clip_reads_back_with_its_own_times(tmp_path: Path) -> None:
    times = [0.0, 0.033, 0.067, 0.150, 0.183, 0.300]  # two dropped-frame gaps
    clip = write_video(tmp_path / "vfr.mp4", (frame(i) for i in range(6)), fps=30, times=times)
    got = list(VideoReader(clip).frames())
    assert [f.index for f in got] == list(range(6))
    np.testing.assert_allclose([f.time for f in got], times, atol=1e-4)
    assert all(f.image.shape == (48, 64, 3) and f.image.dtype == np.uint8 for f in got)
    # lossy, but the content is in the right frame: the square moved 3 px a frame
    np.testing.assert_allclose(
        [column(f.image) for f in got], [6.5 + 3 * i for i in range(6)], atol=0.5
    )
    info = VideoReader(clip).info()
    assert (info.width, info.height, info.codec) == (64, 48, "h264")
    assert info.subsampled  # 4:2:0: colour at half the resolution, as a camera's


def test_trimming_keeps_the_file_times_and_streams(tmp_path: Path) -> None:
    clip = write_video(tmp_path / "c.mp4", (frame(i) for i in range(10)), fps=10)
    reader = VideoReader(clip, start=0.25, end=0.6)
    frames = reader.frames()
    first = next(frames)  # a generator: nothing is decoded ahead of use
    assert first.index == 0 and first.time == pytest.approx(0.3)
    assert [round(f.time, 3) for f in frames] == [0.4, 0.5, 0.6]
    with pytest.raises(VideoError, match="no frames between 5 and 6 s"):
        list(VideoReader(clip, start=5, end=6).frames())
    with pytest.raises(VideoError, match=r"end = 0\.1: must come after start = 0\.2"):
        VideoReader(clip, start=0.2, end=0.1)


def test_gifs_and_folders_of_images(tmp_path: Path) -> None:
    from PIL import Image

    imgs = [Image.fromarray(frame(i)) for i in range(4)]
    imgs[0].save(tmp_path / "a.gif", save_all=True, append_images=imgs[1:], duration=100)
    got = list(VideoReader(tmp_path / "a.gif").frames())
    assert len(got) == 4 and got[3].time == pytest.approx(0.3)
    folder = tmp_path / "shots"
    folder.mkdir()
    for i, im in enumerate(imgs):
        im.save(folder / f"img_{i:03d}.png")
    (folder / "notes.txt").write_text("not a frame")
    seq = list(VideoReader(folder, fps=20).frames())
    assert [f.time for f in seq] == [0.0, 0.05, 0.1, 0.15]
    assert np.array_equal(seq[2].image, frame(2))
    assert not VideoReader(folder, fps=20).info().subsampled  # every pixel its own colour
    assert not VideoReader(tmp_path / "a.gif").info().subsampled
    with pytest.raises(VideoError, match="give its frame rate"):
        VideoReader(folder)
    (tmp_path / "empty_dir").mkdir()
    with pytest.raises(VideoError, match="holds no images"):
        VideoReader(tmp_path / "empty_dir")


def test_unusable_files_are_named_and_left_untouched(tmp_path: Path) -> None:
    clip = write_video(tmp_path / "c.mp4", (frame(i) for i in range(10)), fps=10)
    data = clip.read_bytes()
    (tmp_path / "cut.mp4").write_bytes(data[: len(data) // 3])
    (tmp_path / "text.mp4").write_text("hello")
    (tmp_path / "empty.mp4").write_bytes(b"")
    for name in ("cut.mp4", "text.mp4", "empty.mp4"):
        with pytest.raises(VideoError, match=name):
            list(VideoReader(tmp_path / name).frames())
    with pytest.raises(VideoError, match="does not exist"):
        VideoReader(tmp_path / "missing.mp4")
    # A codec FFmpeg has no decoder for: the stream's sample entry renamed from avc1.
    (tmp_path / "odd.mp4").write_bytes(data.replace(b"avc1", b"zzz9"))
    with pytest.raises(VideoError, match=r"odd\.mp4': its video codec is not supported"):
        VideoReader(tmp_path / "odd.mp4").info()
    assert clip.read_bytes() == data and (tmp_path / "text.mp4").read_text() == "hello"
    with pytest.raises(VideoError, match="no frames to write"):
        write_video(tmp_path / "none.mp4", [], fps=10)
    with pytest.raises(VideoError, match="strictly increasing"):
        write_video(tmp_path / "t.mp4", [frame(0), frame(1)], fps=10, times=[0.1, 0.1])


def test_frames_can_be_selected_without_converting_the_others(tmp_path: Path) -> None:
    # A median background keeps every k-th frame: the others are decoded (a video needs them)
    # but not yielded, with the same indices and times as without a selection.
    clip = write_video(tmp_path / "c.mp4", (frame(i) for i in range(9)), fps=30)
    every = list(VideoReader(clip).frames())
    some = list(VideoReader(clip).frames(lambda k: k % 3 == 0))
    assert [f.index for f in some] == [0, 3, 6]
    assert [f.time for f in some] == [every[k].time for k in (0, 3, 6)]
    np.testing.assert_array_equal(some[1].image, every[3].image)
    assert list(VideoReader(clip).frames(lambda k: False)) == []  # decoded, none wanted: no error


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """How many frames each read decodes (one entry per read)."""
    decoded = VideoReader._decoded
    counts: list[int] = []

    def counted(*args):  # type: ignore[no-untyped-def]
        counts.append(0)
        for frame in decoded(*args):
            counts[-1] += 1
            yield frame

    monkeypatch.setattr(VideoReader, "_decoded", staticmethod(counted))
    return counts


@pytest.mark.parametrize("start", [0.0, 0.4])
@pytest.mark.parametrize("keep", [(0, 8, 16, 24, 32), (3, 5, 29)])
def test_a_sparse_read_leaves_out_unwanted_non_reference_frames_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, start: float, keep: tuple[int, ...]
) -> None:
    # x264's defaults code B-frames no other frame is decoded from: a median background keeps 1
    # frame in 8 or fewer and need not decode them. What it does keep is the same to the bit.
    times = [i / 30 + (0.02 if i > 20 else 0.0) for i in range(40)]  # a dropped-frame gap
    clip = write_video(tmp_path / "c.mp4", (frame(i % 18) for i in range(40)), fps=30, times=times)
    counts = _counting(monkeypatch)
    full = list(VideoReader(clip, start=start).frames(lambda k: k in keep))
    sparse = list(VideoReader(clip, start=start).frames(lambda k: k in keep, sparse=True))
    assert [f.index for f in full] == [k for k in keep if k < sum(t > start - 1e-3 for t in times)]
    assert [(f.index, f.time) for f in sparse] == [(f.index, f.time) for f in full]
    for a, b in zip(full, sparse, strict=True):
        np.testing.assert_array_equal(a.image, b.image)
    assert counts[0] == 40 and counts[1] <= 36, counts  # 7-8 of the B-frames left out here


def test_a_sparse_read_of_frames_whose_order_is_unknown_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from physbench.video.reader import SparseError, _Order

    clip = write_video(tmp_path / "c.mp4", (frame(i) for i in range(12)), fps=30)
    every = list(VideoReader(clip).frames(sparse=True))  # nothing refused: every frame
    assert [f.index for f in every] == list(range(12))
    order = VideoReader._display_order

    def short(self, stream):  # type: ignore[no-untyped-def]
        o = order(self, stream)
        return _Order(sorted(o.index)[:-3], 0.0, stream.time_base)  # three frames not listed

    monkeypatch.setattr(VideoReader, "_display_order", short)
    with pytest.raises(SparseError, match="order is not known"):
        list(VideoReader(clip).frames(lambda k: k % 4 == 0, sparse=True))


def _turned_clip(path: Path, upright: np.ndarray, degrees: float, frames: int = 3) -> None:
    """``upright`` stored as a phone stores a portrait clip: turned against its display rotation
    (``degrees`` counter-clockwise), the rotation written beside it."""
    import av

    stored = np.ascontiguousarray(np.rot90(upright, -round(degrees / 90)))
    with av.open(str(path), "w") as out:
        s = out.add_stream("libx264", rate=10)
        s.height, s.width = stored.shape[:2]
        s.pix_fmt = "yuv420p"
        s.options = {"crf": "10"}
        s.set_display_rotation(degrees)
        for i in range(frames):
            f = av.VideoFrame.from_ndarray(stored, format="rgb24")
            f.pts = i
            for p in s.encode(f):
                out.mux(p)
        for p in s.encode():
            out.mux(p)


def test_a_phone_clip_with_a_display_rotation_is_read_upright(tmp_path: Path) -> None:
    upright = np.full((64, 48, 3), 40, np.uint8)  # portrait, as shown
    upright[4:16, 6:18] = 230  # a mark near the top-left corner
    for degrees in (-90, 90, 180):
        path = tmp_path / f"turned{degrees}.mp4"
        _turned_clip(path, upright, degrees)
        reader = VideoReader(path)
        info = reader.info()
        assert (info.width, info.height) == (48, 64), degrees
        for fr in reader.frames():
            assert fr.image.shape == upright.shape
            assert np.abs(fr.image.astype(int) - upright).mean() < 3, degrees
    _turned_clip(tmp_path / "tilted.mp4", upright[:48], 45)
    with pytest.raises(VideoError, match=r"turned by 45 degrees.*quarter turns"):
        list(VideoReader(tmp_path / "tilted.mp4").frames())


def test_interlaced_video_is_named_and_warned_of(tmp_path: Path, still_disc) -> None:  # type: ignore[no-untyped-def]
    """An interlaced clip (as camcorders and older teaching clips are) says so in its info, and
    tracking it warns with the fix (a frame per field, at twice the rate); a progressive clip
    says nothing."""
    import warnings

    from physbench.errors import PhysbenchWarning
    from physbench.video.track import track_video

    scene, cal, plate = still_disc.scene, still_disc.calibration, still_disc.plate
    combed = still_disc.clip(tmp_path / "interlaced.mp4", interlaced=True)
    assert VideoReader(combed).info().interlaced
    with pytest.warns(
        PhysbenchWarning, match=r"is interlaced video.*\(20 frames/s\): ffmpeg -i IN -vf yadif=1"
    ):
        got = track_video(combed, scene, cal, background=plate)
    assert got.summary.detections["ball"] == 20
    plain = still_disc.clip(tmp_path / "progressive.mp4")
    assert not VideoReader(plain).info().interlaced
    with warnings.catch_warnings():
        warnings.simplefilter("error", PhysbenchWarning)
        track_video(plain, scene, cal, background=plate)
