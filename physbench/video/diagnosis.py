"""Why a body is not where the scene says it starts: the measured cause and the fix for it.

Called by the tracker when a body in view has no blob near its projection in the first frame.
What it measures there, in the frame's light (:class:`~physbench.video.photometry.Light`):

- **A blob of the body's size elsewhere** (searched out to 8 radii): the scene's initial position,
  the calibration or ``--start`` is off; the message gives the blob's pixel and distance.
- **A clear blob of another size there**: the scene's radius (or the calibration's scale) is
  off; the message gives the blob's radius, in metres too.
- **Some contrast, under the threshold**: the body differs from the wall behind it by fewer grey
  levels than the frame's noise or the other bodies' contrast allow, or does so over too little
  of its area to be found; more contrast is the fix.
- **Nothing there**: with a plate, the body is elsewhere (or the plate is of another view); with
  the clip's median as the background, either that, or the body stays put for most of the clip
  and the median holds it (then a plate of the empty scene is the fix).

A light change between the frame and the background is measured and compensated; where it is
large the message says so, since it is not the cause.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physbench.video.detect import Blob, find_blobs
from physbench.video.photometry import DEVIATIONS, Light

#: How far (in radii) to look for a blob of the body's size.
SEARCH_RADII = 8.0
#: A blob rounder than this (:attr:`~physbench.video.detect.Blob.elongation`, the ratio of its
#: second moments; 1.44 for an ellipse of axes 1.2 : 1) is taken for a disc.
ROUND = 1.5


@dataclass(frozen=True)
class Missing:
    """A body not found in the first frame: its ``name``, the pixel ``uv`` where the scene puts
    it, its ``radius`` and covered ``area`` there (px), its initial ``position`` (m), and a
    disc's radius in ``metres``."""

    name: str
    uv: np.ndarray
    radius: float
    area: float
    position: tuple[float, float]
    metres: float | None = None  # a disc's radius in the scene (m)


def not_found(
    body: Missing,
    image: np.ndarray,
    background: np.ndarray,
    light: Light,
    low: float,
    *,
    median: bool,
    deviations: float = DEVIATIONS,
) -> str:
    """The message for ``body`` missing from ``image`` (``(H, W, 3)`` uint8) against
    ``background`` in the frame's ``light``, where ``low`` (grey levels) is the foreground
    threshold; ``median``: the background is the clip's median; ``deviations``: the noise
    threshold in the frame's robust deviations that the tracker used."""
    h, w = image.shape[:2]
    u, v = body.uv
    head = (
        f"body {body.name!r} is not in the first frame: expected near pixel (u={u:.0f}, "
        f"v={v:.0f}) of the {w}x{h} image (its initial position "
        f"{tuple(round(c, 3) for c in body.position)} m through the calibration)"
    )
    m = SEARCH_RADII * body.radius + 12
    r0, r1 = max(0, int(v - m)), min(h, int(v + m) + 2)
    c0, c1 = max(0, int(u - m)), min(w, int(u + m) + 2)
    diff = light.difference(image[r0:r1, c0:c1], background[r0:r1, c0:c1])
    vv, uu = np.mgrid[r0:r1, c0:c1]
    spot = (uu - u) ** 2 + (vv - v) ** 2 <= max(body.radius, 2.0) ** 2
    peak = float(np.percentile(diff[spot], 90)) if spot.any() else 0.0
    noise = light.threshold(deviations=deviations)
    shift = light.change
    lit = (
        f"; frame 0 is {abs(shift):.0%} {'brighter' if shift > 0 else 'darker'} than the "
        "background, which the tracker measured and compensated (not the cause)"
        if abs(shift) >= 0.03
        else ""
    )
    near = max(2 * body.radius, 12.0)
    blobs = find_blobs(diff, low, 2 * low, offset=(r0, c0), min_area=2.0)
    sized = [b for b, *_ in blobs if 0.4 * body.area <= b.area <= 2.5 * body.area]
    if sized:
        best = min(sized, key=lambda b: float(np.hypot(b.u - u, b.v - v)))
        far = float(np.hypot(best.u - u, best.v - v))
        if far <= near:
            # A solid round blob of another size is a wrong radius or scale, not "no disc".
            (found,) = [f for f in blobs if f[0] is best]
            if _solid(found) and best.elongation < ROUND and abs(best.area / body.area - 1) > 0.4:
                return f"{head}; {_size(body, best)}{lit}"
            return (
                f"{head}; a blob there, at pixel (u={best.u:.0f}, v={best.v:.0f}), covers "
                f"{best.area / body.area:.0%} of its area but is not a disc's of {body.radius:.1f} "
                "px radius nor of its area: check the body's size in the scene and the "
                f"calibration's scale{lit}"
            )
    other = _another_size(body, blobs, near)
    if other:
        return f"{head}; {other}{lit}"
    if sized:
        # With the clip's median as the background, a body that stays put is not there at all,
        # and the blob of its size may be another body.
        held = (
            "; or it stays there for most of the clip and the background, the median of the "
            "clip, holds it: film the empty scene and give it as --background"
            if median
            else ""
        )
        return (
            f"{head}; a blob of its size is {far:.0f} px away, at pixel (u={best.u:.0f}, "
            f"v={best.v:.0f}): the scene's initial position, --seed, --start or the calibration "
            f"is off{held}{lit}"
        )
    fix = (
        "too little contrast. Give it a colour or brightness unlike the wall behind it, light "
        f"it evenly, and film a plate of the empty scene (--background){lit}"
    )
    if low <= peak:
        covered = float((diff[spot] > low).mean())
        return (
            f"{head}; only {covered:.0%} of its area there differs from the "
            f"background by more than the threshold of {low:.0f} grey levels (the frame's noise: "
            f"{noise:.0f}; the most contrasted tenth of it: {peak:.0f}): {fix}"
        )
    if peak > 0.5 * noise:
        return (
            f"{head}; it differs from the background there by at most {peak:.0f} grey levels, "
            f"under the threshold of {low:.0f} (the frame's noise: {noise:.0f}): {fix}"
        )
    if median:
        return (
            f"{head}; nothing there differs from the background (at most {peak:.0f} grey levels; "
            f"noise threshold {noise:.0f}). Either the body is elsewhere (check the scene's "
            "initial position, --seed, --start and the calibration), or it stays there for "
            "most of the clip and the background, the median of the clip, holds it: film the "
            f"empty scene and give it as --background{lit}"
        )
    return (
        f"{head}; nothing there differs from the background (at most {peak:.0f} grey levels; "
        f"noise threshold {noise:.0f}): check the scene's initial position, --seed, --start and "
        f"the calibration, and that the background is a plate of this camera's view{lit}"
    )


def _another_size(body: Missing, blobs: list, near: float) -> str:
    """What a clear, solid blob at ``body``'s start, of another size than the scene gives it,
    says (the scene's radius or the calibration's scale is wrong); ``""`` without one. A faint
    body's blob is only a part of it, its pixels barely over the threshold: not solid."""
    u, v = body.uv
    odd = [f[0] for f in blobs if _solid(f) and float(np.hypot(f[0].u - u, f[0].v - v)) <= near]
    if not odd:
        return ""
    return _size(body, max(odd, key=lambda b: b.area))


def _solid(found: tuple) -> bool:
    """Whether a blob ``(blob, u, v, coverage)`` is solid: some of it fully over the background,
    and most of its pixels near it (a faint body's blob is a part of it, barely over the
    threshold)."""
    blob, _, _, cover = found
    return bool(cover.max() >= 1.0) and blob.area >= 0.6 * blob.count


def _size(body: Missing, b: Blob) -> str:
    """The radius blob ``b`` at ``body``'s start shows, against the scene's."""
    seen = float(np.sqrt(b.area / np.pi))
    size = ""
    if body.metres is not None:
        size = (
            f" (if it is the body, its radius is about {seen * body.metres / body.radius:.3g} m, "
            f"not {body.metres:.3g} m)"
        )
    return (
        f"a blob there, at pixel (u={b.u:.0f}, v={b.v:.0f}), is about {seen:.1f} px in radius, "
        f"where the scene's radius makes {body.radius:.1f} px{size}: correct the scene's radius "
        "(scene new --radius) or the calibration's scale"
    )
