"""Video codecs through PyAV (FFmpeg inside its wheel, ``pip install physbench[video]``): the one
place that imports ``av``. The video package reads and writes files with it; a camera renderer
passes its frames through an in-memory H.264 encode and decode (:func:`h264_round_trip`) so that
they are what a video file would hold. :data:`IMAGE_SUFFIXES` names the image files a folder of
frames may hold (read by PIL), which a Tracker project's image sequence is checked against too."""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np

from physbench.errors import PhysbenchError

#: Image files a folder may hold, as a video's frames.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")
#: Threads every encoder runs with. x264's output depends on its thread count, which FFmpeg sets
#: from the machine's cores by default: the same frames coded on one core and on two differ (a
#: ball's highlight came out with a hole on one core only). A fixed count makes a clip the same
#: on every machine; 2 is what the committed results were filmed with (2-core machines).
ENCODER_THREADS = 2
#: x264 settings every file encoder adds. x264's macroblock tree (``mbtree``, on in its default
#: preset) is not deterministic in the wheel's build: one 12-frame clip, encoded 25 times in one
#: process with one thread, came out as 11 different files, and the results depended on how many
#: clips the process had encoded before. (Without x264's assembly one thread was deterministic but
#: two were not.) With ``mbtree=0`` the same encodes gave one file every time, with one thread or
#: two, on 12 or 60 frames.
#: :func:`h264_round_trip` needs no such setting: ``tune=zerolatency`` has no lookahead, so no tree.
X264_PARAMS = "mbtree=0"


class CodecError(PhysbenchError, ValueError):
    """PyAV is missing, or a codec failed: names what to install or what went wrong."""


def load_av() -> Any:
    """The ``av`` module; :class:`CodecError` naming the extra to install when it is missing."""
    try:
        import av
    except ImportError:
        raise CodecError(
            "reading or writing video needs PyAV: pip install 'physbench[video]' (or pip install "
            "av)"
        ) from None
    return av


def even(frames: np.ndarray) -> np.ndarray:
    """Frames ``(T, H, W, 3)`` padded (edge pixels repeated) to an even height and width, as H.264
    needs."""
    _, h, w, _ = frames.shape
    if h % 2 == 0 and w % 2 == 0:
        return frames
    return np.pad(frames, ((0, 0), (0, h % 2), (0, w % 2), (0, 0)), mode="edge")


def h264_round_trip(frames: np.ndarray, fps: float, bitrate: float, crf: int | None) -> np.ndarray:
    """``frames`` (T, H, W, 3) uint8 encoded with H.264 (yuv420p) at ``bitrate`` (bit/s, > 0) or
    ``crf``, and decoded again in memory; same shape."""
    av = load_av()
    t, h, w, _ = frames.shape
    padded = even(frames)
    enc = av.CodecContext.create("libx264", "w")
    enc.width, enc.height = padded.shape[2], padded.shape[1]
    enc.pix_fmt = "yuv420p"
    enc.thread_count = ENCODER_THREADS
    rate = Fraction(fps).limit_denominator(1001)
    enc.framerate = rate
    enc.time_base = 1 / rate
    if bitrate > 0:
        enc.bit_rate = int(bitrate)
    opts = {"preset": "veryfast", "tune": "zerolatency"}
    if crf is not None:
        opts["crf"] = str(crf)
    enc.options = opts
    dec = av.CodecContext.create("h264", "r")
    got: list[np.ndarray] = []

    def decode(packets: Any) -> None:
        for packet in packets:
            for frame in dec.decode(packet):
                got.append(frame.to_ndarray(format="rgb24"))

    for i in range(t):
        frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(padded[i]), format="rgb24")
        frame.pts = i
        decode(enc.encode(frame))
    decode(enc.encode(None))
    for frame in dec.decode(None):
        got.append(frame.to_ndarray(format="rgb24"))
    if len(got) != t:
        raise CodecError(f"H.264 round trip returned {len(got)} frames for {t}")
    return np.stack(got)[:, :h, :w]
