"""Pictures of a trajectory for people: an animated GIF or a one-image PNG trail.

Called by the CLI and examples, never in the estimation loop. Unlike the frames an estimator sees,
previews draw the static geometry, colour the test body and the focus body distinctly, mark each
body's orientation and are captioned (:func:`annotate`): each body's name, the scene and the time,
and a scale bar in metres, in a band below the picture.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.render.base import DEFAULT_RENDERER, RenderError
from physbench.scene import Segment

if TYPE_CHECKING:
    from PIL import Image

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


def _colours(scene: Scene, focus: str | None) -> np.ndarray:
    cols = []
    for b in scene.bodies:
        cols.append(FOCUS if b.name == focus else TEST if b.name == scene.test_body else OTHER)
    return np.asarray(cols, dtype=np.float32)


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
    scene: Scene, traj: Trajectory, path: str | Path, *, size: int = 256, focus: str | None = None
) -> Path:
    """Write ``path``: ``.gif`` animates the frames at the scene's frame rate; ``.png`` overlays
    every frame as a fading trail with each body's path. Both are captioned by :func:`annotate`
    in a band below the scene. ``size`` is the image width in pixels. Returns the path."""
    from PIL import Image, ImageDraw

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise RenderError(
            f"preview path {str(path)!r}: unsupported file type; accepted: {', '.join(SUFFIXES)}"
        )
    if focus is not None:
        scene.body_index(focus)  # raises, listing the body names

    xmin, ymin, xmax, ymax = scene.bounds
    mx, my = MARGIN * (xmax - xmin), MARGIN * (ymax - ymin)
    view = dataclasses.replace(scene, bounds=(xmin - mx, ymin - my, xmax + mx, ymax + my))
    from physbench.components import create

    # the default renderer draws each body's coverage, one channel per body, for the colours
    renderer = create("renderer", DEFAULT_RENDERER, resolution=size, mode="instance")
    cover = renderer.render(view, traj)  # (T, N, H, W)
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
    colours = _colours(scene, focus)
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

    # A few evenly spaced snapshots, fading in towards the last frame; every frame would smear.
    img_f = base
    keys = np.unique(
        np.linspace(0, cover.shape[0] - 1, min(TRAIL_FRAMES, cover.shape[0])).round().astype(int)
    )
    for k, t in enumerate(keys):
        img_f = _composite(cover[t], colours, img_f, alpha=0.2 + 0.8 * k / max(1, len(keys) - 1))
    img = Image.fromarray(img_f.round().astype(np.uint8))
    d = ImageDraw.Draw(img)
    for i in range(len(scene.bodies)):
        pts = [px(x, y) for x, y in states[:, i, :2]]
        if len(pts) > 1:
            d.line(pts, fill=tuple(int(c * 0.6) for c in colours[i]), width=1)
    last = cover.shape[0] - 1
    markers(img, last)
    caption = (
        f"{scene.name}   t = {traj.times[keys[0]]:.2f} to {traj.times[last]:.2f} s "
        f"({len(keys)} snapshots, faint: early)"
    )
    annotate(img, scene, states[last, :, :2], caption, px, 1 / sx).save(path)
    return path
