"""The renderer kit: checks of a :class:`~physbench.render.base.Renderer` in every mode it
declares, on a hand-made trajectory (no simulation) of a disc and a box well apart, so each check
takes milliseconds.

Layouts are compared geometry-free: a body "appears in" a channel when that channel matches, within
0.05 per pixel, the render of a scene holding that body alone. The kit builds renderers with
``resolution`` 32 unless the options give one.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from physbench.render.base import MODES, Renderer, RenderError
from physbench.scene import Body, Box, Circle, Scene
from physbench.testing.kit import (
    Check,
    ConformanceError,
    Subject,
    construct,
    label,
    require_contract,
    run_checks,
)
from physbench.trajectory import Trajectory

#: Image width the kit asks for when the options give none.
RESOLUTION = 32
#: Largest per-pixel difference between a channel and the lone body's render it should match.
LAYOUT_TOL = 0.05


# --------------------------------------------------------------------------- probe scene


def probe_scene() -> Scene:
    """A disc and a tilted box 2 m apart in a 4 m x 3 m world, 6 frames."""
    bodies = (
        Body("disc", Circle(0.35), (1.0, 1.5)),
        Body("block", Box(0.6, 0.5), (3.0, 1.5), angle=0.3),
    )
    return Scene("kit_render", bodies, bounds=(0.0, 0.0, 4.0, 3.0), frames=6).validate()


def probe_trajectory(scene: Scene, frames: int | None = None) -> Trajectory:
    """The disc drifts right and up while the box turns; any body subset of :func:`probe_scene`."""
    n = scene.frames if frames is None else frames
    t = np.arange(n) / scene.fps
    states = np.zeros((n, len(scene.bodies), 6))
    for i, b in enumerate(scene.bodies):
        vx, vy, w = (1.5, 0.6, 0.0) if b.name == "disc" else (0.0, 0.0, 2.0)
        states[:, i] = np.stack(
            [
                b.position[0] + vx * t,
                b.position[1] + vy * t,
                b.angle + w * t,
                vx + 0 * t,
                vy + 0 * t,
                w + 0 * t,
            ],
            axis=1,
        )
    return Trajectory(scene.body_names, t, states)


def alone(scene: Scene, body: str) -> Scene:
    """``scene`` holding only ``body``."""
    return replace(scene, bodies=tuple(b for b in scene.bodies if b.name == body))


# --------------------------------------------------------------------------- helpers


def _build(cls: type, options: Mapping[str, Any], mode: str, **override: Any) -> Renderer:
    kw = {"resolution": RESOLUTION, **options, "mode": mode, **override}
    ren: Renderer = construct(cls, kw, Renderer)
    return ren


def _render(
    cls: type,
    ren: Renderer,
    scene: Scene,
    frames: int | None = None,
    *,
    focus: str | None = None,
    out: np.ndarray | None = None,
    traj: Trajectory | None = None,
) -> np.ndarray:
    """``ren``'s frames of ``scene`` along ``traj`` (default: :func:`probe_trajectory`)."""
    traj = probe_trajectory(scene, frames) if traj is None else traj
    try:
        return ren.render(scene, traj, focus=focus, out=out)
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: mode {ren.mode!r}: render() of the probe scene {scene.name!r} "
            f"(focus {focus!r}) raised {type(exc).__name__}: {exc}"
        ) from exc


def _modes(cls: type[Renderer]) -> tuple[str, ...]:
    return tuple(cls.modes)


#: Channels ``C`` of each mode for a scene of ``n`` bodies (see :data:`MODES`).
CHANNELS = {"mark": lambda n: 2, "instance": lambda n: n, "mask": lambda n: 1, "rgb": lambda n: 3}
#: Smallest largest change a body makes to an ``rgb`` image (sensor noise stays well below).
SHOWS_TOL = 0.1


# --------------------------------------------------------------------------- checks


def check_protocol(cls: type[Renderer], **options: Any) -> None:
    """``name`` is a non-empty string, ``modes`` a non-empty tuple of known layouts
    (:data:`~physbench.render.base.MODES`), and ``cls(resolution=..., mode=m, **options)`` builds
    a :class:`~physbench.render.base.Renderer` for every declared mode."""
    require_contract(cls, Renderer)
    modes = cls.modes
    if not isinstance(modes, tuple) or not modes or not set(modes) <= set(MODES):
        raise ConformanceError(
            f"{label(cls)}: class attribute 'modes' must be a non-empty tuple of "
            f"{', '.join(MODES)}; got {modes!r}"
        )
    for mode in modes:
        ren = _build(cls, options, mode)
        if ren.mode != mode:
            raise ConformanceError(
                f"{label(cls)}: built with mode={mode!r}, the instance says mode={ren.mode!r}"
            )


def check_shape(cls: type[Renderer], **options: Any) -> None:
    """In every mode ``shape(scene, frames)`` is what ``render()`` returns, for the scene's frame
    count and for another, with the mode's channel count; a ``(height, width)`` resolution is
    honoured or refused with a :class:`~physbench.render.base.RenderError` naming it."""
    scene = probe_scene()
    for mode in _modes(cls):
        ren = _build(cls, options, mode)
        for frames in (None, 3):
            want = ren.shape(scene, frames)
            got = _render(cls, ren, scene, frames).shape
            n = scene.frames if frames is None else frames
            if tuple(want) != got or got[0] != n:
                raise ConformanceError(
                    f"{label(cls)}: mode {mode!r}: shape(scene, frames={frames}) says "
                    f"{tuple(want)}, render() of {n} frames returned {got}"
                )
            if got[1] != CHANNELS[mode](len(scene.bodies)):
                raise ConformanceError(
                    f"{label(cls)}: mode {mode!r}: {got[1]} channels for "
                    f"{len(scene.bodies)} bodies; the {mode!r} layout has "
                    f"{CHANNELS[mode](len(scene.bodies))}"
                )
        hw = (20, 28)
        try:
            ren = cls(**{**options, "resolution": hw, "mode": mode})
        except RenderError as exc:
            if str(hw) not in str(exc):
                raise ConformanceError(
                    f"{label(cls)}: resolution={hw} raised RenderError without naming the "
                    f"value: {exc}"
                ) from exc
            continue
        except Exception as exc:
            raise ConformanceError(
                f"{label(cls)}: resolution={hw} raised {type(exc).__name__}: {exc}; support "
                "(height, width) or raise physbench.render.base.RenderError naming the value"
            ) from exc
        got = _render(cls, ren, scene).shape
        if got[2:] != hw or tuple(ren.shape(scene)) != got:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: resolution={hw} gives frames {got} (shape() says "
                f"{tuple(ren.shape(scene))}); expected (height, width) = {hw}"
            )


def check_frames(cls: type[Renderer], **options: Any) -> None:
    """In every mode the frames are float32, finite, inside [0, 1] and show the bodies. An
    ``rgb`` image is never empty, so there each body must change some pixel by at least
    :data:`SHOWS_TOL` (the frames of the scene without it differ), and a focus changes nothing."""
    scene = probe_scene()
    for mode in _modes(cls):
        frames = np.asarray(_render(cls, _build(cls, options, mode), scene))
        if frames.dtype != np.float32:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: frames are {frames.dtype}, expected float32"
            )
        if not np.isfinite(frames).all():
            raise ConformanceError(f"{label(cls)}: mode {mode!r}: frames contain NaN or inf")
        lo, hi = float(frames.min()), float(frames.max())
        if lo < 0 or hi > 1:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: values span [{lo:.4g}, {hi:.4g}], expected [0, 1]"
            )
        if hi == 0:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: every frame is empty; the probe scene's two "
                "bodies lie inside its bounds"
            )
        if mode == "rgb":
            _check_rgb(cls, options, frames)


def _check_rgb(cls: type[Renderer], options: Mapping[str, Any], frames: np.ndarray) -> None:
    scene = probe_scene()
    ren = _build(cls, options, "rgb")
    for name in scene.body_names:
        (other,) = (n for n in scene.body_names if n != name)
        without = np.asarray(_render(cls, ren, alone(scene, other)))
        if _far(frames, without) < SHOWS_TOL:
            raise ConformanceError(
                f"{label(cls)}: mode 'rgb': body {name!r} does not show (the frames without it "
                f"differ by {_far(frames, without):.3g} at most)"
            )
    focused = np.asarray(_render(cls, ren, scene, focus=scene.body_names[0]))
    if not np.array_equal(focused, frames):
        raise ConformanceError(
            f"{label(cls)}: mode 'rgb': focus={scene.body_names[0]!r} changes the frames "
            f"(by up to {_far(focused, frames):.3g}); an rgb image marks no body"
        )


def check_deterministic(cls: type[Renderer], **options: Any) -> None:
    """The same input gives identical frames twice, from a fresh instance, and from an instance
    that rendered another scene first (no state leaks between calls)."""
    scene = probe_scene()
    other = replace(alone(scene, "block"), bounds=(-1.0, -1.0, 5.0, 4.0))
    for mode in _modes(cls):
        ren = _build(cls, options, mode)
        a = _render(cls, ren, scene).copy()
        again = _render(cls, ren, scene).copy()
        fresh = _render(cls, _build(cls, options, mode), scene).copy()
        first_other = _build(cls, options, mode)
        _render(cls, first_other, other)
        after = _render(cls, first_other, scene)
        for what, b in (
            ("again", again),
            ("from a fresh instance", fresh),
            ("after rendering another scene", after),
        ):
            if not np.array_equal(a, b):
                raise ConformanceError(
                    f"{label(cls)}: mode {mode!r}: rendering the probe scene {what} changes "
                    f"the frames (largest change {float(np.abs(a - b).max()):.3g})"
                )


def check_out(cls: type[Renderer], **options: Any) -> None:
    """``render(..., out=buffer)`` fills the float32 buffer of ``shape()`` and returns it, with the
    frames a plain call returns, whatever the buffer held."""
    scene = probe_scene()
    for mode in _modes(cls):
        ren = _build(cls, options, mode)
        want = _render(cls, ren, scene).copy()
        buf = np.full(ren.shape(scene), np.nan, dtype=np.float32)
        got = _render(cls, ren, scene, out=buf)
        if got is not buf:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: render(out=buffer) returned a new array, not "
                "the buffer"
            )
        if not np.array_equal(buf, want):
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: render(out=buffer) left frames that differ from "
                "a plain render() (stale or unwritten pixels in the buffer?)"
            )


#: Where the kit's disc starts, ends and rests for :func:`check_follows_trajectory` (m): it moves
#: right and up by 0.6 m, about five pixels at the kit's resolution; the third place is apart
#: from both.
MOTION = ((1.0, 1.5), (1.6, 2.1), (3.2, 0.6))


def _resting(scene: Scene, at: tuple[float, float]) -> Trajectory:
    """Every frame of ``scene`` (one body) at ``at``, unrotated and at rest."""
    t = np.arange(scene.frames) / scene.fps
    states = np.zeros((scene.frames, 1, 6))
    states[:, 0, :2] = at
    return Trajectory(scene.body_names, t, states)


def _moving(scene: Scene, start: tuple[float, float], end: tuple[float, float]) -> Trajectory:
    """``scene``'s one body moving at constant velocity from ``start`` (frame 0) to ``end`` (the
    last frame)."""
    t = np.arange(scene.frames) / scene.fps
    v = (np.subtract(end, start)) / t[-1]
    states = np.zeros((scene.frames, 1, 6))
    states[:, 0, :2] = np.asarray(start) + t[:, None] * v
    states[:, 0, 3:5] = v
    return Trajectory(scene.body_names, t, states)


def _centroid(weight: np.ndarray) -> tuple[float, float]:
    """(row, column) of the centre of mass of a (H, W) weight."""
    total = float(weight.sum())
    rows, cols = np.indices(weight.shape)
    return float((rows * weight).sum()) / total, float((cols * weight).sum()) / total


def check_follows_trajectory(cls: type[Renderer], **options: Any) -> None:
    """In every mode each frame shows the trajectory's pose at that frame: a disc moving right
    and up (:data:`MOTION`) ends nearer the render of the disc resting at its last pose than at
    its first (a renderer that draws every frame at the initial pose fails here), and that
    picture lies to the right of and above the first (columns grow and rows shrink: the world's
    ``y`` points up, image rows run down)."""
    scene = alone(probe_scene(), "disc")
    start, end, elsewhere = MOTION
    for mode in _modes(cls):
        ren = _build(cls, options, mode)
        last = np.asarray(_render(cls, ren, scene, traj=_moving(scene, start, end)))[-1]
        rest = {
            p: np.asarray(_render(cls, ren, scene, traj=_resting(scene, p)))[-1].astype(float)
            for p in MOTION
        }
        to_end, to_start = _mean_far(last, rest[end]), _mean_far(last, rest[start])
        if not to_end < to_start:
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: the last frame of a disc moving from {start} to "
                f"{end} m is no nearer the disc resting at {end} (mean difference {to_end:.3g}) "
                f"than at {start} ({to_start:.3g}); each frame must show the trajectory's pose "
                "at that frame"
            )
        # A pose's blob: where its picture differs from both other poses' pictures.
        r0, c0 = _centroid(_blob(rest[start], rest[end], rest[elsewhere]))
        r1, c1 = _centroid(_blob(rest[end], rest[start], rest[elsewhere]))
        if not (c1 > c0 and r1 < r0):
            raise ConformanceError(
                f"{label(cls)}: mode {mode!r}: a disc moved right and up from {start} to {end} m, "
                f"but its picture moved {c1 - c0:+.1f} columns and {r1 - r0:+.1f} rows; columns "
                "must grow with x and rows shrink with y (the world's y points up, image rows run "
                "down)"
            )


def _blob(here: np.ndarray, *others: np.ndarray) -> np.ndarray:
    """(H, W) weight of where the (C, H, W) picture ``here`` differs from every one of
    ``others``."""
    weight = np.ones(here.shape[1:])
    for other in others:
        weight *= np.abs(here - other).sum(axis=0)
    return weight


def _mean_far(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(np.asarray(a, dtype=float) - b).mean())


def _far(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(np.asarray(a, dtype=float) - b).max())


def check_marking(cls: type[Renderer], **options: Any) -> None:
    """``mark`` mode: with ``focus=body`` channel 1 shows that body and channel 0 every other body
    but not the focus body; without a focus channel 1 is empty."""
    scene = probe_scene()
    ren = _build(cls, options, "mark")
    lone = {
        b.name: np.asarray(_render(cls, ren, alone(scene, b.name)))[:, 0].copy()
        for b in scene.bodies
    }
    plain = np.asarray(_render(cls, ren, scene)).copy()
    if float(np.abs(plain[:, 1]).max()) > 0:
        raise ConformanceError(
            f"{label(cls)}: mark mode: without a focus, channel 1 must be empty; it holds "
            f"values up to {float(plain[:, 1].max()):.3g}"
        )
    for focus in scene.body_names:
        (other,) = (n for n in scene.body_names if n != focus)
        frames = np.asarray(_render(cls, ren, scene, focus=focus))
        if _far(frames[:, 1], lone[focus]) > LAYOUT_TOL:
            raise ConformanceError(
                f"{label(cls)}: mark mode: with focus={focus!r} channel 1 does not show "
                f"{focus!r} (differs from its lone render by {_far(frames[:, 1], lone[focus]):.3g})"
            )
        if _far(frames[:, 0], lone[other]) > LAYOUT_TOL:
            raise ConformanceError(
                f"{label(cls)}: mark mode: with focus={focus!r} channel 0 must show {other!r} "
                f"and not the focus body (differs from {other!r} alone by "
                f"{_far(frames[:, 0], lone[other]):.3g})"
            )


def check_channel_layout(cls: type[Renderer], **options: Any) -> None:
    """``instance`` mode: channel ``i`` shows body ``i`` alone; ``mask`` mode: the one channel
    shows every body."""
    scene = probe_scene()
    for mode in set(_modes(cls)) & {"instance", "mask"}:
        ren = _build(cls, options, mode)
        frames = np.asarray(_render(cls, ren, scene))
        lone = [np.asarray(_render(cls, ren, alone(scene, n)))[:, 0] for n in scene.body_names]
        if mode == "instance":
            for i, name in enumerate(scene.body_names):
                if _far(frames[:, i], lone[i]) > LAYOUT_TOL:
                    raise ConformanceError(
                        f"{label(cls)}: instance mode: channel {i} does not show body {name!r} "
                        f"alone (differs from its lone render by {_far(frames[:, i], lone[i]):.3g})"
                    )
        elif _far(frames[:, 0], np.maximum(*lone)) > LAYOUT_TOL:
            raise ConformanceError(
                f"{label(cls)}: mask mode: channel 0 does not show every body (differs from the "
                f"bodies' lone renders by {_far(frames[:, 0], np.maximum(*lone)):.3g})"
            )


def _refused(cls: type, kw: Mapping[str, Any], value: object) -> None:
    try:
        cls(**kw)
    except RenderError as exc:
        if repr(value) not in str(exc) and str(value) not in str(exc):
            raise ConformanceError(
                f"{label(cls)}: {cls.__name__}(**{dict(kw)!r}) raised RenderError without "
                f"naming {value!r}: {exc}"
            ) from exc
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: {cls.__name__}(**{dict(kw)!r}) raised {type(exc).__name__}: {exc}; "
            "raise physbench.render.base.RenderError naming the value"
        ) from exc
    else:
        raise ConformanceError(f"{label(cls)}: {cls.__name__}(**{dict(kw)!r}) was accepted")


def check_bad_options(cls: type[Renderer], **options: Any) -> None:
    """A resolution that is not a whole number >= 1, an unknown mode and every known mode the
    renderer does not declare raise :class:`~physbench.render.base.RenderError` naming the
    value."""
    mode = _modes(cls)[0]
    for resolution in (0, -4, 2.5, "64"):
        _refused(cls, {**options, "resolution": resolution, "mode": mode}, resolution)
    base = {"resolution": RESOLUTION, **options}
    for bad in ("sepia", *(m for m in MODES if m not in _modes(cls))):
        _refused(cls, {**base, "mode": bad}, bad)


#: Kit settings the renderer checks take (none).
SETTINGS: frozenset[str] = frozenset()
#: Every renderer check, in the order they run.
CHECKS = (
    check_protocol,
    check_shape,
    check_frames,
    check_deterministic,
    check_out,
    check_follows_trajectory,
    check_marking,
    check_channel_layout,
    check_bad_options,
)


def yield_checks(subject: Subject) -> Iterator[Any]:
    """The renderer checks for the modes ``subject`` declares: ``check_marking`` needs ``mark``,
    ``check_channel_layout`` ``instance`` or ``mask``."""
    if not (isinstance(subject.cls, type) and issubclass(subject.cls, Renderer)):
        yield from CHECKS  # the protocol check says why, and the kit stops there
        return
    modes = set(_modes(subject.cls))
    for check in CHECKS:
        if check is check_marking and "mark" not in modes:
            continue
        if check is check_channel_layout and not modes & {"instance", "mask"}:
            continue
        yield check


def check_renderer(cls: type[Renderer], /, **options: Any) -> None:
    """Every renderer check for the modes ``cls`` declares; raises one :class:`ConformanceError`
    listing every failure."""
    subject = Subject(cls, options)
    checks = [Check(f) for f in yield_checks(subject)]
    run_checks(subject, checks, stop_after=check_protocol.__name__)
