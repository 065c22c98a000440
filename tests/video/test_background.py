"""Backgrounds: a plate is read or refused by name; the median streams and removes moving bodies."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from physbench.video.background import (
    BackgroundError,
    load_plate,
    median_background,
    median_frames,
)


def test_a_plate_reads_as_rgb_and_bad_files_are_named(tmp_path) -> None:
    img = np.random.default_rng(0).integers(0, 256, (6, 8, 3), dtype=np.uint8)
    Image.fromarray(img).convert("L").save(tmp_path / "grey.png")
    plate = load_plate(tmp_path / "grey.png")
    assert plate.shape == (6, 8, 3) and plate.dtype == np.uint8
    with pytest.raises(BackgroundError, match="does not exist"):
        load_plate(tmp_path / "none.png")
    (tmp_path / "bad.png").write_text("not an image")
    with pytest.raises(BackgroundError, match=r"'.*bad.png' cannot be read as an image"):
        load_plate(tmp_path / "bad.png")


def test_the_median_removes_a_moving_body_and_holds_few_frames() -> None:
    bg = np.full((10, 40, 3), 90, np.uint8)
    held = []

    def frames(n: int):
        for i in range(n):
            img = bg.copy()
            img[4:7, i % 40 : i % 40 + 3] = 250  # a body sweeping across
            held.append(img)
            yield img

    out = median_background(frames(1000), samples=9)
    np.testing.assert_array_equal(out, bg)
    with pytest.raises(BackgroundError, match="samples = 0"):
        median_background(frames(3), samples=0)
    with pytest.raises(BackgroundError, match="no frames"):
        median_background(iter([]))


@pytest.mark.parametrize("n", [1, 2, 7, 8, 15, 31])
def test_the_median_is_numpys_median(n: int) -> None:
    from physbench.video.background import _median

    stack = np.random.default_rng(n).integers(0, 256, (n, 37, 23, 3), dtype=np.uint8)
    want = np.median(stack, axis=0)
    got = _median(stack).astype(float)
    # Odd counts exactly; even ones round the middle pair's half up (numpy: to even).
    assert np.abs(got - want).max() <= (0 if n % 2 else 0.5)


def test_a_median_read_sparsely_is_the_median_of_the_streamed_frames(tmp_path) -> None:
    # A reader that counts its frames is asked for the streamed median's frames by index and
    # decodes only what they need; where a frame counted is missing, or the reader cannot tell which
    # frame is which before decoding, the frames are streamed as before.
    pytest.importorskip("av")
    from physbench.video.reader import SparseError, VideoReader
    from physbench.video.writer import write_video

    rng = np.random.default_rng(3)
    frames = [rng.integers(0, 256, (32, 48, 3), dtype=np.uint8) for _ in range(70)]
    reader = VideoReader(write_video(tmp_path / "c.mp4", frames, fps=30))
    assert reader.count() == 70
    streamed = median_background(reader.frames(), samples=9)  # a generator: no count
    np.testing.assert_array_equal(median_background(reader, samples=9), streamed)

    class Unordered:
        def __init__(self, count: int) -> None:
            self.n = count

        def count(self) -> int:
            return self.n

        def frames(self, select, *, sparse=False):  # type: ignore[no-untyped-def]
            if sparse and self.n == 70:
                yield next(reader.frames(select))
                raise SparseError("order not known")
            yield from reader.frames(select, sparse=sparse)

    for n in (70, 90):  # the order unknown; frames counted that are not there
        np.testing.assert_array_equal(median_background(Unordered(n), samples=9), streamed)
    as_list = list(VideoReader(reader.path).frames())  # frames in a list: streamed
    np.testing.assert_array_equal(median_background(as_list, samples=9), streamed)
    images = [f.image for f in as_list]
    np.testing.assert_array_equal(median_background(tuple(images), samples=9), streamed)


def test_the_median_keeps_its_frames_and_their_times(tmp_path) -> None:
    # The tracker takes the median again over the same frames without its bodies
    # (physbench.video.held), so it needs them and when they were filmed.
    pytest.importorskip("av")
    from physbench.video.reader import VideoReader
    from physbench.video.writer import write_video

    rng = np.random.default_rng(4)
    frames = [rng.integers(0, 256, (32, 48, 3), dtype=np.uint8) for _ in range(70)]
    reader = VideoReader(write_video(tmp_path / "c.mp4", frames, fps=20))
    kept = median_frames(reader, samples=9)
    decoded = [f.image for f in VideoReader(reader.path).frames()]
    indices = np.rint(kept.times * 20).astype(int)
    assert kept.times[0] == 0 and np.all(np.diff(indices) > 0) and len(indices) == len(kept.frames)
    np.testing.assert_allclose(kept.times, indices / 20, atol=1e-6)
    for k, i in enumerate(indices):
        np.testing.assert_array_equal(kept.frames[k], decoded[i])
    np.testing.assert_array_equal(kept.image, median_background(reader, samples=9))
    bare = median_frames(iter(decoded), samples=9)  # bare arrays: times unknown
    assert np.isnan(bare.times).all()
    np.testing.assert_array_equal(bare.image, kept.image)
