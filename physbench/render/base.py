"""The Renderer contract: a trajectory becomes frames ``(T, C, H, W)`` float32 in [0, 1].

Every renderer is built with two standard keywords, as Gymnasium builds every environment with its
``render_mode``: ``resolution`` (image width in pixels, square pixels; or ``(H, W)``) and ``mode``,
the channel layout an estimator sees (:data:`MODES`). Anything else a renderer needs (a camera
pose, a background, ...) is its own keyword option, given on the command line with
``--renderer-option KEY=VALUE`` and in a sweep spec as ``renderer = {name = ..., options = {...}}``.

An observation model (camera blur, pixel noise) is not part of a renderer: the framework applies
:class:`ObservationModel` to the observed frames only, whatever renderer made them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: The renderer a run uses unless told otherwise.
DEFAULT_RENDERER = "raster"
#: Channel layouts: ``mark`` (the paper's: channel 0 every body but the focus body, channel 1 the
#: focus body, empty without a focus), ``instance`` (one channel per body, ``scene.bodies`` order),
#: ``mask`` (one channel, every body).
MODES = ("mark", "instance", "mask")


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


class Renderer:
    """Base class of every renderer (plugin contract).

    Subclasses set :attr:`name` (and :attr:`modes` when they support fewer layouts), call
    ``super().__init__(resolution, mode)`` and implement :meth:`render`.
    """

    #: Registered name (unique among renderers).
    name: ClassVar[str] = ""
    #: The channel layouts (:data:`MODES`) this renderer can produce. Estimators that correct one
    #: marked object at a time need ``mark``.
    modes: ClassVar[tuple[str, ...]] = MODES

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


def _nonneg(name: str, value: object) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not math.isfinite(value)
        or value < 0
    ):
        raise RenderError(f"{name} = {value!r}: expected a finite number >= 0")
    return float(value)


@dataclass(frozen=True)
class ObservationModel:
    """How a camera degrades what a renderer draws: Gaussian blur of ``blur`` pixels, then
    Gaussian pixel noise of standard deviation ``noise`` (drawn from ``seed`` afresh for every
    call, so an observation is a pure function of its inputs), clipped to [0, 1]. Applied to
    observed frames only; the model's frames stay sharp."""

    blur: float = 0.0
    noise: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "blur", _nonneg("blur", self.blur))
        object.__setattr__(self, "noise", _nonneg("noise", self.noise))
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer):
            raise RenderError(f"seed = {self.seed!r}: expected a whole number")

    @property
    def identity(self) -> bool:
        return self.blur == 0 and self.noise == 0

    def apply(self, frames: np.ndarray) -> np.ndarray:
        """Called on every observed view: ``frames`` degraded (in place when float32)."""
        if self.identity:
            return frames
        from physbench.render.observe import add_noise, gaussian_blur

        out = np.asarray(frames, dtype=np.float32)
        if self.blur > 0:
            out[...] = gaussian_blur(out, self.blur)
        if self.noise > 0:
            out[...] = add_noise(out, self.noise, np.random.default_rng(int(self.seed)))
        return out

    def to_dict(self) -> dict[str, Any]:
        return {"blur": self.blur, "noise": self.noise, "seed": int(self.seed)}
