"""Bodies in one frame: foreground blobs, their sub-pixel centres, sizes and orientations.

A pixel's *coverage* is how much of it a body covers, estimated from the difference to the
background: ``(diff - low) / (high - low)`` clipped to ``[0, 1]``, with ``high`` about half the
bodies' contrast and ``low`` above the noise. Blobs are the connected pixels above ``low``
(:func:`label`, numbered as :func:`scipy.ndimage.label` numbers them); a blob's centre is the
coverage-weighted mean of its pixels, so a partly covered edge pixel counts in part and the centre
moves smoothly with the body (and, under motion blur, sits at the middle of the smear: the body's
pose at mid-exposure, for a body that does not turn much during the exposure; a fast-swinging arm's
centre is biased towards where it stays longest). What the tracker records is measured on the
scene's plane (:func:`plane_pose`): the centroid and axes of the pixels mapped into metres.

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

from physbench.video.compiled import jit, pairwise_sum

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
    # (du + i dv)^4 in real arithmetic (complex arrays cost several times as much).
    re, im = du * du - dv * dv, 2 * du * dv
    z4 = float(w @ (re * re - im * im)), float(w @ (2 * re * im))
    return _blob_of_moments(total, cu, cv, muu, mvv, muv, *z4, int(u.size))


def _blob_of_moments(
    total: float,
    cu: float,
    cv: float,
    muu: float,
    mvv: float,
    muv: float,
    z4_re: float,
    z4_im: float,
    count: int,
) -> Blob:
    """The :class:`Blob` of ``count`` pixels from their coverage ``total``, centre ``(cu, cv)``,
    weighted second central moments and fourth-order moment ``z4`` (the weighted sum of
    ``(du + i dv)^4``)."""
    axis = 0.5 * math.atan2(2 * muv, muu - mvv)
    spread = math.hypot(muu - mvv, 2 * muv)
    big, small = (muu + mvv + spread) / 2, (muu + mvv - spread) / 2
    elongation = big / small if small > 1e-12 else math.inf
    # A square's corners dominate the fourth moment: its phase points at a corner, 45 degrees
    # from a side.
    square = (math.atan2(z4_im, z4_re) / 4 - math.pi / 4) % (math.pi / 2)
    return Blob(cu, cv, total, count, axis, elongation, square)


def find_blobs(
    diff: np.ndarray, low: float, high: float, *, offset: tuple[int, int] = (0, 0), min_area=2.0
) -> list[tuple[Blob, np.ndarray, np.ndarray, np.ndarray]]:
    """Blobs of a difference image ``diff`` (``(H, W)``, a crop whose top-left pixel is
    ``offset = (row, col)`` of the frame): each with its pixels' ``u``, ``v`` (frame px) and
    coverage, largest first; blobs covering less than ``min_area`` px are noise and dropped."""
    # Labelled within the foreground's bounding box: a window is mostly wall, and labelling
    # and scanning it cost more than the rest of this function. (Compared in float64, the box
    # holds at least the pixels that NumPy's comparison, in the difference's type, finds.)
    r0, r1, c0, c1 = _extent(diff, float(low))
    if r0 == r1:
        return []
    labels, n = label_above(diff[r0:r1, c0:c1], float(low))
    scale = np.float32(1.0 / max(high - low, 1e-6))  # as in coverage()
    u, v, w, starts, sums = _blob_pixels(
        labels, n, diff, r0, c0, r0 + offset[0], c0 + offset[1], float(low), scale, float(min_area)
    )
    out = []
    ends = starts.tolist()
    for k, (total, *moments) in enumerate(sums.tolist()):
        if total > 0:
            a, b = ends[k], ends[k + 1]
            blob = _blob_of_moments(total, *moments, b - a)
            out.append((blob, u[a:b], v[a:b], w[a:b]))
    out.sort(key=lambda b: -b[0].area)
    return out


def label(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """The 4-connected blobs of ``mask`` (bool ``(H, W)``): int32 labels ``(H, W)`` (0 off the
    blobs) and their count, numbered in the order of their first pixels row by row, as
    :func:`scipy.ndimage.label` with :data:`CROSS` numbers them (:func:`label_above`)."""
    return label_above(np.ascontiguousarray(mask, dtype=bool).view(np.uint8), 0.0)


@jit
def label_above(values, low):  # type: ignore[no-untyped-def]
    """The 4-connected blobs of the pixels of ``values`` (``(H, W)``) above ``low``, as
    :func:`label`'s. One pass with a union-find over the blobs' provisional labels: scipy's own
    costs about 45 us a call before any pixel (63-78 us on the tracker's windows' foreground
    boxes, against 19-24 us); the comparison in the same pass saves NumPy's mask (compared in
    float64, as NumPy compares uint8 with a float)."""
    h, w = values.shape
    labels = np.zeros((h, w), np.int32)
    parent = np.empty((h * w + 1) // 2 + 2, np.int32)  # at most a checkerboard's
    made = 1
    for i in range(h):
        for j in range(w):
            if not values[i, j] > low:
                continue
            up = labels[i - 1, j] if i else 0
            left = labels[i, j - 1] if j else 0
            if up and left:
                a, b = up, left
                while parent[a] != a:
                    a = parent[a]
                while parent[b] != b:
                    b = parent[b]
                root = min(a, b)  # the first in row order
                parent[a] = parent[b] = parent[up] = parent[left] = root
                labels[i, j] = root
            elif up or left:
                labels[i, j] = up or left
            else:
                parent[made] = made
                labels[i, j] = made
                made += 1
    final = np.zeros(made, np.int32)
    n = 0
    for k in range(1, made):
        root = k
        while parent[root] != root:
            root = parent[root]
        if root == k:
            n += 1
            final[k] = n
        else:
            final[k] = final[root]
    for i in range(h):
        for j in range(w):
            labels[i, j] = final[labels[i, j]]
    return labels, n


@jit
def _extent(diff, low):  # type: ignore[no-untyped-def]
    """The bounding box ``(r0, r1, c0, c1)`` of the pixels of ``diff`` above ``low``, compared
    in float64 (``r0 == r1`` when there are none)."""
    h, w = diff.shape
    # Or-ed along rows and columns without a branch, so that the loop is vectorised.
    cols = np.zeros(w, np.uint8)
    r0, r1 = h, 0
    for i in range(h):
        row = np.uint8(0)
        for j in range(w):
            above = np.uint8(diff[i, j] > low)
            cols[j] |= above
            row |= above
        if row:
            r0, r1 = min(r0, i), i + 1
    c0, c1 = w, 0
    for j in range(w):
        if cols[j]:
            c0, c1 = min(c0, j), j + 1
    if r1 == 0:
        return 0, 0, 0, 0
    return r0, r1, c0, c1


@jit
def _blob_pixels(  # type: ignore[no-untyped-def]
    labels, n, diff, r0, c0, row0, col0, low, scale, min_area
):
    """:func:`find_blobs`' work after labelling, in one call: from ``labels``
    (:func:`label` of ``diff[r0:, c0:]``'s pixels above ``low``, ``n`` blobs, its
    top-left pixel the frame's ``(row0, col0)``), the pixels' ``u``, ``v`` (frame px) and
    coverage (:func:`coverage`, ``scale`` its factor), blob after blob, each in row-major order;
    each blob's first pixel (``n + 1`` starts, the last the end); and per blob its coverage
    total, centre and moments for :func:`_blob_of_moments` (zeros for a blob covering less than
    ``min_area``).

    The sums are :func:`blob_from_pixels`': the total is ``w.sum()``'s (``pairwise_sum``), each
    weighted sum ``np.dot``, which calls BLAS as ``w @ u`` does (numba SciPy's, NumPy its own:
    the same to the bit where both are OpenBLAS and choose the same kernel, as here)."""
    h, w = labels.shape
    # The foreground's pixels in row-major order, with their labels and coverage...
    counts = np.zeros(n + 1, np.intp)
    rows, cols, label = np.empty(h * w, np.intp), np.empty(h * w, np.intp), np.empty(h * w, np.intp)
    low32, zero, one = np.float32(low), np.float32(0.0), np.float32(1.0)
    found = 0
    for i in range(h):
        for j in range(w):
            if labels[i, j]:
                rows[found], cols[found], label[found] = i, j, labels[i, j]
                counts[labels[i, j]] += 1
                found += 1
    # ... then sorted by label (stable: a counting sort).
    starts = np.empty(n + 1, np.intp)
    at = np.empty(n + 1, np.intp)
    size, largest = 0, 0
    for k in range(n):
        starts[k] = at[k + 1] = size
        size += counts[k + 1]
        largest = max(largest, counts[k + 1])
    starts[n] = size
    us, vs, cov = np.empty(size), np.empty(size), np.empty(size)
    for f in range(found):
        k = at[label[f]]
        at[label[f]] += 1
        i, j = rows[f], cols[f]
        us[k], vs[k] = np.float64(j + col0), np.float64(i + row0)
        c = (np.float32(diff[i + r0, j + c0]) - low32) * scale
        cov[k] = np.float64(min(max(c, zero), one))
    sums = np.zeros((n, 8))
    terms = np.empty((5, largest))  # each pixel's terms of the moments
    for k in range(n):
        a, m = starts[k], counts[k + 1]
        total = pairwise_sum(cov, a, m)
        if total < min_area or total <= 0:
            continue
        wb, ub, vb = cov[a : a + m], us[a : a + m], vs[a : a + m]
        cu, cv = np.dot(wb, ub) / total, np.dot(wb, vb) / total
        for q in range(m):
            du, dv = ub[q] - cu, vb[q] - cv
            re, im = du * du - dv * dv, 2 * du * dv
            terms[0, q], terms[1, q], terms[2, q] = du * du, dv * dv, du * dv
            terms[3, q], terms[4, q] = re * re - im * im, 2 * re * im
        sums[k, 0], sums[k, 1], sums[k, 2] = total, cu, cv
        for e in range(5):
            sums[k, 3 + e] = np.dot(wb, terms[e, :m])
    return us, vs, cov, starts, sums


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
