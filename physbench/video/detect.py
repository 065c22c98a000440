"""Bodies in one frame: foreground blobs, their sub-pixel centres, sizes and orientations.

A pixel's *coverage* is how much of it a body covers, estimated from the difference to the
background: ``(diff - low) / (high - low)`` clipped to ``[0, 1]``, with ``high`` about half the
bodies' contrast and ``low`` above the noise. Blobs are the connected pixels above ``low``
(:func:`scipy.ndimage.label`); a blob's centre is the coverage-weighted mean of its pixels, so a
partly covered edge pixel counts in part and the centre moves smoothly with the body (and, under
motion blur, sits at the middle of the smear: the body's pose at mid-exposure, for a body that
does not turn much during the exposure; a fast-swinging arm's centre is biased towards where it
stays longest). What the tracker records is measured on the scene's plane
(:func:`plane_pose`): the centroid and axes of the pixels mapped into metres.

Orientation comes from moments: the second moments give a blob's long axis (``symmetry=2``, for an
elongated body), the fourth-order angular moment a square's sides (``symmetry=4``). Where one blob
holds several bodies (touching, or passing each other), :func:`split_blob` shares its pixels out by
the nearest predicted outline and re-fits each body's centre inside its own outline.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

if TYPE_CHECKING:
    from physbench.calibration import Calibration

#: Blobs are 4-connected (:func:`scipy.ndimage.label`'s default, built once).
CROSS = ndimage.generate_binary_structure(2, 1)


@dataclass(frozen=True)
class Blob:
    """One body's pixels in a frame: centre ``(u, v)`` (px), ``area`` (covered px), the pixel
    ``count``, the long axis ``axis`` (rad in the image, ``v`` down, mod pi) with ``elongation``
    (ratio of the principal second moments, >= 1), and the fourth-order orientation ``square``
    (rad, mod pi/2)."""

    u: float
    v: float
    area: float
    count: int
    axis: float
    elongation: float
    square: float

    @property
    def centre(self) -> np.ndarray:
        return np.array([self.u, self.v])


@dataclass(frozen=True)
class Outline:
    """A body's outline in the image around its centre, for sharing a blob between bodies: a disc
    of ``radius`` px, or a convex polygon of ``vertices`` ``(K, 2)`` px around the centre (a box or
    polygon at its predicted angle, through the calibration)."""

    radius: float
    vertices: np.ndarray | None = None

    def distance(self, du: np.ndarray, dv: np.ndarray) -> np.ndarray:
        """Signed distance (px, < 0 inside) of pixels at offsets ``(du, dv)`` from the centre;
        exact inside a polygon and along its sides, a lower bound off its corners."""
        if self.vertices is None:
            return np.hypot(du, dv) - self.radius
        p = np.asarray(self.vertices, dtype=np.float64)
        q = np.roll(p, -1, axis=0)
        e = q - p
        ccw = float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1])) > 0
        n = np.stack([e[:, 1], -e[:, 0]], axis=1) * (1.0 if ccw else -1.0)
        n /= np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-12)[:, None]
        d = n[:, :1] * (du[None] - p[:, :1]) + n[:, 1:] * (dv[None] - p[:, 1:])
        return d.max(axis=0)


def coverage(diff: np.ndarray, low: float, high: float) -> np.ndarray:
    """Per-pixel coverage in ``[0, 1]`` (float32) from a background difference (see the module
    docstring); ``high > low``."""
    out = diff.astype(np.float32)
    out -= np.float32(low)
    out *= np.float32(1.0 / max(high - low, 1e-6))
    np.maximum(out, 0.0, out=out)  # np.clip's dispatch costs more than its work here
    return np.minimum(out, 1.0, out=out)


def blob_from_pixels(u: np.ndarray, v: np.ndarray, w: np.ndarray) -> Blob | None:
    """The :class:`Blob` of pixels at ``(u, v)`` with coverage ``w`` (``None`` when uncovered)."""
    total = float(w.sum())
    if total <= 0:
        return None
    cu, cv = float(w @ u) / total, float(w @ v) / total
    du, dv = u - cu, v - cv
    muu, mvv, muv = float(w @ (du * du)), float(w @ (dv * dv)), float(w @ (du * dv))
    axis = 0.5 * math.atan2(2 * muv, muu - mvv)
    spread = math.hypot(muu - mvv, 2 * muv)
    big, small = (muu + mvv + spread) / 2, (muu + mvv - spread) / 2
    elongation = big / small if small > 1e-12 else math.inf
    # (du + i dv)^4 in real arithmetic (complex arrays cost several times as much).
    re, im = du * du - dv * dv, 2 * du * dv
    z4 = complex(float(w @ (re * re - im * im)), float(w @ (2 * re * im)))
    # A square's corners dominate the fourth moment: its phase points at a corner, 45 degrees
    # from a side.
    square = (math.atan2(z4.imag, z4.real) / 4 - math.pi / 4) % (math.pi / 2)
    return Blob(cu, cv, total, int(u.size), axis, elongation, square)


def find_blobs(
    diff: np.ndarray, low: float, high: float, *, offset: tuple[int, int] = (0, 0), min_area=2.0
) -> list[tuple[Blob, np.ndarray, np.ndarray, np.ndarray]]:
    """Blobs of a difference image ``diff`` (``(H, W)``, a crop whose top-left pixel is
    ``offset = (row, col)`` of the frame): each with its pixels' ``u``, ``v`` (frame px) and
    coverage, largest first; blobs covering less than ``min_area`` px are noise and dropped."""
    mask = diff > low
    # Labelled within the foreground's bounding box: a window is mostly wall, and labelling
    # and scanning it cost more than the rest of this function.
    some_rows = np.flatnonzero(mask.any(axis=1))
    if not len(some_rows):
        return []
    some_cols = np.flatnonzero(mask.any(axis=0))
    r0, c0 = int(some_rows[0]), int(some_cols[0])
    box = mask[r0 : some_rows[-1] + 1, c0 : some_cols[-1] + 1]
    labels, n = ndimage.label(box, CROSS)
    # Every blob's pixels in one pass, each blob's in the frame's row-major order.
    rows, cols = np.nonzero(box)
    label = labels[rows, cols]
    if n > 1:
        order = np.argsort(label, kind="stable")
        rows, cols = rows[order], cols[order]
    rows += r0
    cols += c0
    cov = coverage(diff[rows, cols], low, high).astype(np.float64)
    us = (cols + offset[1]).astype(np.float64)
    vs = (rows + offset[0]).astype(np.float64)
    ends = np.cumsum(np.bincount(label, minlength=n + 1)[1:]).tolist()
    out = []
    for a, b in zip([0, *ends[:-1]], ends, strict=True):
        w = cov[a:b]
        if w.sum() < min_area:
            continue
        u, v = us[a:b], vs[a:b]
        blob = blob_from_pixels(u, v, w)
        if blob is not None:
            out.append((blob, u, v, w))
    out.sort(key=lambda b: -b[0].area)
    return out


def split_pixels(
    u: np.ndarray,
    v: np.ndarray,
    w: np.ndarray,
    centres: np.ndarray,
    outlines: list[Outline],
    *,
    iterations: int = 6,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Share one blob's pixels among bodies predicted at ``centres`` (``(N, 2)`` px) with
    ``outlines``: each pixel goes to the body whose outline is nearest (signed distance, so
    touching bodies split along their contact), and each body's centre is re-fitted to the pixels
    it owns inside its outline, ``iterations`` times. Returns the centres ``(N, 2)``, each pixel's
    owner ``(P,)`` and whether it lies inside its owner's outline ``(P,)``."""
    c = np.array(centres, dtype=np.float64)

    def distances() -> np.ndarray:
        return np.stack([o.distance(u - c[j, 0], v - c[j, 1]) for j, o in enumerate(outlines)])

    for _ in range(iterations):
        dist = distances()  # (N, P)
        owner = np.argmin(dist, axis=0)
        moved = 0.0
        for j in range(len(c)):
            inside = (owner == j) & (dist[j] <= 1.0)
            wj = w[inside]
            if wj.sum() <= 0:
                continue
            new = np.array([wj @ u[inside], wj @ v[inside]]) / wj.sum()
            moved = max(moved, float(np.abs(new - c[j]).max()))
            c[j] = new
        if moved < 0.01:
            break
    dist = distances()
    owner = np.argmin(dist, axis=0)
    return c, owner, dist[owner, np.arange(owner.size)] <= 1.0


def split_blob(
    u: np.ndarray,
    v: np.ndarray,
    w: np.ndarray,
    centres: np.ndarray,
    outlines: list[Outline],
    *,
    iterations: int = 6,
) -> list[Blob | None]:
    """:func:`split_pixels` as one blob (or ``None``) per body: the centre is the fit inside the
    outline; the moments come from all the pixels the body owns."""
    c, owner, _ = split_pixels(u, v, w, centres, outlines, iterations=iterations)
    out: list[Blob | None] = []
    for j in range(len(c)):
        mine = owner == j
        blob = blob_from_pixels(u[mine], v[mine], w[mine])
        if blob is not None:
            blob = replace(blob, u=float(c[j, 0]), v=float(c[j, 1]))
        out.append(blob)
    return out


@dataclass(frozen=True)
class PlanePose:
    """A body's pixels measured on the scene's plane: the area centroid ``xy`` (m), the long
    axis ``axis`` (rad, CCW from x, mod pi) with ``elongation``, and a square's sides ``square``
    (rad, mod pi/2). Measured in metres, so an oblique view's foreshortening and perspective do
    not bias them (a centroid or an axis taken in the image does not map to the body's)."""

    xy: np.ndarray
    axis: float
    elongation: float
    square: float


def plane_points(
    u: np.ndarray, v: np.ndarray, calibration: Calibration
) -> tuple[np.ndarray, np.ndarray]:
    """Pixels ``(u, v)`` on the scene's plane: their points ``(n, 2)`` (m) and the plane area
    each sees (the homography's Jacobian; a lens's is neglected), with one lens undistortion."""
    uv = np.column_stack([u, v])
    und = uv if calibration.lens is None else calibration.lens.undistort(uv)
    h = calibration.homography
    q = und @ h[:, :2].T + h[:, 2]
    return q[:, :2] / q[:, 2:3], np.abs(np.linalg.det(h) / q[:, 2] ** 3)


def plane_pose(
    u: np.ndarray,
    v: np.ndarray,
    w: np.ndarray,
    calibration: Calibration,
    points: tuple[np.ndarray, np.ndarray] | None = None,
) -> PlanePose:
    """The :class:`PlanePose` of pixels at ``(u, v)`` with coverage ``w``: each pixel mapped
    into the plane and weighted by its coverage times the plane area it sees
    (:func:`plane_points`, or ``points`` where the caller has them)."""
    xy, area = plane_points(u, v, calibration) if points is None else points
    blob = blob_from_pixels(xy[:, 0], xy[:, 1], w * area)
    if blob is None:
        return PlanePose(xy.mean(axis=0), 0.0, 1.0, 0.0)
    return PlanePose(blob.centre, blob.axis, blob.elongation, blob.square)
