"""Pictures of a tracking run: each body's centre, a short trail and its name drawn on the video.

:func:`draw_tracks` marks one frame; :func:`write_overlay` re-reads the video and writes the marked
frames to an ``.mp4`` (H.264, through :func:`~physbench.video.writer.write_video`, streamed) or an
animated ``.gif`` (PIL; a GIF holds its frames in memory, so keep it to short clips).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from physbench.errors import PhysbenchError

#: Overlay file suffixes.
OVERLAY_SUFFIXES = (".mp4", ".gif")
_COLOURS = ((255, 64, 64), (64, 160, 255), (64, 220, 64), (255, 210, 0), (230, 64, 230))


class OverlayError(PhysbenchError, ValueError):
    """An overlay that cannot be written: names the path or value and what is accepted."""


def draw_tracks(
    image: np.ndarray, pixels: Mapping[str, np.ndarray], t: float, *, trail: float = 0.5
) -> np.ndarray:
    """A copy of ``image`` (``(H, W, 3)`` uint8) with each body of ``pixels`` (name -> ``(n, 3)``
    rows of ``t, u, v``) marked at time ``t``: a cross at its centre, its path over the last
    ``trail`` s and its name. A body not measured at ``t`` gets only its trail."""
    from PIL import Image, ImageDraw

    im = Image.fromarray(image)
    draw = ImageDraw.Draw(im)
    for k, (name, rows) in enumerate(pixels.items()):
        colour = _COLOURS[k % len(_COLOURS)]
        if len(rows) == 0:
            continue
        past = rows[(rows[:, 0] <= t + 1e-9) & (rows[:, 0] >= t - trail)]
        if len(past) > 1:
            draw.line([(float(u), float(v)) for _, u, v in past], fill=colour, width=2)
        now = past[np.abs(past[:, 0] - t) < 1e-6] if len(past) else past
        if len(now):
            u, v = float(now[0, 1]), float(now[0, 2])
            draw.line([(u - 6, v), (u + 6, v)], fill=colour, width=2)
            draw.line([(u, v - 6), (u, v + 6)], fill=colour, width=2)
            draw.text((u + 8, v - 14), name, fill=colour)
    return np.asarray(im)


def write_overlay(
    path: str | Path,
    video: str | Path,
    pixels: Mapping[str, np.ndarray],
    *,
    start: float | None = None,
    end: float | None = None,
    trail: float = 0.5,
    fps: float | None = None,
    capture_fps: float | None = None,
) -> Path:
    """Write ``video`` (trimmed to ``start``/``end`` as it was tracked) with the tracks of
    ``pixels`` (times from its first frame) drawn on, to ``path`` (``.mp4`` or ``.gif``).
    ``fps``: the frame rate of a folder of images (the one it was tracked at); ``capture_fps``:
    the rate a slow-motion file was tracked at (``pixels`` are in real seconds; the overlay
    plays as the file does)."""
    from physbench.video.reader import VideoReader

    out = Path(path)
    suffix = out.suffix.lower()
    if suffix not in OVERLAY_SUFFIXES:
        raise OverlayError(f"overlay {str(out)!r}: expected a {' or '.join(OVERLAY_SUFFIXES)} file")
    reader = VideoReader(video, start=start, end=end, fps=fps, capture_fps=capture_fps)
    slow = 1.0  # file seconds per real second
    if capture_fps is not None and not reader.images:
        slow = capture_fps / (reader.info().rate or capture_fps)
    times: list[float] = []

    def marked() -> Iterator[np.ndarray]:
        t0 = None
        for fr in reader.frames():
            t0 = fr.time if t0 is None else t0
            times.append((fr.time - t0) * slow)
            img = draw_tracks(fr.image, pixels, fr.time - t0, trail=trail)
            h, w = img.shape[:2]
            yield img[: h - h % 2, : w - w % 2]  # H.264 wants even sizes

    out.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".gif":
        from PIL import Image

        images = [Image.fromarray(f) for f in marked()]
        gaps = np.diff(times) if len(times) > 1 else np.array([0.1])
        ms = round(1000 * float(np.median(gaps)))
        images[0].save(out, save_all=True, append_images=images[1:], duration=ms, loop=0)
        return out
    from physbench.video.writer import write_video

    rate = reader.info().rate or 30.0
    # `times` fills as the frames stream: frame i's time is in it when the writer reads times[i].
    write_video(out, marked(), fps=rate, times=times)
    return out
