"""The Renderer contract: a trajectory becomes frames ``(T, C, H, W)`` float32 in [0, 1].

Every renderer is built with two standard keywords, as Gymnasium builds every environment with its
``render_mode``: ``resolution`` (image width in pixels, square pixels; or ``(H, W)``) and ``mode``,
the channel layout an estimator sees (:data:`MODES`). Anything else a renderer needs (a camera
pose, a background, ...) is its own keyword option, given on the command line with
``--renderer-option KEY=VALUE`` and in a sweep spec as ``renderer = {name = ..., options = {...}}``.

An observation model (camera blur, pixel noise) is not part of a renderer: the framework applies
:class:`~physbench.render.sensor.SensorModel` to the observed frames only, whatever renderer
made them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from physbench.errors import PhysbenchError
from physbench.requirements import Requirements

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: The renderer a run uses unless told otherwise.
DEFAULT_RENDERER = "raster"
#: Channel layouts: ``mark`` (the paper's: channel 0 every body but the focus body, channel 1 the
#: focus body, empty without a focus), ``instance`` (one channel per body, ``scene.bodies`` order),
#: ``mask`` (one channel, every body), ``rgb`` (the three colour channels of a camera image, values
#: in [0, 1]; no body is marked, a focus changes nothing).
MODES = ("mark", "instance", "mask", "rgb")


class RenderError(PhysbenchError, ValueError):
    """Bad renderer options or inputs that do not fit the scene."""


def check_resolution(resolution: object) -> int | tuple[int, int]:
    """``resolution`` as a whole number >= 1 or an ``(H, W)`` pair, else :class:`RenderError`."""

    def ok(v: object) -> bool:
        return isinstance(v, int | np.integer) and not isinstance(v, bool) and v >= 1

    if ok(resolution):
        return int(resolution)  # type: ignore[arg-type]
    if isinstance(resolution, tuple | list) and len(resolution) == 2 and all(map(ok, resolution)):
        return (int(resolution[0]), int(resolution[1]))
    raise RenderError(
        f"resolution = {resolution!r}: expected a whole number >= 1 (image width, square pixels) "
        "or a pair (height, width) of whole numbers >= 1"
    )


def check_view(view: object) -> tuple[float, float, float, float]:
    """A camera's ``view`` option as ``(xmin, ymin, xmax, ymax)`` in metres with ``xmin < xmax``
    and ``ymin < ymax``, else :class:`RenderError`."""
    try:
        vals = tuple(float(v) for v in view)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        vals = ()
    if (
        len(vals) != 4
        or not all(map(math.isfinite, vals))
        or not (vals[0] < vals[2] and vals[1] < vals[3])
    ):
        raise RenderError(
            f"view = {view!r}: expected [xmin, ymin, xmax, ymax] in metres with xmin < xmax and "
            "ymin < ymax"
        )
    return vals  # type: ignore[return-value]


class Renderer(Requirements):
    """Base class of every renderer (plugin contract).

    Subclasses set :attr:`name` and :attr:`modes` (the layouts they can produce), call
    ``super().__init__(resolution, mode)`` and implement :meth:`render`.
    """

    #: Registered name (unique among renderers).
    name: ClassVar[str] = ""
    #: The channel layouts (:data:`MODES`) this renderer can produce; by default the three
    #: segmentation layouts (a camera-like renderer declares ``("rgb",)``). Estimators that
    #: correct one marked object at a time need ``mark``.
    modes: ClassVar[tuple[str, ...]] = ("mark", "instance", "mask")

    def __init__(self, resolution: int | tuple[int, int] = 64, mode: str = "mark") -> None:
        self.resolution = check_resolution(resolution)
        if mode not in self.modes:
            raise RenderError(
                f"mode = {mode!r}: renderer {self.name!r} supports modes {', '.join(self.modes)}"
            )
        self.mode = mode

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Called after every simulation (and once per observed view): frames ``(T, C, H, W)``
        float32 in [0, 1], one per trajectory frame. ``focus`` names the body to mark (``mark``
        mode); ``out``, when given, is a float32 buffer of :meth:`shape` to render into and
        return."""
        raise NotImplementedError(f"{type(self).__name__} must implement render()")

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        """``(T, C, H, W)`` of a render of ``frames`` frames (default ``scene.frames``); called
        before a run to check an observation and preallocate buffers. Default: renders a one-frame
        still of the scene's initial poses (no simulation needed); override when it is cheaper to
        compute."""
        from physbench.trajectory import Trajectory

        states = np.zeros((1, len(scene.bodies), 6))
        for i, b in enumerate(scene.bodies):
            states[0, i, :3] = (*b.position, b.angle)
        frame = self.render(scene, Trajectory(scene.body_names, np.zeros(1), states))
        return (scene.frames if frames is None else frames, *frame.shape[1:])  # type: ignore[return-value]


class Camera(Renderer):
    """Base class of renderers that film the scene as a real camera would (plugin contract of
    observer cameras, ``run --observer``, and of ``simulate --out clip.mp4``): 8-bit ``rgb``
    footage, the empty scene's plate, and the camera's own true calibration. The video package
    encodes the footage (:func:`physbench.video.writer.write_clip`) and tracks it.

    Subclasses implement :meth:`exposure`, :meth:`plate` and :meth:`calibration`; :meth:`film`,
    :meth:`image_points` and :meth:`render` have defaults built on them.
    """

    modes: ClassVar[tuple[str, ...]] = ("rgb",)
    #: Encoding of the footage: bit rate in bits/s (0: none) or H.264 quality ``crf`` (0-51,
    #: ``None``: none). Set by the subclass from its options; the writer reads them.
    bitrate: float = 0.0
    crf: int | None = None
    #: The transfer function of the footage's pixel values (a name of
    #: :data:`physbench.video.transfer.TRANSFERS`), which the writer tags the video with so that
    #: the tracker decodes it to linear light. Default: linear (pixels proportional to light).
    transfer: str = "linear"

    def exposure(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """Called to film ``traj``: the frames the sensor records, before any encoding, ``(T, H,
        W, 3)`` uint8."""
        raise NotImplementedError(f"{type(self).__name__} must implement exposure()")

    def plate(self, scene: Scene) -> np.ndarray:
        """Called before tracking the camera's footage: the empty scene (background and static
        geometry) as this camera films it, ``(H, W, 3)`` uint8."""
        raise NotImplementedError(f"{type(self).__name__} must implement plate()")

    def calibration(self, scene: Scene) -> Calibration:
        """Called before tracking the camera's footage: the true map from this camera's pixels to
        ``scene``'s metres."""
        raise NotImplementedError(f"{type(self).__name__} must implement calibration()")

    def film(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """The frames as a video file would hold them, ``(T, H, W, 3)`` uint8. Default:
        :meth:`exposure` (no codec)."""
        return self.exposure(scene, traj)

    def image_points(self, scene: Scene, xy: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        """Where scene points ``(N, 2)`` (metres) land in the image (pixels). Default: through
        :meth:`calibration`."""
        return np.asarray(self.calibration(scene).to_image(np.asarray(xy, dtype=float)))

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Called after every simulation: :meth:`film` as ``(T, 3, H, W)`` float32 in [0, 1]
        (``focus`` is ignored: a camera marks no body)."""
        frames = self.film(scene, traj)
        shape = (frames.shape[0], 3, frames.shape[1], frames.shape[2])
        if out is not None and (out.shape != shape or out.dtype != np.float32):
            raise RenderError(
                f"out has shape {out.shape} and dtype {out.dtype}; expected {shape} float32"
            )
        if out is None:
            out = np.empty(shape, np.float32)
        np.divide(frames.transpose(0, 3, 1, 2), np.float32(255), out=out)
        return out
