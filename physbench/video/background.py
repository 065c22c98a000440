"""The background a tracker subtracts: a plate of the empty scene, or the median of the video.

A plate (an image filmed before the bodies came in, or a camera renderer's
:meth:`~physbench.render.base.Camera.plate`) is the better choice: the median of a clip holds a
body that never moves as background. :func:`median_background` streams the video and keeps about
``samples`` frames spread over the whole clip (it never holds the video in memory).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    from physbench.video.reader import Frame, VideoReader


#: Frames a median background is taken over: a body moving on is gone from it, and the median
#: of 15 coded frames has a third of one frame's noise (30 cost twice the time, for a quarter
#: less noise).
SAMPLES = 15


class BackgroundError(PhysbenchError, ValueError):
    """A background that cannot be used: names the file or the value and what is expected."""


def load_plate(path: str | Path) -> np.ndarray:
    """The image of the empty scene at ``path`` (png, jpg, ...) as ``(H, W, 3)`` uint8 RGB."""
    from PIL import Image, UnidentifiedImageError

    p = Path(path)
    if not p.is_file():
        raise BackgroundError(f"background image {str(p)!r} does not exist")
    try:
        with Image.open(p) as im:
            return np.array(im.convert("RGB"))
    except (OSError, UnidentifiedImageError, ValueError) as exc:
        raise BackgroundError(
            f"background image {str(p)!r} cannot be read as an image (png, jpg, bmp, tif): {exc}"
        ) from None


@dataclass(frozen=True)
class MedianFrames:
    """A median background ``image`` and the ``frames`` (``(N, H, W, 3)`` uint8) it is the median
    of, at ``times`` (s from the source's first frame; NaN where the source gave none): the
    tracker takes the median again without the bodies it tracked (:mod:`~physbench.video.held`)
    where it holds one that stayed put."""

    image: np.ndarray
    frames: np.ndarray
    times: np.ndarray


def median_background(
    source: VideoReader | Iterable[Frame | np.ndarray], *, samples: int = SAMPLES
) -> np.ndarray:
    """The per-pixel median of about ``samples`` frames spread over the whole of ``source`` (a
    :class:`~physbench.video.reader.VideoReader` or frames / ``(H, W, 3)`` arrays), streamed: it
    keeps every ``k``-th frame and doubles ``k`` (dropping every other kept frame) whenever more
    than ``2 samples`` are held, so memory stays flat in the video's length. A reader that
    counts its frames is asked for the same frames by index, and decodes only what they need."""
    return median_frames(source, samples=samples).image


def median_frames(
    source: VideoReader | Iterable[Frame | np.ndarray], *, samples: int = SAMPLES
) -> MedianFrames:
    """:func:`median_background` with the frames it is taken over."""
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise BackgroundError(f"samples = {samples!r}: expected a whole number >= 1")
    counted = hasattr(source, "frames") and hasattr(source, "count")  # a list has a count too
    kept = _chosen(source, samples) if counted else None  # type: ignore[arg-type]
    if kept is None:  # streamed
        kept = _kept(source.frames if hasattr(source, "frames") else lambda _: source, samples)
    if not kept:
        raise BackgroundError("no frames to take a median background from")
    shapes = {k.shape for k, _ in kept}
    if len(shapes) != 1:
        raise BackgroundError(f"frames of different sizes: {sorted(shapes)}")
    stack = np.stack([k for k, _ in kept])
    times = np.array([t for _, t in kept], dtype=float)
    return MedianFrames(_median(stack), stack, times - times[0])


def _chosen(reader: VideoReader, samples: int) -> list[tuple[np.ndarray, float]] | None:
    """The images :func:`_kept` keeps of ``reader``, chosen from its frame count up front, so
    that only they and the frames they are decoded from are decoded (``sparse``); ``None``
    where the count is unknown, or the reader cannot tell which frame is which before decoding
    (then the frames are streamed)."""
    from physbench.video.reader import SparseError

    n = reader.count()
    if not n:
        return None
    indices = _kept(lambda _: range(n), samples)  # what streaming n frames would keep
    wanted = set(int(i) for i, _ in indices)
    try:
        frames = list(reader.frames(wanted.__contains__, sparse=True))
    except SparseError:
        return None
    if [f.index for f in frames] != sorted(wanted):  # counted wrong: stream them instead
        return None
    return [(f.image, f.time) for f in frames]


def _kept(
    frames: Callable[[Callable[[int], bool]], Iterable[Frame | np.ndarray]], samples: int
) -> list[tuple[np.ndarray, float]]:
    """Every ``k``-th image of ``frames(wanted)`` with its time (NaN for a bare array), ``k``
    doubled (every other kept image dropped) whenever more than ``2 samples`` are held, then
    thinned evenly to about ``samples``."""
    step = 1

    def wanted(i: int) -> bool:
        return i % step == 0

    kept: list[tuple[np.ndarray, float]] = []
    # A reader converts only the frames kept to images (decoding the rest is unavoidable).
    for i, fr in enumerate(frames(wanted)):
        index = getattr(fr, "index", i)
        if not wanted(index):
            continue
        kept.append((np.asarray(getattr(fr, "image", fr)), float(getattr(fr, "time", np.nan))))
        if len(kept) > 2 * samples:
            kept = kept[::2]
            step *= 2
    if len(kept) > samples:
        kept = [kept[int(j)] for j in np.linspace(0, len(kept) - 1, samples).round()]
    return kept


#: Pixel values a band of the median's selection network takes at a time (the ``N`` rows of a band
#: stay in the cache between its compare-exchanges).
BAND = 32768


def _median(stack: np.ndarray) -> np.ndarray:
    """The per-pixel median of ``stack`` ``(N, H, W, 3)`` uint8, rounded (the mean of the two
    middle values of an even ``N``, rounded half up): a selection network of elementwise minima
    and maxima in uint8 over a band of pixels at a time, 5 ms for 15 frames of 640x480 (a partial
    sort along the frames took 140 ms; ``np.median`` converts to float64 and sorts, slower still;
    ``benchmarks/track_speed.py``)."""
    n = len(stack)
    mid = n // 2
    size = 1 << (n - 1).bit_length()  # padded with 255s, which sort last
    pairs = _network(size, (mid - 1, mid) if n % 2 == 0 else (mid,))
    flat = stack.reshape(n, -1)
    total = flat.shape[1]
    out = np.empty(total, np.uint8)
    for a in range(0, total, BAND):
        b = min(a + BAND, total)
        rows = [flat[k, a:b].copy() for k in range(n)]
        rows += [np.full(b - a, 255, np.uint8) for _ in range(size - n)]
        spare = np.empty(b - a, np.uint8)
        for i, j in pairs:
            np.minimum(rows[i], rows[j], out=spare)
            np.maximum(rows[i], rows[j], out=rows[j])
            rows[i], spare = spare, rows[i]
        if n % 2:
            out[a:b] = rows[mid]
        else:
            out[a:b] = (rows[mid - 1].astype(np.uint16) + rows[mid] + 1) // 2
    return out.reshape(stack.shape[1:])


def _network(size: int, wanted: tuple[int, ...]) -> list[tuple[int, int]]:
    """The compare-exchanges ``(i, j)`` (``i`` takes the smaller) of Batcher's odd-even merge
    sort of ``size`` (a power of two) values that the sorted positions ``wanted`` depend on."""
    pairs = []
    p = 1
    while p < size:
        k = p
        while k >= 1:
            for j in range(k % p, size - k, 2 * k):
                for i in range(min(k, size - j - k)):
                    if (i + j) // (2 * p) == (i + j + k) // (2 * p):
                        pairs.append((i + j, i + j + k))
            k //= 2
        p *= 2
    need, kept = set(wanted), []
    for i, j in reversed(pairs):
        if i in need or j in need:
            kept.append((i, j))
            need |= {i, j}
    return kept[::-1]
