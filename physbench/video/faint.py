"""A disc of a few pixels too faint for a per-pixel threshold, found by a matched filter.

A ball of 1-2 px radius on a second camera (shaded, on a textured wall, coded at a high CRF,
smeared by a long shutter) differs from the plate by 50-90 grey levels summed over the colour
channels at its best pixel, while the noise's 99th percentile is 22-24: a threshold per pixel
either misses it or takes the noise. Summed over the body's footprint the contrast adds up
while the noise averages out. :func:`find_faint` takes the difference to the background in the
frame's light (summed over the channels), correlates it with the body's expected footprint (its
disc smeared along its predicted motion over the exposure), and scales that response by its own
robust spread over the crop (its MAD: the texture the light does not quite match and the
coding's blocks are correlated noise, which a per-pixel sigma would underrate). The most
significant response within the gate around the prediction is the body, if it is
:data:`SIGNIFICANCE` robust deviations above the crop's median; its centre is the weighted
centroid of the difference over the footprint placed there, refined twice.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from physbench.video.photometry import Light

#: How many robust deviations of the filtered response over the crop a detection must reach.
SIGNIFICANCE = 8.0
#: Gates up to this radius (px) take :data:`SIGNIFICANCE` as it is; a wider gate holds more
#: places where noise could reach it, so its threshold grows as the root of the logarithm of
#: the number of footprints the gate holds (a Gaussian's largest of n draws grows so): a ball
#: lost for a few frames, whose gate had grown to 116 px, took a spot of brick texture 8.9
#: deviations high, 120 px from it, while its own disc measured 30-40.
WIDE_GATE = 30.0
#: How many of a small body's last places (the frames it was seen in) may hold its ghost
#: (:func:`ghosts_of`).
GHOST_FRAMES = 10
#: Half the side (px) of the smallest crop the response's spread is measured on.
MIN_HALF = 24
#: The share of the frame interval the exposure is taken to last (unknown: 0.15-0.7 seen):
#: a footprint of half the motion loses little of a shorter or longer smear's sum.
SHUTTER = 0.5
#: A detection whose place stood at least this share of its significance above the crop in the
#: first frame too, where no body was, is a fixed spot of the scene that the background does
#: not quite match (:class:`FirstFrame`), not the body: a 1.2 px ball lost for four frames took
#: a spot of plank 5.5-8.1 deviations high in every frame of its clip, 55 px from it, and
#: followed it. Over the faint detections of the second camera's 72 clips of small balls
#: (tracked without this rule), those 5 px or more off had a median share of 0.52, those under
#: 3 px 0.09 (99th percentile 0.39): at 0.4, 22 of the 36 far ones and 4 of the 478 near ones
#: were such spots.
FIXED_SHARE = 0.4
#: How many fixed spots one search passes by before it gives up on the frame.
FIXED_TRIES = 3


@dataclass(frozen=True)
class Faint:
    """A faint disc: its centre ``uv`` (px) and how many robust deviations its filtered
    response stood above the crop's."""

    uv: np.ndarray
    significance: float


def footprint(radius: float, smear: np.ndarray, centre: np.ndarray | None = None) -> np.ndarray:
    """The soft footprint ``(k, k)`` float32 of a disc of ``radius`` px moved by ``smear``
    ``(2,)`` px over the exposure, centred in its array (or at ``centre``, an offset from the
    array's middle, px): each pixel's coverage ``clip(radius + 0.5 - distance, 0, 1)`` from the
    segment the disc's centre sweeps."""
    half = math.ceil(radius + 0.5 * float(np.hypot(*smear)) + 1.5)
    g = np.arange(-half, half + 1, dtype=np.float64)
    du, dv = np.meshgrid(g, g)
    if centre is not None:
        du, dv = du - centre[0], dv - centre[1]
    return _coverage(du, dv, radius, smear).astype(np.float32)


def _coverage(du: np.ndarray, dv: np.ndarray, radius: float, smear: np.ndarray) -> np.ndarray:
    """Coverage of pixels at offsets ``(du, dv)`` from the middle of the segment ``smear``."""
    a = 0.5 * np.asarray(smear, dtype=np.float64)
    aa = float(a @ a)
    t = np.clip((du * a[0] + dv * a[1]) / aa, -1.0, 1.0) if aa > 1e-9 else 0.0
    dist = np.hypot(du - t * a[0], dv - t * a[1])
    return np.clip(radius + 0.5 - dist, 0.0, 1.0)


@dataclass(frozen=True)
class FirstFrame:
    """A clip's first frame, its light and where its bodies were (``places``: ``(u, v, reach)``
    px), kept to tell a small body from a fixed spot of the scene (:meth:`holds`)."""

    image: np.ndarray
    light: Light
    places: tuple[tuple[float, float, float], ...]

    def holds(
        self, uv: np.ndarray, radius: float, smear: np.ndarray, background: np.ndarray, level: float
    ) -> bool:
        """Whether a detection of ``level`` robust deviations at ``uv`` (px), of a disc of
        ``radius`` px smeared by ``smear`` px, was in the first frame already, at
        :data:`FIXED_SHARE` of that level or more, where no body was near. ``False`` where a body
        of the first frame was within reach: its own response there says nothing."""
        for u, v, reach in self.places:
            if math.hypot(float(uv[0]) - u, float(uv[1]) - v) <= reach + radius + 2.0:
                return False
        then = find_faint(
            self.image, background, self.light, uv, ghost_reach(radius), radius, smear,
            significance=-math.inf,
        )  # fmt: skip
        return then is not None and then.significance >= FIXED_SHARE * level


def _significance(resp: np.ndarray) -> np.ndarray | None:
    """A filtered response in robust deviations from its median over the crop."""
    centre = float(np.median(resp))
    spread = 1.4826 * float(np.median(np.abs(resp - centre)))
    return None if spread <= 1e-6 else (resp - centre) / spread


def look_elsewhere(gate: float, radius: float) -> float:
    """The significance a search within ``gate`` px needs for a disc of ``radius`` px, as a share
    of what one within :data:`WIDE_GATE` px needs: the root of the ratio of the logarithms of the
    number of footprints each holds (a Gaussian's largest of n draws grows so)."""
    n, n0 = ((g / (radius + 1.0)) ** 2 for g in (gate, WIDE_GATE))
    return math.sqrt(math.log(max(n, 2.0)) / math.log(max(n0, 2.0)))


def ghosts_of(places: Sequence[np.ndarray], pred: np.ndarray, radius: float) -> list[np.ndarray]:
    """Of ``places`` (px) where a small body of ``radius`` px was seen in its last frames, those
    its prediction ``pred`` has moved away from (by more than its diameter and 2 px): a detection
    within :func:`ghost_reach` of one is the lossy codec's ghost of the body, not the body. A
    coded clip's skipped blocks keep a body's imprint where it was: a 1.2 px ball at CRF 30
    stood 54 grey levels (summed over the channels) above the plate at its first place in all
    41 frames while the ball itself showed 19-48 in most, and the tracker followed the imprint."""
    return [q for q in places if float(np.hypot(*(q - pred))) > 2 * radius + 2.0]


def ghost_reach(radius: float) -> float:
    """How far (px) from a ghost's place (:func:`ghosts_of`) a detection of a body of ``radius``
    px is that ghost."""
    return radius + 1.5


def _widening(gate: float, radius: float) -> float:
    """How much a gate of ``gate`` px raises the threshold for a disc of ``radius`` px (see
    :data:`WIDE_GATE`)."""
    return 1.0 if gate <= WIDE_GATE else look_elsewhere(gate, radius)


def find_faint(
    image: np.ndarray,
    background: np.ndarray,
    light: Light,
    pred: np.ndarray,
    gate: float,
    radius: float,
    smear: np.ndarray,
    taken: Sequence[np.ndarray] = (),
    seen: Sequence[np.ndarray] = (),
    significance: float = SIGNIFICANCE,
    rivals: Sequence[tuple[np.ndarray, float]] = (),
    fixed: Sequence[np.ndarray] = (),
) -> Faint | None:
    """The disc of ``radius`` px nearest-by-significance to ``pred`` (px) within ``gate`` px in
    ``image`` against ``background`` (both ``(H, W, 3)`` uint8) in the frame's ``light``,
    smeared by ``smear`` px over the exposure (see the module docstring); ``taken``: centres
    (px) of other bodies found in this frame, whose footprints are not this body; ``seen``:
    where this body was seen in its last frames (px), not it either where the prediction has
    moved away from there (:func:`ghosts_of`: a lossy codec's skipped blocks leave a ghost of it
    there); ``significance``: the robust deviations a detection must reach in a gate of up to
    :data:`WIDE_GATE` px; ``rivals``: the predictions (px) and gates (px) of the other bodies
    not yet found in this frame: a place nearer one of them, in gates, is theirs (two small
    balls after a collision: the first searched took the other's disc, 26 px from its own
    prediction and 4 px from the other's); ``fixed``: spots of the scene found in the first frame
    too (:meth:`FirstFrame.holds`), passed by as a ghost is. ``None`` where nothing within the
    gate reaches it."""
    h, w = image.shape[:2]
    half = max(MIN_HALF, math.ceil(gate + radius + float(np.hypot(*smear)) + 3))
    u0, v0 = round(float(pred[0])), round(float(pred[1]))
    r0, r1 = max(0, v0 - half), min(h, v0 + half + 1)
    c0, c1 = max(0, u0 - half), min(w, u0 + half + 1)
    if r1 - r0 < 8 or c1 - c0 < 8:
        return None
    lit = background[r0:r1, c0:c1].astype(np.float32) * light.gain.astype(np.float32)
    lit += light.offset.astype(np.float32)
    diff = np.abs(image[r0:r1, c0:c1].astype(np.float32) - lit).sum(axis=2)
    diff -= np.float32(np.median(diff))
    kernel = footprint(radius, smear)
    kernel /= kernel.sum()
    z = _significance(ndimage.correlate(diff, kernel, mode="nearest"))
    if z is None:
        return None
    vv, uu = np.mgrid[r0:r1, c0:c1]
    allowed = (uu - pred[0]) ** 2 + (vv - pred[1]) ** 2 <= gate * gate
    reach = radius + 0.5 * float(np.hypot(*smear)) + 2.0
    for q in taken:
        allowed &= (uu - q[0]) ** 2 + (vv - q[1]) ** 2 > (2 * reach) ** 2
    if rivals:
        mine = np.sqrt((uu - pred[0]) ** 2 + (vv - pred[1]) ** 2) / gate
        for q, other in rivals:
            allowed &= mine <= np.sqrt((uu - q[0]) ** 2 + (vv - q[1]) ** 2) / other
    ghosts, near = ghosts_of(seen, pred, radius) + list(fixed), ghost_reach(radius)
    for q in ghosts:
        allowed &= (uu - q[0]) ** 2 + (vv - q[1]) ** 2 > near**2
    if not allowed.any():
        return None
    z = np.where(allowed, z, -np.inf)
    weight = np.maximum(diff, 0.0).astype(np.float64)
    for _ in range(2):
        k = int(np.argmax(z))
        best = float(z.flat[k])
        if best < significance * _widening(gate, radius):
            return None
        uv = _centred(weight, uu, vv, np.array([uu.flat[k], vv.flat[k]], float), radius, smear)
        off = float(np.hypot(*(uv - pred))) / gate
        if any(float(np.hypot(*(uv - q))) / other < off for q, other in rivals):
            return None  # centred on a rival's disc: the peak was the edge of it
        hit = [q for q in ghosts if float(np.hypot(*(uv - q))) <= near]
        if not hit:
            return Faint(uv, best)
        # Centred on a ghost, the peak was the edge of its response: once more, past the reach
        # of that response (the ghost is still, the footprint smeared).
        past = near + radius + 0.5 * float(np.hypot(*smear)) + 1.0
        z = np.where((uu - hit[0][0]) ** 2 + (vv - hit[0][1]) ** 2 > past**2, z, -np.inf)
    return None


def _centred(
    weight: np.ndarray,
    uu: np.ndarray,
    vv: np.ndarray,
    uv: np.ndarray,
    radius: float,
    smear: np.ndarray,
) -> np.ndarray:
    """The weighted centroid of ``weight`` (the difference, at pixels ``uu``, ``vv``) over the
    footprint placed at ``uv``, refined up to three times."""
    for _ in range(3):
        cover = _coverage(uu - uv[0], vv - uv[1], radius + 1.0, smear)
        wt = weight * cover
        total = float(wt.sum())
        if total <= 0:
            break
        new = np.array([(wt * uu).sum(), (wt * vv).sum()]) / total
        moved = float(np.hypot(*(new - uv)))
        uv = new
        if moved < 0.02:
            break
    return uv
