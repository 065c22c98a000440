"""Writing video files with real lossy encoding (H.264 through PyAV's FFmpeg), with each frame's
time kept as its container timestamp: frames (:func:`write_video`), or a camera filming a
trajectory (:func:`write_clip`)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.codec import ENCODER_THREADS, X264_PARAMS, even, load_av
from physbench.video.reader import VideoError
from physbench.video.transfer import CODES, check_transfer

if TYPE_CHECKING:
    from physbench.render.base import Camera
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

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
    transfer: str | None = None,
) -> Path:
    """Encode ``frames`` (each ``(H, W, 3)`` uint8 RGB, H and W even for H.264) into ``path``.

    ``fps`` is the nominal rate; ``times`` (s, increasing), when given, become the frames'
    timestamps, so a variable frame rate or dropped frames are recorded as such. ``bitrate``
    (bits/s) or ``crf`` (H.264 quality, 0-51) sets the compression. ``transfer``: the transfer
    function the frames are in (:mod:`~physbench.video.transfer`), tagged in the stream (``None``:
    untagged). Returns the path.
    """
    av = load_av()
    code = None if transfer is None else CODES[check_transfer(transfer, auto=False)]
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
        stream.codec_context.thread_count = ENCODER_THREADS  # the same file on any machine
        if bitrate is not None:
            stream.bit_rate = int(bitrate)
        options = {"x264-params": X264_PARAMS} if codec == "libx264" else {}
        if crf is not None:
            options["crf"] = str(int(crf))
        stream.options = options
        if code is not None:
            stream.codec_context.color_trc = code
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


#: H.264 quality of a clip written with neither a bitrate nor a CRF.
WRITE_CRF = 20
#: Container suffix -> codec; others get H.264.
VIDEO_CODECS = {".webm": "libvpx-vp9"}


def write_clip(camera: Camera, path: str | Path, scene: Scene, traj: Trajectory) -> Path:
    """Film ``traj`` with ``camera`` and encode the clip to ``path``, each frame at its trajectory
    time: H.264 (VP9 for ``.webm``) at the camera's ``bitrate`` or ``crf``, else CRF
    :data:`WRITE_CRF`, tagged with the camera's transfer function; ``.gif`` is an animated GIF
    (256 colours, times rounded to 10 ms, untagged). Returns the path."""
    frames = camera.exposure(scene, traj)
    times = np.asarray(traj.times, dtype=float)
    path = Path(path)
    if path.suffix.lower() == ".gif":
        _write_gif(path, frames, times, scene.dt)
        return path
    crf = camera.crf if camera.crf is not None or camera.bitrate > 0 else WRITE_CRF
    return write_video(
        path,
        even(frames),
        fps=scene.fps,
        times=times,
        codec=VIDEO_CODECS.get(path.suffix.lower(), "libx264"),
        bitrate=int(camera.bitrate) if camera.bitrate > 0 else None,
        crf=crf,
        transfer=getattr(camera, "transfer", None),
    )


def _write_gif(path: Path, frames: np.ndarray, times: np.ndarray, dt: float) -> None:
    from PIL import Image

    ends = np.append(times[1:], times[-1] + (times[-1] - times[-2] if len(times) > 1 else dt))
    ms = [max(10, round(d * 100) * 10) for d in ends - times]
    images = [Image.fromarray(f) for f in frames]
    images[0].save(path, save_all=True, append_images=images[1:], duration=ms, loop=0)
