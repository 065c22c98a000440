"""Writing video files with real lossy encoding (H.264 through PyAV's FFmpeg), with each frame's
time kept as its container timestamp."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from pathlib import Path

import numpy as np

from physbench.video.reader import VideoError, _av

#: Timestamps are written in these units (ticks per second): fine enough for any camera's clock.
TIME_BASE = Fraction(1, 90_000)


def write_video(
    path: str | Path,
    frames: Iterable[np.ndarray],
    *,
    fps: float,
    times: Sequence[float] | None = None,
    codec: str = "libx264",
    bitrate: int | None = None,
    crf: int | None = None,
) -> Path:
    """Encode ``frames`` (each ``(H, W, 3)`` uint8 RGB, H and W even for H.264) into ``path``.

    ``fps`` is the nominal rate; ``times`` (s, increasing), when given, become the frames'
    timestamps, so a variable frame rate or dropped frames are recorded as such. ``bitrate``
    (bits/s) or ``crf`` (H.264 quality, 0-51) sets the compression. Returns the path.
    """
    av = _av()
    if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
        raise VideoError(f"fps = {fps!r}: expected a number > 0")
    if times is not None and (np.diff(np.asarray(times, dtype=float)) <= 0).any():
        raise VideoError("times: expected strictly increasing frame times (s)")
    path = Path(path)
    container = av.open(str(path), mode="w")
    try:
        stream = container.add_stream(codec, rate=Fraction(fps).limit_denominator(1001))
        stream.time_base = TIME_BASE
        stream.codec_context.time_base = TIME_BASE  # frame pts are in these ticks, not 1/fps
        stream.pix_fmt = "yuv420p"
        if bitrate is not None:
            stream.bit_rate = int(bitrate)
        if crf is not None:
            stream.options = {"crf": str(int(crf))}
        n = 0
        for i, image in enumerate(frames):
            img = np.ascontiguousarray(image, dtype=np.uint8)
            if img.ndim != 3 or img.shape[2] != 3:
                raise VideoError(f"frame {i}: expected (H, W, 3) RGB, got shape {img.shape}")
            if n == 0:
                stream.width, stream.height = img.shape[1], img.shape[0]
            frame = av.VideoFrame.from_ndarray(img, format="rgb24")
            t = times[i] if times is not None else i / fps
            frame.pts = round(t / TIME_BASE)
            frame.time_base = TIME_BASE
            container.mux(stream.encode(frame))
            n += 1
        if n == 0:
            raise VideoError(f"{str(path)!r}: no frames to write")
        container.mux(stream.encode(None))
    except av.error.FFmpegError as exc:
        raise VideoError(f"{str(path)!r}: encoding failed ({exc})") from None
    finally:
        container.close()
    return path
