"""Reading a camera's video: frames streamed one at a time with their times from the container.

Video files (mp4, mov, avi, mkv, webm, gif, ...) are decoded by PyAV, which ships FFmpeg inside
its wheel (``pip install physbench[video]``). A frame's time is its presentation timestamp in the
container (``pts * time_base``, relative to the first frame), not ``index / rate``: phones record
at a variable frame rate and drop frames, and the timestamps say so. A folder of images (png, jpg,
bmp, tif) is a video too, in file-name order, at the frame rate the caller gives.

Frames are yielded one by one (:meth:`VideoReader.frames`), so a long 1080p video never sits in
memory whole; ``start`` and ``end`` (seconds) trim it.

Frames come upright, as a player shows them: a phone holds a portrait video as landscape frames
with a display rotation beside them, which is applied here (quarter turns; FFmpeg's own command
line and OpenCV do the same), so that pixel coordinates, calibrations and scenes made by looking
at the video agree with what is tracked.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from physbench.codec import IMAGE_SUFFIXES, load_av
from physbench.errors import PhysbenchError
from physbench.video.transfer import from_tag, hdr_from_tag

#: Suffixes taken for video files where a command also accepts other inputs (any container FFmpeg
#: reads opens in :class:`VideoReader`; these are the ones a command recognises by name).
VIDEO_SUFFIXES = (".mp4", ".m4v", ".mov", ".avi", ".mkv", ".webm", ".gif", ".mpg", ".mpeg")


def is_video(path: str | Path) -> bool:
    """Whether a command should read ``path`` as a video: a video suffix or a folder."""
    p = Path(path)
    return p.is_dir() or p.suffix.lower() in VIDEO_SUFFIXES


class VideoError(PhysbenchError, ValueError):
    """A video that cannot be read: names the file and what is wrong with it."""


@dataclass(frozen=True)
class Frame:
    """One decoded frame: its index in the (trimmed) video, its time in seconds from the first
    frame of the file, and the image ``(H, W, 3)`` uint8 RGB."""

    index: int
    time: float
    image: np.ndarray


@dataclass(frozen=True)
class VideoInfo:
    """What the container says: size, the average frame rate, the frame count and duration when
    it knows them (``None`` otherwise), the codec, and the transfer function the stream is tagged
    with (:mod:`~physbench.video.transfer`; ``None``: untagged, or a folder of images) or, for
    HDR video, the HDR curve it is tagged with (``hdr``: ``"PQ"`` or ``"HLG"``), and whether it
    is ``interlaced`` (each frame two fields filmed half a frame apart), and whether its colour is
    ``subsampled`` (stored at a lower resolution than brightness: 4:2:0, 4:2:2)."""

    width: int
    height: int
    rate: float
    frames: int | None
    duration: float | None
    codec: str
    transfer: str | None = None
    hdr: str | None = None
    interlaced: bool = False
    subsampled: bool = False


def _subsampled(fmt: Any, width: int, height: int) -> bool:
    """Whether the pixel format ``fmt`` (an ``av.VideoFormat`` or ``None``) stores colour at a
    lower resolution than brightness."""
    if fmt is None or fmt.is_rgb or not width or not height:
        return False
    return fmt.chroma_width(width) < width or fmt.chroma_height(height) < height


def _positive(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise VideoError(f"{name} = {value!r}: expected a frame rate > 0 (frames/s)")
    if not math.isfinite(value):
        raise VideoError(f"{name} = {value!r}: expected a finite frame rate")
    return float(value)


def _number(name: str, value: float | None, *, low: float = 0.0) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise VideoError(f"{name} = {value!r}: expected a finite number of seconds")
    if value < low:
        raise VideoError(f"{name} = {value!r}: expected a number >= {low:g}")
    return float(value)


class VideoReader:
    """A video file or a folder of images, opened lazily: :meth:`info` reads the header, and
    :meth:`frames` decodes as it is iterated. ``fps`` is needed for a folder of images (and
    ignored for a file, whose timestamps rule); ``start``/``end`` trim to ``[start, end]`` s of
    the file (as a player counts them). ``capture_fps``: the rate a slow-motion file was filmed
    at, where it plays back slower (a phone's 240 fps stored to play at 30): its frames' times
    are the file's scaled by its average rate over ``capture_fps``, so that they are the real
    seconds between the frames (ignored for a folder of images, whose ``fps`` is the rate)."""

    def __init__(
        self,
        path: str | Path,
        *,
        start: float | None = None,
        end: float | None = None,
        fps: float | None = None,
        capture_fps: float | None = None,
    ) -> None:
        self.path = Path(path)
        self.start = _number("start", start) or 0.0
        self.end = _number("end", end)
        self.capture_fps = _positive("capture_fps", capture_fps)
        if self.end is not None and self.end <= self.start:
            raise VideoError(f"end = {end!r}: must come after start = {self.start:g} s")
        if not self.path.exists():
            raise VideoError(f"video {str(self.path)!r} does not exist")
        self.images: list[Path] = []
        self._pts: list[int] | None = None  # the packets' timestamps, once read
        self._pts_read = False
        if self.path.is_dir():
            self.images = sorted(
                p for p in self.path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES
            )
            if not self.images:
                raise VideoError(
                    f"folder {str(self.path)!r} holds no images ({', '.join(IMAGE_SUFFIXES)})"
                )
            rate = _number("fps", fps)
            if not rate:
                raise VideoError(
                    f"folder {str(self.path)!r} is a sequence of images: give its frame rate "
                    "(fps > 0)"
                )
            self.fps: float | None = rate
        else:
            self.fps = None

    def __repr__(self) -> str:
        return f"VideoReader({str(self.path)!r}, start={self.start:g}, end={self.end})"

    # ----------------------------------------------------------------- header

    def info(self) -> VideoInfo:
        """Size (upright, as shown), rate, frame count and duration, from the header (and the
        first frame's display rotation)."""
        if self.images:
            h, w = self._image(self.images[0]).shape[:2]
            n, rate = len(self.images), float(self.fps or 0.0)
            return VideoInfo(w, h, rate, n, n / rate, "images")
        with self._open() as container:
            stream = self._stream(container)
            rotation, interlaced = _first_frame(container, stream)
            turns = _quarter_turns(self.path, rotation)
            rate = float(stream.average_rate or stream.guessed_rate or 0.0)
            frames = int(stream.frames) or None
            duration = None
            if stream.duration is not None and stream.time_base is not None:
                duration = float(stream.duration * stream.time_base)
            elif container.duration is not None:
                duration = container.duration / 1_000_000  # microseconds
            w, h = stream.codec_context.width, stream.codec_context.height
            trc = getattr(stream.codec_context, "color_trc", None)
            return VideoInfo(
                h if turns % 2 else w,
                w if turns % 2 else h,
                rate,
                frames,
                duration,
                stream.codec_context.name,
                from_tag(trc),
                hdr_from_tag(trc),
                interlaced,
                _subsampled(stream.codec_context.format, w, h),
            )

    # ----------------------------------------------------------------- frames

    def frames(
        self, select: Callable[[int], bool] | None = None, *, sparse: bool = False
    ) -> Iterator[Frame]:
        """The frames inside ``[start, end]``, decoded one at a time, with their times (s from the
        first frame of the file; real seconds where ``capture_fps`` rescales a slow-motion
        file). ``select(index)``: yield only the frames it accepts (the others are still decoded,
        as a video's later frames need them, but not converted to images). ``sparse``: for a
        caller that keeps few frames, the refused frames that no other frame is decoded from
        (H.264's and HEVC's non-reference frames) are not decoded at all. ``select`` is then also
        asked before a frame is decoded, possibly ahead of earlier frames, and may only narrow
        its answer later; a file whose frames cannot be told apart by their timestamps before
        decoding raises :class:`SparseError` instead (read it again without ``sparse``). Raises
        :class:`VideoError` for a file that cannot be decoded, and when no frame lies inside the
        trim."""
        count = 0

        def chosen(k: int) -> bool:
            nonlocal count
            count += 1
            return select is None or select(k)

        yield from self._images(chosen) if self.images else self._decode(chosen, select, sparse)
        if count == 0:
            span = f" between {self.start:g} and {self.end:g} s" if self.end else ""
            after = f" after {self.start:g} s" if self.start and not self.end else ""
            raise VideoError(f"video {str(self.path)!r} has no frames{span}{after}")

    def _images(self, select: Callable[[int], bool]) -> Iterator[Frame]:
        assert self.fps is not None
        k = 0
        for i, p in enumerate(self.images):
            t = i / self.fps
            if t < self.start - 1e-9:
                continue
            if self.end is not None and t > self.end + 1e-9:
                break
            if select(k):
                yield Frame(k, t, self._image(p))
            k += 1

    def _image(self, p: Path) -> np.ndarray:
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(p) as im:
                return np.asarray(im.convert("RGB"))
        except (OSError, UnidentifiedImageError) as exc:
            raise VideoError(f"image {str(p)!r} cannot be read: {exc}") from None

    def _open(self) -> Any:
        av = load_av()
        try:
            return av.open(str(self.path))
        except av.error.FFmpegError as exc:
            raise VideoError(
                f"{str(self.path)!r} is not a video FFmpeg can read ({exc.strerror or exc})"
            ) from None

    def _stream(self, container: Any) -> Any:
        if not container.streams.video:
            raise VideoError(f"{str(self.path)!r} has no video stream")
        stream = container.streams.video[0]
        if stream.codec_context is None or not stream.codec_context.name:
            raise VideoError(f"{str(self.path)!r}: its video codec is not supported")
        return stream

    def _time_scale(self, stream: Any) -> float:
        """Real seconds per second of the file: its average rate over ``capture_fps`` (1 without
        one)."""
        if self.capture_fps is None:
            return 1.0
        rate = float(stream.average_rate or stream.guessed_rate or 0.0)
        if not rate > 0:
            raise VideoError(
                f"{str(self.path)!r} states no frame rate, so capture_fps = {self.capture_fps:g} "
                "cannot rescale its times; convert it to images and give their rate"
            )
        return rate / self.capture_fps

    def _decode(
        self,
        select: Callable[[int], bool],
        ask: Callable[[int], bool] | None = None,
        sparse: bool = False,
    ) -> Iterator[Frame]:
        av = load_av()
        with self._open() as container:
            stream = self._stream(container)
            stream.thread_type = "AUTO"
            scale = self._time_scale(stream)
            order = self._display_order(stream) if sparse else None
            # One conversion context for the clip: a frame's own is made anew for each frame
            # (0.3 ms a 640x480 frame against 0.15).
            rgb = av.video.reformatter.VideoReformatter()
            t0: float | None = None
            k, last = 0, -math.inf
            try:
                for frame in self._decoded(container, stream, order, ask):
                    if frame.pts is None or frame.time_base is None:
                        raise VideoError(
                            f"{str(self.path)!r}: frame {k} carries no timestamp; physbench reads "
                            "times from the container, not from an assumed rate"
                        )
                    t_abs = float(frame.pts * frame.time_base)
                    t0 = t_abs if t0 is None else t0
                    t = t_abs - t0
                    if order is not None:  # the frame's place from its timestamp
                        place = order.index.get(frame.pts)
                        first = (t0 == t_abs) == (frame.pts == order.first)
                        if place is None or place <= last or not first:
                            raise SparseError(f"{str(self.path)!r}: the frames' order is not known")
                        k = last = place
                    if t < self.start - 1e-9:
                        continue
                    if self.end is not None and t > self.end + 1e-9:
                        break
                    if select(k):
                        image = rgb.reformat(frame, format="rgb24").to_ndarray()
                        yield Frame(k, t * scale, _upright(image, frame, self.path))
                    k += 1
            except av.error.FFmpegError as exc:
                raise VideoError(
                    f"{str(self.path)!r} is damaged after {k} frames ({exc.strerror or exc})"
                ) from None

    def count(self) -> int | None:
        """The number of frames inside ``[start, end]``, from the container's timestamps (a pass
        that reads the file but decodes nothing); ``None`` where a timestamp is missing or
        repeated. Called by a median background, to choose the frames it keeps up front."""
        if self.images:
            assert self.fps is not None
            seconds = [i / self.fps for i in range(len(self.images))]
        else:
            with self._open() as container:
                stream = self._stream(container)
                pts = self._packet_times(container, stream)
                if pts is None:
                    return None
                seconds = [float((q - pts[0]) * stream.time_base) for q in pts]
        end = math.inf if self.end is None else self.end + 1e-9
        return sum(self.start - 1e-9 <= t <= end for t in seconds)

    def _packet_times(self, container: Any, stream: Any) -> list[int] | None:
        """The timestamps of the stream's packets, sorted (display order), read once per reader;
        ``None`` where one is missing or repeated."""
        if not self._pts_read:
            pts = [p.pts for p in container.demux(stream) if p.size]
            unusable = not pts or None in pts or len(set(pts)) != len(pts)
            self._pts, self._pts_read = (None if unusable else sorted(pts)), True
        return self._pts

    def _display_order(self, stream: Any) -> _Order | None:
        """The display order of the stream's packets, from their timestamps (a pass that reads
        but does not decode); ``None`` where a codec's skipping is not known to drop only
        non-reference frames, or a packet's timestamp is missing or repeated."""
        if stream.codec_context.name not in ("h264", "hevc"):
            return None
        if not self._pts_read:
            with self._open() as container:
                self._packet_times(container, container.streams.video[0])
        pts = self._pts
        return None if pts is None else _Order(pts, self.start, stream.time_base)

    @staticmethod
    def _decoded(
        container: Any, stream: Any, order: _Order | None, ask: Callable[[int], bool] | None
    ) -> Iterator[Any]:
        """The stream's decoded frames; with ``order``, each packet whose frame ``ask`` refuses
        is decoded only if other frames need it."""
        if order is None or ask is None:
            yield from container.decode(stream)
            return
        context = stream.codec_context
        for packet in container.demux(stream):
            k = order.index.get(packet.pts)
            keep = k is None or packet.pts == order.first or (k >= 0 and ask(k))
            context.skip_frame = "DEFAULT" if keep else "NONREF"
            yield from stream.decode(packet)


class SparseError(VideoError):
    """A video read with ``sparse`` whose frames' order could not be known before decoding."""


class _Order:
    """The display order of a stream's frames, from its packets' timestamps ``pts`` (sorted):
    ``index[pts]`` is a frame's index in the trim starting ``start`` s after the first frame
    (negative before it), ``first`` the first frame's timestamp."""

    def __init__(self, pts: list[int], start: float, time_base: Any) -> None:
        self.first = pts[0]
        seconds = [float((q - self.first) * time_base) for q in pts]
        before = sum(t < start - 1e-9 for t in seconds)
        self.index = {q: i - before for i, q in enumerate(pts)}


def _quarter_turns(path: Path, degrees: float) -> int:
    """Counter-clockwise quarter turns of a display rotation of ``degrees``; refused unless a
    multiple of 90."""
    turns = round(degrees / 90.0)
    if abs(degrees - 90.0 * turns) > 0.5:
        raise VideoError(
            f"{str(path)!r} is to be shown turned by {degrees:g} degrees, which physbench cannot "
            "apply (quarter turns only): rotate it upright first (ffmpeg -i IN OUT does)"
        )
    return turns % 4


def _upright(image: np.ndarray, frame: Any, path: Path) -> np.ndarray:
    """``image``, decoded ``frame`` in RGB, turned as the frame's display rotation says."""
    turns = _quarter_turns(path, float(getattr(frame, "rotation", 0) or 0))
    return np.ascontiguousarray(np.rot90(image, turns)) if turns else image


#: FFmpeg's field orders of interlaced video (``AVFieldOrder``: top or bottom field first,
#: coded and shown either way); 0 is unknown and 1 progressive.
INTERLACED_ORDERS = (2, 3, 4, 5)


def _first_frame(container: Any, stream: Any) -> tuple[float, bool]:
    """The display rotation of the stream's first frame (degrees counter-clockwise) and whether
    it is interlaced (flagged so, or the stream's field order says so); ``(0, False)`` as far as
    the file cannot be decoded here (:meth:`VideoReader.frames` says why)."""
    av = load_av()
    order = getattr(stream.codec_context, "field_order", 0)
    try:
        for frame in container.decode(stream):
            rotation = float(getattr(frame, "rotation", 0) or 0)
            flagged = bool(getattr(frame, "interlaced_frame", False))
            return rotation, flagged or order in INTERLACED_ORDERS
    except av.error.FFmpegError:
        pass
    return 0.0, order in INTERLACED_ORDERS
