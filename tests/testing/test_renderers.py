"""The renderer kit passes correct renderers and catches deliberately broken ones."""

from __future__ import annotations

import re
from typing import Any, ClassVar

import numpy as np
import pytest

from physbench.render.base import Renderer, RenderError
from physbench.scene import Scene
from physbench.testing import (
    Check,
    ConformanceError,
    Subject,
    ToyRenderer,
    check_renderer,
    checks_for,
    parametrize_with_checks,
)
from physbench.testing.renderers import (
    check_bad_options,
    check_channel_layout,
    check_deterministic,
    check_follows_trajectory,
    check_frames,
    check_marking,
    check_out,
    check_protocol,
    check_shape,
)
from physbench.trajectory import Trajectory


class BlobRenderer(Renderer):
    """A correct renderer in every mode: a Gaussian blob per body, as wide as the body, on an
    image of the world's bounds; bodies sharing a channel combine with max."""

    name: ClassVar[str] = "blobs"

    def __init__(self, resolution: int | tuple[int, int] = 32, mode: str = "mark") -> None:
        super().__init__(resolution, mode)
        r = self.resolution
        self.hw = r if isinstance(r, tuple) else (r, r)

    def channels(self, scene: Scene) -> int:
        return {"mark": 2, "instance": len(scene.bodies), "mask": 1}[self.mode]

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        return (scene.frames if frames is None else frames, self.channels(scene), *self.hw)

    def channel(self, scene: Scene, i: int, focus: str | None) -> int:
        if self.mode == "mark":
            return int(scene.bodies[i].name == focus)
        return i if self.mode == "instance" else 0

    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        xmin, ymin, xmax, ymax = scene.bounds
        h, w = self.hw
        gx = xmin + (np.arange(w) + 0.5) / w * (xmax - xmin)
        gy = ymax - (np.arange(h) + 0.5) / h * (ymax - ymin)
        frames = np.zeros((traj.frames, self.channels(scene), h, w), np.float32)
        for i, body in enumerate(scene.bodies):
            x, y = traj.states[:, i, 0, None, None], traj.states[:, i, 1, None, None]
            d2 = (gx[None, None, :] - x) ** 2 + (gy[None, :, None] - y) ** 2
            blob = np.exp(-d2 / (2 * (body.shape.extent() / 2) ** 2)).astype(np.float32)
            ch = self.channel(scene, i, focus)
            np.maximum(frames[:, ch], blob, out=frames[:, ch])
        return frames

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        frames = self.draw(scene, traj, focus)
        if out is None:
            return frames
        out[...] = frames
        return out


class InitialPoseOnly(BlobRenderer):
    """Draws every frame at the trajectory's first pose: a still picture of frame 0."""

    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        still = np.repeat(traj.states[:1], traj.frames, axis=0)
        return super().draw(scene, Trajectory(traj.bodies, traj.times, still), focus)


class UpsideDown(BlobRenderer):
    """Puts the world's y = ymin in the top row: a picture flipped upside down."""

    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        return np.ascontiguousarray(super().draw(scene, traj, focus)[:, :, ::-1])


class WrongShape(BlobRenderer):
    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        t, c, h, w = super().shape(scene, frames)
        return (t, c + 1, h, w)


class Float64(BlobRenderer):
    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        return super().draw(scene, traj, focus).astype(np.float64)


class Overexposed(BlobRenderer):
    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        return super().draw(scene, traj, focus) * np.float32(2.0)


class Noisy(BlobRenderer):
    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        frames = super().draw(scene, traj, focus)
        frames *= np.random.default_rng().uniform(0.99, 1.0, frames.shape).astype(np.float32)
        return frames


class CachesByFrameCount(BlobRenderer):
    """Reuses the frames of the last render of as many frames, whatever the scene."""

    def __init__(self, **kw: Any) -> None:
        super().__init__(**kw)
        self.cache: dict[tuple[int, str | None], np.ndarray] = {}

    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        key = (traj.frames, focus)
        if key not in self.cache or self.cache[key].shape[1] != self.channels(scene):
            self.cache[key] = super().draw(scene, traj, focus)
        return self.cache[key].copy()


class IgnoresOut(BlobRenderer):
    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        return self.draw(scene, traj, focus)


class KeepsStalePixels(BlobRenderer):
    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        if out is None:
            return self.draw(scene, traj, focus)
        np.copyto(out, self.draw(scene, traj, focus), where=self.draw(scene, traj, focus) > 0.5)
        return out


class MarksIntoBothChannels(BlobRenderer):
    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        frames = super().draw(scene, traj, focus)
        if self.mode == "mark":
            np.maximum(frames[:, 0], frames[:, 1], out=frames[:, 0])
        return frames


class MarksTheFirstBody(BlobRenderer):
    def channel(self, scene: Scene, i: int, focus: str | None) -> int:
        if self.mode == "mark":
            return int(focus is not None and i == 0)
        return super().channel(scene, i, focus)


class MarksWithoutFocus(BlobRenderer):
    def channel(self, scene: Scene, i: int, focus: str | None) -> int:
        if self.mode == "mark" and focus is None:
            return int(i == 0)
        return super().channel(scene, i, focus)


class InstancesReversed(BlobRenderer):
    def channel(self, scene: Scene, i: int, focus: str | None) -> int:
        if self.mode == "instance":
            return len(scene.bodies) - 1 - i
        return super().channel(scene, i, focus)


class MaskShowsOneBody(BlobRenderer):
    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        if self.mode == "mask" and len(scene.bodies) > 1:
            scene = Scene(scene.name, scene.bodies[:1], bounds=scene.bounds, frames=scene.frames)
            traj = Trajectory(traj.bodies[:1], traj.times, traj.states[:, :1])
        return super().draw(scene, traj, focus)


class AcceptsAnyMode(BlobRenderer):
    def __init__(self, resolution: int | tuple[int, int] = 32, mode: str = "mark") -> None:
        super().__init__(resolution, "mark")
        self.mode = mode


class ValueErrorOnBadResolution(BlobRenderer):
    def __init__(self, resolution: int | tuple[int, int] = 32, mode: str = "mark") -> None:
        if not isinstance(resolution, int | tuple) or (
            isinstance(resolution, int) and resolution < 1
        ):
            raise ValueError("bad size")
        super().__init__(resolution, mode)


class SquareOnlyWithoutRenderError(BlobRenderer):
    def __init__(self, resolution: int | tuple[int, int] = 32, mode: str = "mark") -> None:
        super().__init__(resolution, mode)
        self.hw = (int(resolution), int(resolution))  # type: ignore[arg-type]


class UnknownMode(BlobRenderer):
    modes: ClassVar[tuple[str, ...]] = ("mark", "sepia")


class MaskOnly(BlobRenderer):
    modes: ClassVar[tuple[str, ...]] = ("mask",)


class RgbBlobs(BlobRenderer):
    """A correct ``rgb`` renderer: coloured blobs on a grey image; a focus changes nothing."""

    modes: ClassVar[tuple[str, ...]] = ("rgb",)
    colours: ClassVar[dict[str, np.ndarray]] = {
        "disc": np.array([0.9, 0.1, 0.1], np.float32),
        "block": np.array([0.1, 0.2, 0.9], np.float32),
    }

    def channels(self, scene: Scene) -> int:
        return 3

    def draw(self, scene: Scene, traj: Trajectory, focus: str | None) -> np.ndarray:
        mask = BlobRenderer(self.resolution, "instance").draw(scene, traj, None)
        frames = np.full((traj.frames, 3, *self.hw), 0.5, np.float32)
        for i, name in enumerate(scene.body_names):
            colour = self.colour(scene, name, focus)[None, :, None, None]
            frames += mask[:, i : i + 1] * (colour - frames)
        return frames

    def colour(self, scene: Scene, name: str, focus: str | None) -> np.ndarray:
        return self.colours[name]


class RgbHidesBlock(RgbBlobs):
    def colour(self, scene: Scene, name: str, focus: str | None) -> np.ndarray:
        return (
            np.full(3, 0.5, np.float32) if name == "block" else super().colour(scene, name, focus)
        )


class RgbMarksFocus(RgbBlobs):
    def colour(self, scene: Scene, name: str, focus: str | None) -> np.ndarray:
        return np.ones(3, np.float32) if name == focus else super().colour(scene, name, focus)


def failing_checks(cls: type) -> list[str]:
    """The names of the checks ``check_renderer`` reports as failed."""
    try:
        check_renderer(cls)
    except ConformanceError as exc:
        return re.findall(r"^- (check_\w+):", str(exc), flags=re.MULTILINE)
    return []


def test_correct_renderers_pass() -> None:
    check_renderer(BlobRenderer)
    check_renderer(BlobRenderer, resolution=24)
    check_renderer(ToyRenderer)  # mark only, square images (refuses (height, width) clearly)
    check_renderer(MaskOnly)
    check_renderer(RgbBlobs)


@parametrize_with_checks([BlobRenderer, ToyRenderer, MaskOnly, RgbBlobs])
def test_correct_renderers_pass_every_parametrized_check(component: Subject, check: Check) -> None:
    check(component)


def test_checks_follow_the_declared_modes() -> None:
    def names(cls: type) -> list[str]:
        return [c.name for c in checks_for(cls)]

    assert "check_marking" in names(ToyRenderer) and "check_channel_layout" not in names(
        ToyRenderer
    )
    assert "check_marking" not in names(MaskOnly) and "check_channel_layout" in names(MaskOnly)
    assert {"check_marking", "check_channel_layout"} <= set(names(BlobRenderer))


@pytest.mark.parametrize(
    ("broken", "check", "message", "also"),
    [
        (
            WrongShape,
            check_shape,
            r"mode 'mark': shape\(scene, frames=None\) says \(6, 3, 32, 32\), render\(\) of 6 "
            r"frames returned \(6, 2, 32, 32\)",
            ("check_out",),  # the buffer it asks for has the wrong shape too
        ),
        (Float64, check_frames, "mode 'mark': frames are float64, expected float32", ()),
        (Overexposed, check_frames, r"values span \[0, 1.97\d*\], expected \[0, 1\]", ()),
        (
            Noisy,
            check_deterministic,
            "rendering the probe scene again changes the frames",
            ("check_out",),
        ),
        (
            CachesByFrameCount,
            check_deterministic,
            "rendering the probe scene after rendering another scene changes the frames",
            # lone renders and the moving disc's poses come from the cache too
            ("check_marking", "check_channel_layout", "check_follows_trajectory"),
        ),
        (IgnoresOut, check_out, r"render\(out=buffer\) returned a new array", ()),
        (KeepsStalePixels, check_out, "differ from a plain render", ()),
        (
            MarksIntoBothChannels,
            check_marking,
            "with focus='disc' channel 0 must show 'block' and not the focus body",
            (),
        ),
        (
            MarksTheFirstBody,
            check_marking,
            "with focus='block' channel 1 does not show 'block'",
            (),
        ),
        (MarksWithoutFocus, check_marking, "without a focus, channel 1 must be empty", ()),
        (
            InstancesReversed,
            check_channel_layout,
            "instance mode: channel 0 does not show body 'disc' alone",
            (),
        ),
        (
            MaskShowsOneBody,
            check_channel_layout,
            "mask mode: channel 0 does not show every body",
            (),
        ),
        (
            AcceptsAnyMode,
            check_bad_options,
            r"\(\*\*\{'resolution': 32, 'mode': 'sepia'\}\) was accepted",
            (),
        ),
        (
            ValueErrorOnBadResolution,
            check_bad_options,
            r"raised ValueError: bad size; raise physbench.render.base.RenderError",
            (),
        ),
        (
            SquareOnlyWithoutRenderError,
            check_shape,
            r"resolution=\(20, 28\) raised TypeError: .*raise physbench.render.base.RenderError",
            (),
        ),
        (
            InitialPoseOnly,
            check_follows_trajectory,
            r"mode 'mark': the last frame of a disc moving from \(1.0, 1.5\) to \(1.6, 2.1\) m "
            r"is no nearer the disc resting at \(1.6, 2.1\) \(mean difference 0.0\d+\) than at "
            r"\(1.0, 1.5\) \(0\); each frame must show the trajectory's pose",
            (),
        ),
        (
            UpsideDown,
            check_follows_trajectory,
            r"mode 'mark': a disc moved right and up from \(1.0, 1.5\) to \(1.6, 2.1\) m, but its "
            r"picture moved \+\d\.\d columns and \+\d\.\d rows; columns must grow with x and rows "
            "shrink with y",
            (),
        ),
        (RgbHidesBlock, check_frames, "mode 'rgb': body 'block' does not show", ()),
        (
            RgbMarksFocus,
            check_frames,
            "mode 'rgb': focus='disc' changes the frames .* an rgb image marks no body",
            (),
        ),
        (
            UnknownMode,
            check_protocol,
            r"'modes' must be a non-empty tuple of mark, instance, mask, rgb",
            (),
        ),
    ],
)
def test_a_broken_renderer_fails_only_its_check_with_a_clear_message(
    broken: type, check: Any, message: str, also: tuple[str, ...]
) -> None:
    with pytest.raises(ConformanceError, match=message):
        check(broken)
    if check is check_protocol:
        assert failing_checks(broken) == ["check_protocol"]  # the kit stops there
    else:
        assert set(failing_checks(broken)) == {check.__name__, *also}


def test_refusals_must_name_the_value() -> None:
    class Vague(BlobRenderer):
        def __init__(self, resolution: int | tuple[int, int] = 32, mode: str = "mark") -> None:
            try:
                super().__init__(resolution, mode)
            except RenderError:
                raise RenderError("bad renderer option") from None

    with pytest.raises(ConformanceError, match="raised RenderError without naming 0"):
        check_bad_options(Vague)
