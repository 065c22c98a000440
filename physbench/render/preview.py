"""Pictures of a trajectory for people: an animated GIF or a one-image PNG trail.

Called by the CLI and examples, never in the estimation loop. Unlike the frames an estimator sees,
previews draw the static geometry, colour the test body and the focus body distinctly, mark each
body's orientation and are captioned (:func:`annotate`): each body's name, the scene and the time,
and a scale bar in metres, in a band below the picture.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.render.base import DEFAULT_RENDERER, RenderError
from physbench.scene import Segment

if TYPE_CHECKING:
    from PIL import Image

    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

SUFFIXES = (".gif", ".png")
BACKGROUND = (255, 255, 255)
STATIC = (110, 110, 110)
OTHER = (150, 150, 150)
TEST = (31, 119, 180)
FOCUS = (214, 39, 40)
#: Snapshots in a PNG trail.
TRAIL_FRAMES = 6
#: Fraction of the world size added around it, so walls on the bounds stay visible.
MARGIN = 0.03
TEXT = (0, 0, 0)


def scale_length(width: float) -> float:
    """The scale bar's length (m): the largest 1, 2 or 5 × 10^k that is at most a quarter of the
    world's ``width`` (m)."""
    top = width / 4
    power = 10.0 ** math.floor(math.log10(top))
    return max(m * power for m in (1, 2, 5) if m * power <= top)


def annotate(
    img: Image.Image,
    scene: Scene,
    positions: np.ndarray,
    caption: str,
    px: Callable[[float, float], tuple[float, float]],
    metres_per_pixel: float,
) -> Image.Image:
    """``img`` with each body's name beside its centre (``positions (N, 2)``, m) and, in a white
    band added below the scene so nothing covers it, ``caption`` and a scale bar with its length
    in metres. ``px`` maps world coordinates to pixels. Called for every GIF frame and once for a
    PNG trail."""
    from PIL import Image, ImageDraw, ImageFont

    w, h = img.size
    size = max(9, w // 24)
    font = ImageFont.load_default(size=size)
    d = ImageDraw.Draw(img)
    for b, (x, y) in zip(scene.bodies, positions, strict=True):
        r = b.shape.extent()
        at = px(x + 0.7 * r, y + 0.7 * r)
        d.text(
            at, b.name, fill=TEXT, font=font, anchor="lb", stroke_width=2, stroke_fill=BACKGROUND
        )
    pad = max(2, size // 3)
    row = size + pad
    out = Image.new("RGB", (w, h + 2 * row + pad), BACKGROUND)
    out.paste(img, (0, 0))
    d = ImageDraw.Draw(out)
    d.text((pad, h + pad), caption, fill=TEXT, font=font, anchor="lt")
    length = scale_length(metres_per_pixel * w)
    bar = round(length / metres_per_pixel)
    y = h + row + pad + size // 2
    d.rectangle([pad, y - 1, pad + bar, y + 1], fill=TEXT)
    d.text((2 * pad + bar, y), f"{length:g} m", fill=TEXT, font=font, anchor="lm")
    return out


#: The layouts a preview colours, best first: a colour per body (the test body blue, the focus
#: red), the focus body against the rest, every body alike.
COVERAGE = ("instance", "mark", "mask")


def _colours(scene: Scene, focus: str | None, mode: str | None = None) -> np.ndarray:
    """The colour of each channel of ``mode``'s frames (``None``: of each body)."""
    if mode == "mark":
        return np.asarray([OTHER, FOCUS], dtype=np.float32)
    if mode == "mask":
        return np.asarray([OTHER], dtype=np.float32)
    cols = []
    for b in scene.bodies:
        cols.append(FOCUS if b.name == focus else TEST if b.name == scene.test_body else OTHER)
    return np.asarray(cols, dtype=np.float32)


def caption_band(img: Image.Image, caption: str, width: int | None = None) -> Image.Image:
    """``img`` with ``caption`` in a white band added below it (the band :func:`annotate` adds,
    without names or scale bar): for pictures whose pixels do not map linearly to metres. The
    font is sized for pictures ``width`` pixels wide (default: ``img``'s width)."""
    from PIL import Image, ImageDraw, ImageFont

    w, h = img.size
    size = max(9, (width or w) // 24)
    pad = max(2, size // 3)
    out = Image.new("RGB", (w, h + size + 2 * pad), BACKGROUND)
    out.paste(img, (0, 0))
    font = ImageFont.load_default(size=size)
    ImageDraw.Draw(out).text((pad, h + pad), caption, fill=TEXT, font=font, anchor="lt")
    return out


def _composite(
    cover: np.ndarray, colours: np.ndarray, base: np.ndarray, alpha: float = 1.0
) -> np.ndarray:
    """Paint ``cover (N, H, W)`` in ``colours (N, 3)`` over ``base (H, W, 3)``, body by body."""
    img = base.copy()
    for c, col in zip(cover, colours, strict=True):
        a = (c * alpha)[:, :, None]
        img *= 1.0 - a
        img += a * col
    return img


def save_preview(
    scene: Scene,
    traj: Trajectory,
    path: str | Path,
    *,
    size: int = 256,
    focus: str | None = None,
    renderer: str = DEFAULT_RENDERER,
    options: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``path``: ``.gif`` animates the frames at the scene's frame rate; ``.png`` overlays
    every frame as a fading trail with each body's path. Both are captioned by :func:`annotate`
    in a band below the scene. ``size`` is the image width in pixels. ``renderer`` (a registered
    name, with its ``options``; ``simulate --renderer``) draws the bodies, in the first of the
    :data:`COVERAGE` layouts it has; a renderer with none (a camera: ``rgb`` only) is shown as it
    films, captioned with the scene and the time: a GIF of its frames, or a PNG of evenly spaced
    snapshots side by side. Returns the path."""
    from physbench.components import create
    from physbench.plugins import get_registry

    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise RenderError(
            f"preview path {str(path)!r}: unsupported file type; accepted: {', '.join(SUFFIXES)}"
        )
    if focus is not None:
        scene.body_index(focus)  # raises, listing the body names
    modes = get_registry().get("renderer", renderer).modes
    mode = next((m for m in COVERAGE if m in modes), None)
    if mode is None:
        filming = create("renderer", renderer, options, resolution=size, mode="rgb")
        return _save_filmed(scene, traj, path, filming)
    return _save_coverage(scene, traj, path, size, focus, renderer, options, mode)


def _save_filmed(scene: Scene, traj: Trajectory, path: Path, renderer: Renderer) -> Path:
    """The preview of an ``rgb`` renderer: its own frames, captioned."""
    from PIL import Image

    frames = (np.clip(renderer.render(scene, traj), 0, 1) * 255).round().astype(np.uint8)
    pictures = [Image.fromarray(f.transpose(1, 2, 0)) for f in frames]
    if path.suffix.lower() == ".gif":
        shown = [
            caption_band(img, f"{scene.name}   t = {traj.times[t]:.2f} s   ({renderer.name})")
            for t, img in enumerate(pictures)
        ]
        shown[0].save(
            path,
            save_all=True,
            append_images=shown[1:],
            duration=round(1000 / scene.fps),
            loop=0,
            optimize=False,
        )
        return path
    keys = _snapshots(len(pictures))
    w, h = pictures[0].size
    sheet = Image.new("RGB", (w * len(keys), h), BACKGROUND)
    for k, t in enumerate(keys):
        sheet.paste(pictures[t], (k * w, 0))
    caption = (
        f"{scene.name}   t = {traj.times[keys[0]]:.2f} to {traj.times[keys[-1]]:.2f} s "
        f"({len(keys)} snapshots, left to right; {renderer.name})"
    )
    caption_band(sheet, caption, width=w).save(path)
    return path


def _snapshots(frames: int) -> np.ndarray:
    """Evenly spaced frame indices for a PNG: every frame would smear."""
    return np.unique(np.linspace(0, frames - 1, min(TRAIL_FRAMES, frames)).round().astype(int))


def _save_coverage(
    scene: Scene,
    traj: Trajectory,
    path: Path,
    size: int,
    focus: str | None,
    renderer: str,
    options: Mapping[str, Any] | None,
    mode: str,
) -> Path:
    """The preview of a renderer's body coverage in ``mode``, coloured, with the static geometry,
    orientation markers, names, caption and scale bar."""
    from PIL import Image, ImageDraw

    from physbench.components import create

    suffix = path.suffix.lower()
    xmin, ymin, xmax, ymax = scene.bounds
    mx, my = MARGIN * (xmax - xmin), MARGIN * (ymax - ymin)
    view = dataclasses.replace(scene, bounds=(xmin - mx, ymin - my, xmax + mx, ymax + my))
    drawer = create("renderer", renderer, options, resolution=size, mode=mode)
    cover = drawer.render(view, traj, focus=focus if mode == "mark" else None)  # (T, C, H, W)
    h, w = cover.shape[2:]
    vx0, vy0, vx1, vy1 = view.bounds
    sx, sy = w / (vx1 - vx0), h / (vy1 - vy0)

    def px(x: float, y: float) -> tuple[float, float]:
        return ((x - vx0) * sx - 0.5, (vy1 - y) * sy - 0.5)

    background = Image.new("RGB", (w, h), BACKGROUND)
    draw = ImageDraw.Draw(background)
    for s in scene.statics:
        if isinstance(s, Segment):
            width = max(2, round(2 * s.radius * sx))
            draw.line([px(*s.a), px(*s.b)], fill=STATIC, width=width)
        else:
            draw.polygon([px(*p) for p in s.points], fill=STATIC)
    base = np.asarray(background, dtype=np.float32)
    colours = _colours(scene, focus, mode)
    states = traj.states

    def markers(img: Image.Image, t: int) -> None:
        """A line from each body's centre along its angle, so rotation is visible."""
        d = ImageDraw.Draw(img)
        for i, b in enumerate(scene.bodies):
            x, y, a = states[t, i, :3]
            r = b.shape.extent() * 0.9
            d.line(
                [px(x, y), px(x + r * math.cos(a), y + r * math.sin(a))], fill=(0, 0, 0), width=1
            )

    if suffix == ".gif":
        frames = []
        for t in range(cover.shape[0]):
            img = Image.fromarray(_composite(cover[t], colours, base).round().astype(np.uint8))
            markers(img, t)
            caption = f"{scene.name}   t = {traj.times[t]:.2f} s"
            frames.append(annotate(img, scene, states[t, :, :2], caption, px, 1 / sx))
        frames[0].save(
            path,
            save_all=True,
            append_images=frames[1:],
            duration=round(1000 / scene.fps),
            loop=0,
            optimize=False,
        )
        return path

    # A few evenly spaced snapshots, fading in towards the last frame.
    img_f = base
    keys = _snapshots(cover.shape[0])
    for k, t in enumerate(keys):
        img_f = _composite(cover[t], colours, img_f, alpha=0.2 + 0.8 * k / max(1, len(keys) - 1))
    img = Image.fromarray(img_f.round().astype(np.uint8))
    d = ImageDraw.Draw(img)
    for i, colour in enumerate(_colours(scene, focus)):  # each body's path in its own colour
        pts = [px(x, y) for x, y in states[:, i, :2]]
        if len(pts) > 1:
            d.line(pts, fill=tuple(int(c * 0.6) for c in colour), width=1)
    last = cover.shape[0] - 1
    markers(img, last)
    caption = (
        f"{scene.name}   t = {traj.times[keys[0]]:.2f} to {traj.times[last]:.2f} s "
        f"({len(keys)} snapshots, faint: early)"
    )
    annotate(img, scene, states[last, :, :2], caption, px, 1 / sx).save(path)
    return path
