"""What a tracked body looks like, and whether a detection looks like it.

A detection near a body's prediction is not always the body: a hand that reaches in, a shadow, an
occluder crossing in front, a rod joined to a pendulum's bob. Each body keeps its
:class:`Appearance` from the frames where it was found: its size (covered area over the area the
scene and the calibration give it there) and its colour (the median of its inner pixels, taken
back to the background's light by the frame's gain and offset). A detection whose size or colour
departs from the body's by more than the body's own spread allows is rejected, so the body is
unseen in that frame rather than recorded where something else is.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from physbench.video.compiled import jit, pairwise_sum

#: The covered area may be this many times smaller or larger than the scene's: motion blur keeps
#: the area, a threshold or a partly hidden edge changes it by tens of per cent.
SIZE_RATIO = 2.2
#: Largest change of a colour's direction (distance between unit RGB vectors) from the body's:
#: shading and uneven light keep the direction, motion blur mixes in some of the wall's (up to
#: 0.2 measured on a swinging arm's best covered pixels); another material departs further (a
#: red ball and a hand: 0.48, red and blue: 1.2).
HUE_TOLERANCE = 0.25
#: The colour's brightness may be this many times darker or brighter than the body's (shading
#: and uneven light across the view).
BRIGHTNESS_RATIO = 1.8
#: Added to each channel (grey levels) before a colour's direction is taken: a dark body's
#: direction is noise.
DARK = 16.0
#: Colours nearer than this (grey levels, the length of their difference) are one colour whatever
#: their directions: a dark body's hue is its noise and the wall's colour bled into it (a black
#: ball of 6 px in H.264-coded frames measured (31, 18, 0) in its first frames and (12, 13, 19)
#: later: 0.46 apart in direction, 27 levels in all).
SAME_COLOUR = 32.0
#: Below this area (px) a body's measured size is loose: the size ratio allowed grows as the
#: root of this over its area.
SMALL = 50.0
#: The least share of its size that a body's own colour may show in a blob of several colours.
HIDDEN = 0.2
#: Below this area (px) a body has no colour of its own to judge: its few pixels are mostly its
#: outline, blended with the wall behind it and smeared by motion (a ball of 3.7 px on a brick
#: wall measured 0-3 grey levels from the first frame, 90-170 in the next).
COLOUR_PIXELS = 20.0
#: Weight of a new detection in the running appearance.
RATE = 0.1


@dataclass(frozen=True)
class Look:
    """One detection's appearance: ``size`` (covered area over the area the scene gives the
    body there, ``pixels``) and ``colour`` ``(3,)`` (grey levels in the background's light)."""

    size: float
    colour: np.ndarray
    pixels: float = math.inf


# A colour's arithmetic on its three channels as Python floats: NumPy's dispatch costs more than
# the work on three values, and ``d @ d`` and ``np.sum`` of three add them in this order too.


def _direction(c: Sequence[float]) -> tuple[float, float, float]:
    r, g, b = c[0] + DARK, c[1] + DARK, c[2] + DARK
    n = math.sqrt(r * r + g * g + b * b)
    return r / n, g / n, b / n


def _length(d: Sequence[float]) -> float:
    """``np.linalg.norm`` of a vector of three (the same value)."""
    x, y, z = d
    return math.sqrt(x * x + y * y + z * z)


def _apart(a: Sequence[float], b: Sequence[float]) -> float:
    """The length of ``a - b``."""
    x, y, z = a[0] - b[0], a[1] - b[1], a[2] - b[2]
    return math.sqrt(x * x + y * y + z * z)


@dataclass
class Appearance:
    """A body's running appearance (see the module docstring)."""

    size: float
    colour: np.ndarray
    hue_spread: float = 0.0
    seen: int = 1

    def __post_init__(self) -> None:
        self._colour_changed()

    def _colour_changed(self) -> None:
        """Its colour's direction and brightness, which every detection is compared with."""
        r, g, b = self.colour.tolist()
        self._unit = _direction((r, g, b))
        self._brightness = r + g + b + 3 * DARK
        # The last look whose hue was judged, and that hue: the tracker judges a detection
        # (mismatch) and then learns from it (update), and the hue is the same.
        self._judged: tuple[Look, float] | None = None

    @classmethod
    def first(cls, look: Look) -> Appearance:
        return cls(look.size, np.asarray(look.colour, dtype=float))

    def mismatch(self, look: Look, *, hidden: bool = False) -> str | None:
        """Why ``look`` is not this body (a few words with the measured values), or ``None``.
        ``hidden``: the look is of the pixels of the body's colour in a blob that holds other
        colours too, so part of the body may be hidden (by a neighbour, or where a median
        background holds the body itself): down to :data:`HIDDEN` of its size. The colour of a
        body smaller than :data:`COLOUR_PIXELS` is not judged."""
        ratio = look.size / max(self.size, 1e-9)
        # A body of a few pixels has a size of a few pixels, give or take most of them.
        allowed = SIZE_RATIO * max(1.0, math.sqrt(SMALL / max(look.pixels, 1e-9)))
        least = min(1 / allowed, HIDDEN) if hidden else 1 / allowed
        if not least <= ratio <= allowed:
            return f"{ratio:.2f} times its size"
        if look.pixels < COLOUR_PIXELS:
            return None
        colour = np.asarray(look.colour, dtype=float).tolist()
        hue = _apart(_direction(colour), self._unit)
        self._judged = (look, hue)
        near = _apart(colour, self.colour.tolist()) < SAME_COLOUR
        if hue > max(HUE_TOLERANCE, 4 * self.hue_spread) and not near:
            return f"another colour (hue {hue:.2f} off)"
        bright = (colour[0] + colour[1] + colour[2] + 3 * DARK) / self._brightness
        if not 1 / BRIGHTNESS_RATIO <= bright <= BRIGHTNESS_RATIO:
            return f"{bright:.2f} times its brightness"
        return None

    def update(self, look: Look) -> None:
        """Called by the tracker with each accepted detection's appearance."""
        colour = np.asarray(look.colour, dtype=float).tolist()
        judged = self._judged
        hue = judged[1] if judged is not None and judged[0] is look else None
        if hue is None:
            hue = _apart(_direction(colour), self._unit)
        self.hue_spread += RATE * (hue - self.hue_spread)
        self.size += RATE * (look.size - self.size)
        mine = self.colour.tolist()
        self.colour = np.array([c + RATE * (x - c) for c, x in zip(mine, colour, strict=True)])
        self._colour_changed()
        self.seen += 1


def matching(
    looks: Sequence[Appearance],
    image: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    w: np.ndarray,
    ends: np.ndarray,
    offset: np.ndarray,
    gain: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Which pixels ``(u, v)`` of ``image`` (``(H, W, 3)`` uint8) have each of ``looks``' hue and
    brightness (a body's own pixels, in a blob shared with bodies or things of other colours),
    their colours taken back to the background's light (``(raw - offset) / gain``) and darkened
    by :data:`DARK` as a :class:`Look`'s: ``(n, k)``, a column per look. With the pixels in
    groups (blobs) that end at ``ends``, and their coverage ``w``: each group's coverage of each
    look's pixels, ``(groups, k)``, summed as NumPy sums ``w[mask]``."""
    refs = np.array([look.colour for look in looks], dtype=float) + DARK  # (k, 3)
    size = np.array([_length(ref.tolist()) for ref in refs])
    tolerance = np.array([max(HUE_TOLERANCE, 4 * look.hue_spread) for look in looks])
    # |a - b| <= tol for unit vectors: a . b >= 1 - tol^2 / 2.
    least = 1 - 0.5 * tolerance**2
    return _matching(image, u, v, w, ends, offset, gain, refs / size[:, None], size, least)


@jit
def _matching(image, u, v, w, ends, offset, gain, units, size, least):  # type: ignore[no-untyped-def]
    """:func:`matching`'s pixels, one at a time, each channel's level taken back to the
    background's light through a table of its 256 values (the same values: 0.11 s over the 899
    windows of the 20 s speed clip's tracking against 0.14 s dividing per pixel)."""
    n, k = len(u), len(size)
    masks = np.zeros((n, k), np.bool_)
    levels = np.empty((3, 256))
    for c in range(3):
        for x in range(256):
            levels[c, x] = (x - offset[c]) / gain[c] + DARK
    for p in range(n):
        y, x = int(v[p]), int(u[p])
        d0 = levels[0, image[y, x, 0]]
        d1 = levels[1, image[y, x, 1]]
        d2 = levels[2, image[y, x, 2]]
        norm = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        d0, d1, d2 = d0 / norm, d1 / norm, d2 / norm
        for j in range(k):
            bright = norm / size[j]
            hue = d0 * units[j, 0] + d1 * units[j, 1] + d2 * units[j, 2]
            masks[p, j] = (
                hue >= least[j] and bright >= 1 / BRIGHTNESS_RATIO and bright <= BRIGHTNESS_RATIO
            )
    owned = np.zeros((len(ends), k))
    mine = np.empty(n)
    start = 0
    for g in range(len(ends)):
        for j in range(k):
            count = 0
            for p in range(start, ends[g]):
                if masks[p, j]:
                    mine[count] = w[p]
                    count += 1
            owned[g, j] = pairwise_sum(mine, 0, count)
        start = ends[g]
    return masks, owned
