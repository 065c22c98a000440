"""A disc's centre from its silhouette: edge points found along rays, fitted by a circle on the
scene's plane.

The centroid of a lit sphere's pixels is not its centre: the highlight and the shaded side
differ from the wall by different amounts, so any weighting by the difference leans away from
the highlight (measured: 0.7-1.1 px on 13-22 px spheres; up to 4 px for a light grey ball on a
wall of its brightness). The outline does not depend on the shading. From a first guess of the
centre, rays go out in every direction; along each, the outermost point where the difference
falls below half of its level just inside (the edge's half-way point, or the foreground
threshold where that is higher) is an edge point. Edge points map into the plane
(:meth:`~physbench.calibration.Calibration.to_scene`, so an oblique view's foreshortening does
not bias the centre) and a circle is fitted to them; points far off the circle are dropped and the
circle fitted again. A ray that never leaves the foreground (a rod joined to a pendulum's bob,
a touching ball, an occluder), that leaves the image, or whose edge is far off the circle adds
nothing, so the fit holds where part of the outline is hidden. Motion blur stretches a fast disc
into a stadium, symmetric about the disc's pose at mid-exposure: where the circle does not fit
its edges, a stadium along the disc's motion is fitted instead (a fast ball's centre errors: 95 %
within 0.24 px, 0.59 px with the circle). In video that stores colour at a lower resolution than
brightness, a coloured rim bleeds outwards: a disc's edges that look like such a halo
(:data:`HALO`) are left out where the disc fits without them (the tracker keeps them for a disc
whose smear is long: its ends fade out over its length).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

from physbench.video.compiled import jit, pairwise_sum, solve

if TYPE_CHECKING:
    from physbench.calibration import Calibration

#: Radial sampling step along a ray (px).
STEP = 0.5
#: A smeared disc's outline is fitted as a stadium where its circle leaves this RMS (px) in its
#: edges (a still disc's: 0.1-0.2 px).
STADIUM_RMS = 0.25
#: Directions (over half a turn) a smear is fitted along where the track's last direction of
#: motion fits its edges worse than a circle.
TURNS = 12
#: Samples of foreground in a row that make the body's rim (1.5 px).
RUN = 3
#: Rays are this far apart (px) along the disc's outline: 43 rays on a 27 px disc, whose centre
#: they fix to a few hundredths of a pixel.
SPACING = 4.0
#: How far inside an edge its inner level is searched for (px, at most half the radius): past
#: an anti-aliased, coded or blurred edge, short of a highlight.
INNER = 4.0
#: The largest angle (rad) between two neighbouring edge points that a fit accepts: a disc seen
#: over less than ~210 degrees of its outline is too little of it.
MAX_ARC_GAP = math.radians(150.0)
#: With the disc's radius known from earlier frames, this much of its outline (rad) fixes its
#: centre.
MIN_ARC = math.radians(120.0)
#: In video whose colour is stored at a lower resolution than its brightness (4:2:0, 4:2:2), an
#: edge whose contrast is under this share of the difference's peak just inside it may be a
#: halo: colour bled past the rim, where the outermost run of foreground ends (on lit spheres
#: coded as H.264, a tenth of the edges lay a median 2 px further out than in the same frames
#: uncoded).
HALO = 0.75


@dataclass(frozen=True)
class DiscFit:
    """A disc fitted to its outline: centre ``xy`` (m) and ``uv`` (px), ``radius`` (m), the
    share of rays whose edge was kept, the RMS distance (px) of the kept edge points from the
    circle, and whether the radius was the one known from earlier frames (``fixed``: too little
    of the outline to fit it)."""

    xy: np.ndarray
    uv: np.ndarray
    radius: float
    kept: float
    rms_px: float
    fixed: bool = False


@dataclass(frozen=True)
class Rays:
    """Where rays look for one disc's edge: from ``centre`` (frame px) for a disc of about
    ``radius`` px, out to ``reach`` px."""

    centre: np.ndarray
    radius: float
    reach: float


@dataclass(frozen=True)
class Edges:
    """Edge points found along rays: ``uv`` ``(n, 2)`` (frame px), the rays' angles ``theta``,
    each edge's ``contrast`` (grey levels, its inner level over the outside) and ``width`` (px
    from where it rises out of the noise to its half-way point: a sharp edge's is about a
    pixel), its distance from the rays' origin (``reach``, px), the index of the disc each
    belongs to (``owner``), and whether each may be a :data:`HALO` (``halo``)."""

    uv: np.ndarray
    theta: np.ndarray
    contrast: np.ndarray
    width: np.ndarray
    reach: np.ndarray
    owner: np.ndarray
    halo: np.ndarray | None = None

    def select(self, keep: np.ndarray) -> Edges:
        """The edges where ``keep`` (a mask or indices)."""
        return Edges(
            self.uv[keep],
            self.theta[keep],
            self.contrast[keep],
            self.width[keep],
            self.reach[keep],
            self.owner[keep],
            None if self.halo is None else self.halo[keep],
        )

    def of(self, disc: int) -> Edges:
        """The edges of disc ``disc``."""
        return self.select(self.owner == disc)


def edge_points(
    diff: np.ndarray, offset: tuple[int, int], rays: Sequence[Rays], low: float
) -> Edges:
    """Edge points of several discs in one difference image ``diff`` (a crop whose top-left
    pixel is ``offset = (row, col)``), all rays at once: for each of ``rays``, rays every
    :data:`SPACING` px of its outline (16-64), searched from 70 % of its radius less
    :data:`INNER` out to its reach;
    ``low`` is the foreground threshold. Rays that leave the crop, or find no edge, are left
    out."""
    return window_edges([(diff, offset, rays)], low)


def window_edges(
    windows: Sequence[tuple[np.ndarray, tuple[int, int], Sequence[Rays]]], low: float
) -> Edges:
    """:func:`edge_points` in several crops ``(diff, offset, rays)`` at once (one pass over all
    their rays: a frame's discs cost one call, not one per window), their discs numbered on in
    order."""
    rays = [r for _, _, some in windows for r in some]
    if not rays:
        empty = np.empty(0)
        return Edges(np.empty((0, 2)), empty, empty, empty, empty, np.empty(0, np.intp), empty > 0)
    counts = [min(max(round(2 * math.pi * r.radius / SPACING), 16), 64) for r in rays]
    # How far inside an edge its inner level is looked for, from the window's smallest disc.
    inner = [min(INNER, 0.5 * min(r.radius for r in some)) for _, _, some in windows]
    window = [w for w, (_, _, some) in enumerate(windows) for _ in some]
    shape = np.array([diff.shape for diff, _, _ in windows], dtype=np.intp)
    sizes = shape[:, 0] * shape[:, 1]
    discs = np.array(
        [(*r.centre, r.radius, r.reach, n, max(2, round(inner[w] / STEP)), w)
         for r, n, w in zip(rays, counts, window, strict=True)]
    )  # fmt: skip
    origin = np.array([o for _, o, _ in windows], dtype=np.intp)
    flat = np.concatenate([diff.ravel() for diff, _, _ in windows])
    found = _ray_edges(
        flat,
        np.cumsum(sizes) - sizes,
        shape,
        origin,
        discs,
        np.concatenate([_directions(n) for n in counts]),
        float(low),
    )
    return Edges(*found)


@cache
def _directions(n: int) -> np.ndarray:
    """``(n, 3)``: the angles of ``n`` rays spread evenly over a turn, their cosines and sines."""
    theta = np.arange(n) * (2 * math.pi / n)
    return np.column_stack([theta, np.cos(theta), np.sin(theta)])


@jit
def _ray_edges(flat, base, shape, origin, discs, directions, low):  # type: ignore[no-untyped-def]
    """Each disc's rays (``discs`` rows: centre u, v, radius, reach, ray count, inner depth in
    samples, window) sampled on its window's difference (``flat``: the windows' differences
    laid end to end, each from ``base``, ``shape`` ``(h, w)``, top-left pixel ``origin``) and the
    edge each finds (:func:`_edge`): :class:`Edges`' arrays, for the rays inside their window
    that find one. Along a ray, samples every :data:`STEP` px from 70 % of the radius less
    :data:`INNER` to the reach (:func:`_profile`)."""
    n = 0
    for d in range(len(discs)):
        n += int(discs[d, 4])
    start = np.empty(n)
    owner = np.empty(n, np.intp)
    ray = 0
    for d in range(len(discs)):
        for _ in range(int(discs[d, 4])):
            start[ray] = max(0.0, 0.7 * discs[d, 2] - INNER)
            owner[ray] = d
            ray += 1
    longest = 0.0
    for j in range(n):
        longest = max(longest, discs[owner[j], 3] - start[j])
    m = int(np.ceil(longest / STEP)) + 1
    uv = np.empty((n, 2))
    theta, contrast, width, reach = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    halo = np.empty(n, np.bool_)
    kept = np.empty(n, np.intp)
    p, s, near = np.empty(m), np.empty(m, np.float32), np.empty(m + 2)
    count = 0
    for j in range(n):
        d = owner[j]
        win = int(discs[d, 6])
        h, w = shape[win, 0], shape[win, 1]
        cu, cv = discs[d, 0] - origin[win, 1], discs[d, 1] - origin[win, 0]
        du, dv = directions[j, 1], directions[j, 2]
        steps = min(int(np.floor((discs[d, 3] - start[j]) / STEP)) + 1, m)
        # Rays are straight: inside the window where both their ends are.
        inside = True
        for far in (start[j], start[j] + STEP * (steps - 1)):
            eu, ev = cu + du * far, cv + dv * far
            inside &= eu >= 0 and eu <= w - 1 and ev >= 0 and ev <= h - 1
        _profile(flat, base[win], h, w, cu, cv, du, dv, start[j], p, s)
        good, dist, rise, wide, faint = _edge(p, s, steps, int(discs[d, 5]), low, near)
        if not (inside and good):
            continue
        uv[count, 0] = discs[d, 0] + du * dist
        uv[count, 1] = discs[d, 1] + dv * dist
        theta[count], contrast[count], width[count] = directions[j, 0], rise, wide
        reach[count], kept[count], halo[count] = dist, d, faint
        count += 1
    return (uv[:count], theta[:count], contrast[:count], width[:count], reach[:count],
            kept[:count], halo[:count])  # fmt: skip


@jit
def _profile(flat, b, h, w, cu, cv, du, dv, start, p, s):  # type: ignore[no-untyped-def]
    """A ray's profile: the samples ``p`` of a window's difference (``flat[b:]``, ``h`` x
    ``w``) at distances ``s`` (float32) from ``(cu, cv)`` along ``(du, dv)``, every :data:`STEP`
    px from ``start``, read bilinearly and clamped to the window (in NumPy's float types: the
    positions in float32, the values in float64)."""
    top_row, top_col = np.float32(h - 1.001), np.float32(w - 1.001)
    fu, fv, fdu, fdv = np.float32(cu), np.float32(cv), np.float32(du), np.float32(dv)
    for i in range(len(p)):
        s[i] = np.float32(start + STEP * i)
        r = min(max(fv + fdv * s[i], np.float32(0.0)), top_row)
        c = min(max(fu + fdu * s[i], np.float32(0.0)), top_col)
        r0, c0 = int(r), int(c)
        fr, fc = np.float64(r) - r0, np.float64(c) - c0
        q = r0 * w + c0 + b
        a0, a1 = np.float32(flat[q]), np.float32(flat[q + 1])
        upper = np.float64(a0) + np.float64(a1 - a0) * fc
        a0, a1 = np.float32(flat[q + w]), np.float32(flat[q + w + 1])
        lower = np.float64(a0) + np.float64(a1 - a0) * fc
        p[i] = upper + (lower - upper) * fr


@jit
def _edge(p, s, steps, k, low, near):  # type: ignore[no-untyped-def]
    """The edge on a ray's profile ``p`` (at distances ``s``, its first ``steps`` samples its
    own, its inner level searched ``k`` samples inside; ``near``: room for ``k + 2``): whether
    it has one, its distance, contrast, width and whether it may be a halo (:class:`Edges`).

    The outermost run of :data:`RUN` samples at or above ``low`` ends at the edge: a speck of
    the wall's texture the light does not quite match, a pixel or so past the rim, is not it.
    The edge's inner level is where the profile stops falling steeply, walking in from its
    steepest point near the threshold crossing: the rim's own brightness, not the shading
    further in (a lit sphere brightens inwards from a limb as dark as the wall). An edge whose
    inner level is under ``low`` over the outside is placed by the threshold, not by its
    half-way point: it adds nothing."""
    m = len(p)
    last = -1
    for i in range(min(steps, m) - 1, RUN - 2, -1):
        run = True
        for q in range(i - RUN + 1, i + 1):
            run &= p[q] >= low
        if run:
            last = i
            break
    good = last >= 0 and last < steps - 1
    if last < 0:
        last = m - 1
    for t in range(k + 2):  # inside out
        near[t] = p[min(max(last - k + t, 0), m - 1)]
    # The steepest fall over one step out of the last `outer` (the first of equals).
    outer = max(1, round(2.0 / STEP))
    first = k + 1 - outer
    lo = max(first, 0)
    at = lo
    for t in range(lo + 1, k + 1):
        if near[t] - near[t + 1] > near[at] - near[at + 1]:
            at = t
    steep = first + at - lo  # below 0 (an inner depth under `outer`): counted from the end
    top = near[steep % (k + 1)] - near[steep % (k + 1) + 1]
    shoulder = 0
    for t in range(min(steep, k + 1) - 1, -1, -1):
        if near[t] - near[t + 1] < 0.3 * top:
            shoulder = t
            break
    inner, outside = near[shoulder], near[k + 1]
    good &= inner - outside >= low
    level = 0.5 * (inner + outside)
    # The outermost sample at or above the level, and the next one out (below it).
    jj = k
    for t in range(k, -1, -1):
        if near[t] >= level:
            jj = t
            break
    frac = (near[jj] - level) / max(near[jj] - near[jj + 1], 1e-6)
    dist = np.float64(s[min(max(last - k + jj, 0), m - 1)]) + STEP * min(max(frac, 0.0), 1.0)
    peak = near[0]
    for t in range(1, k + 2):
        peak = max(peak, near[t])
    width = np.float64(s[last] + np.float32(0.5 * STEP)) - dist
    return good, dist, inner - outside, width, inner - outside < HALO * (peak - outside)


#: The directions (unit vectors over half a turn, :data:`TURNS` of them) a smear is fitted along
#: where the track's last direction of motion fits its edges worse than a circle.
_TURNED = np.array([[math.cos(a), math.sin(a)] for a in np.arange(0.0, math.pi, math.pi / TURNS)])


@jit
def _circle_fits(  # type: ignore[no-untyped-def]
    xy, chosen, owner, angle, strength, spread, radius, mpp, has_known
):
    """:func:`fit_discs`' circles: each disc's fitted robustly to its ``chosen`` edges (their
    points ``xy`` on the plane; :class:`Edges`' ``owner``, increasing, ``theta``, ``contrast``
    and ``width`` as ``owner``, ``angle``, ``strength`` and ``spread``). Returns the centres
    ``(count, 2)`` and radii (m), each edge's weight and whether it is kept, the kept counts,
    the largest angle between neighbouring kept rays, the discs seen over too little of their
    outline to fit their radius whose radius is known from earlier frames (``has_known``; for
    :func:`_circle_of_radius`), and each disc's edge count and first edge.

    As the NumPy expressions it replaces, to the bit: the normal equations are summed as
    ``np.add.reduceat`` sums them (the first term, then the rest pairwise:
    :func:`~physbench.video.compiled.pairwise_sum`) and solved as OpenBLAS's LAPACK
    ``dgesv`` solves them (:func:`~physbench.video.compiled.solve`)."""
    count, n = len(radius), len(chosen)
    own, theta, contrast, width = _gathered(chosen, owner, angle, strength, spread)
    sizes, starts = _runs(own, count)
    top = _strongest(own, contrast, count)
    weight, w, keys, dist, res = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    order = np.empty(n, np.intp)
    trim, keep = np.empty(n, np.bool_), np.empty(n, np.bool_)
    a, terms, sums = np.empty((n, 4)), np.empty((12, n)), np.empty((count, 12))
    mean, centre, r = np.zeros((count, 2)), np.empty((count, 2)), np.empty(count)
    lu, rhs = np.empty((3, 3)), np.empty(3)
    # Stage 0: each disc's mean and median edge width. Then its circle through all its edges;
    # through the three quarters nearest that circle (least trimmed squares: a highlight's rim
    # is a tight cluster of edges inside the outline, which a fit to all of them leans to); and
    # through those within 3 robust deviations (at least 0.75 px) of the second circle and not
    # inside 70 % of its radius.
    for stage in range(4):
        if stage == 0:
            for i in range(n):
                keys[i] = width[i]
        elif stage == 2:
            _off_circle(xy, own, centre, r, keys)
        elif stage == 3:
            _residuals(xy, own, centre, r, trim, dist, res, keys)
        if stage != 1:
            _rank(keys, starts, sizes, order)
        if stage == 0:
            _weights(xy, own, width, contrast, top, keys, order, starts, sizes, weight, terms)
        elif stage == 1:
            for i in range(n):
                w[i] = weight[i]
        elif stage == 2:
            _trimmed(weight, order, starts, sizes, trim, w)
        else:
            _kept(own, weight, keys, order, starts, sizes, res, dist, r, radius, mpp, keep, w)
        if stage:
            _products(a, w, terms)
        for d in range(count):  # as np.add.reduceat sums: the first term, then the rest
            for col in range(2 if stage == 0 else 12):
                if sizes[d] == 0:
                    continue
                row, lo = terms[col], starts[d]
                sums[d, col] = row[lo]
                if sizes[d] > 1:
                    sums[d, col] += pairwise_sum(row, lo + 1, sizes[d] - 1)
        if stage == 0:
            _centred(xy, own, sums, sizes, mean, a)
            continue
        for d in range(count):
            centre[d, 0], centre[d, 1], r[d] = _circle(
                sums, d, w, starts[d], sizes[d], mean, lu, rhs
            )
    kept, gaps = _arcs(keep, own, theta, count)
    short = np.zeros(count, np.bool_)  # to be fitted with their known radius
    for d in range(count):
        short[d] = gaps[d] > MAX_ARC_GAP and kept[d] >= 6 and has_known[d]
        short[d] &= gaps[d] <= 2 * math.pi - MIN_ARC
    return centre, r, weight, keep, kept, gaps, np.nonzero(short)[0], sizes, starts


@jit
def _gathered(chosen, owner, angle, strength, spread):  # type: ignore[no-untyped-def]
    """The ``chosen`` edges' owners, angles, contrasts and widths (:func:`_circle_fits`'
    ``owner``, ``angle``, ``strength`` and ``spread`` at ``chosen``)."""
    n = len(chosen)
    own, theta = np.empty(n, np.intp), np.empty(n)
    contrast, width = np.empty(n), np.empty(n)
    for i in range(n):
        own[i], theta[i] = owner[chosen[i]], angle[chosen[i]]
        contrast[i], width[i] = strength[chosen[i]], spread[chosen[i]]
    return own, theta, contrast, width


@jit
def _runs(own, count):  # type: ignore[no-untyped-def]
    """Each of ``count`` discs' edge count and first edge, from the edges' owners ``own``
    (increasing)."""
    sizes, starts = np.empty(count, np.intp), np.empty(count, np.intp)
    for d in range(count):
        sizes[d], starts[d] = 0, 0
    for i in range(len(own)):
        sizes[own[i]] += 1
    for d in range(1, count):
        starts[d] = starts[d - 1] + sizes[d - 1]
    return sizes, starts


@jit
def _strongest(own, contrast, count):  # type: ignore[no-untyped-def]
    """Each of ``count`` discs' largest edge ``contrast``, at least 0 (NaN where any is NaN)."""
    top = np.empty(count)
    for d in range(count):
        top[d] = 0.0
    for i in range(len(own)):
        if contrast[i] > top[own[i]] or contrast[i] != contrast[i]:
            top[own[i]] = contrast[i]
    return top


@jit
def _off_circle(xy, own, centre, r, keys):  # type: ignore[no-untyped-def]
    """Into ``keys``: each point's distance from its disc's circle (infinite where NaN)."""
    for i in range(len(own)):
        d = own[i]
        keys[i] = abs(math.hypot(xy[i, 0] - centre[d, 0], xy[i, 1] - centre[d, 1]) - r[d])
        if keys[i] != keys[i]:
            keys[i] = math.inf


@jit
def _residuals(xy, own, centre, r, trim, dist, res, keys):  # type: ignore[no-untyped-def]
    """Into ``dist`` and ``res``: each point's distance from its disc's centre and from its
    circle; into ``keys``: the latter's size where ``trim``, else infinite."""
    for i in range(len(own)):
        d = own[i]
        dist[i] = math.hypot(xy[i, 0] - centre[d, 0], xy[i, 1] - centre[d, 1])
        res[i] = dist[i] - r[d]
        keys[i] = abs(res[i]) if trim[i] else math.inf


@jit
def _rank(keys, starts, sizes, order):  # type: ignore[no-untyped-def]
    """Into ``order``: the points' indices, each disc's ranked by their ``keys``, stably, NaN
    last (``np.lexsort``)."""
    for i in range(len(order)):
        order[i] = i
    for d in range(len(sizes)):
        for k in range(starts[d] + 1, starts[d] + sizes[d]):
            i, q = order[k], k - 1
            while q >= starts[d]:
                other = keys[order[q]]
                if not (other > keys[i] or (other != other and keys[i] == keys[i])):
                    break
                order[q + 1] = order[q]
                q -= 1
            order[q + 1] = i


@jit
def _weights(  # type: ignore[no-untyped-def]
    xy, own, width, contrast, top, keys, order, starts, sizes, weight, terms
):
    """Into ``weight``: each edge's, the square of its contrast over half its disc's strongest
    (``top``) times its sharpness, its disc's median width (``keys`` ranked by ``order``) over
    its own (at least 1e-3), each at most 1. Into ``terms``' first two rows: the points'
    coordinates."""
    for i in range(len(own)):
        d = own[i]
        floor = width[i] if width[i] >= 1e-3 or width[i] != width[i] else 1e-3
        sharp = keys[order[starts[d] + (sizes[d] - 1) // 2]] / floor
        if top[d] != 0.0:
            share = contrast[i] / (0.5 * top[d])
        else:
            share = math.inf if contrast[i] > 0 else -math.inf if contrast[i] < 0 else math.nan
        share = (1.0 if share >= 1.0 else share) * (1.0 if sharp >= 1.0 else sharp)
        weight[i] = share * share
        terms[0, i], terms[1, i] = xy[i, 0], xy[i, 1]


@jit
def _trimmed(weight, order, starts, sizes, trim, w):  # type: ignore[no-untyped-def]
    """Into ``trim``: whether each point is among the first three quarters (at least 6) of its
    disc's as ranked by ``order``; into ``w``: its weight where it is, else 0."""
    for d in range(len(sizes)):
        for k in range(sizes[d]):
            trim[order[starts[d] + k]] = k < max(6, 3 * sizes[d] // 4)
    for i in range(len(weight)):
        w[i] = weight[i] * (1.0 if trim[i] else 0.0)


@jit
def _kept(  # type: ignore[no-untyped-def]
    own, weight, keys, order, starts, sizes, res, dist, r, radius, mpp, keep, w
):
    """Into ``keep``: whether each point lies within 3 robust deviations (1.4826 times the
    median of its disc's ``keys`` ranked by ``order``; at least 0.75 px) of its circle
    (``res``) and not inside 70 % of the larger of the fitted radius ``r`` and the disc's
    ``radius`` px (``dist``); into ``w``: its weight where kept, else 0."""
    for i in range(len(own)):
        d = own[i]
        scale = 1.4826 * keys[order[starts[d] + (sizes[d] - 1) // 2]]
        bound, least = 3.0 * scale, radius[d] * mpp[d]
        if not (bound >= 0.75 * mpp[d] or bound != bound):
            bound = 0.75 * mpp[d]
        if r[d] >= least or r[d] != r[d]:
            least = r[d]
        keep[i] = abs(res[i]) <= bound and dist[i] >= 0.7 * least
        w[i] = weight[i] * (1.0 if keep[i] else 0.0)


@jit
def _products(a, w, terms):  # type: ignore[no-untyped-def]
    """Into ``terms``: each point's products ``a_j w a_k`` (j < 3, k < 4) of its row of ``a``
    and weight ``w``, row ``4 j + k``."""
    for i in range(len(w)):
        for j in range(3):
            aw = a[i, j] * w[i]
            for k in range(4):
                terms[4 * j + k, i] = aw * a[i, k]


@jit
def _centred(xy, own, sums, sizes, mean, a):  # type: ignore[no-untyped-def]
    """Into ``mean``: each disc's mean point (``sums``' first two columns over its ``sizes``
    points; left where it has none); into ``a``: each point's design row about its disc's mean
    (u, v, 1, u^2 + v^2)."""
    for d in range(len(sizes)):
        if sizes[d]:
            mean[d, 0], mean[d, 1] = sums[d, 0] / sizes[d], sums[d, 1] / sizes[d]
    for i in range(len(own)):
        a[i, 0], a[i, 1] = xy[i, 0] - mean[own[i], 0], xy[i, 1] - mean[own[i], 1]
        a[i, 2], a[i, 3] = 1.0, a[i, 0] * a[i, 0] + a[i, 1] * a[i, 1]


@jit
def _circle(sums, d, w, start, size, mean, lu, rhs):  # type: ignore[no-untyped-def]
    """Disc ``d``'s circle, its centre u, v and radius, from its row of ``sums`` (the normal
    equations' terms) by the normal equations for (2 centre, r^2 - |centre|^2) about its mean;
    NaN where fewer than 3 of its ``size`` edges from ``start`` weigh (``w``) anything, or the
    equations are singular. ``lu`` and ``rhs``: room to work in."""
    weighted = 0
    for i in range(start, start + size):
        if w[i] > 0:
            weighted += 1
    if weighted < 3:
        return math.nan, math.nan, math.nan
    eps = 1e-12 * ((sums[d, 0] + sums[d, 5]) + sums[d, 10])
    for j in range(3):
        rhs[j] = sums[d, 4 * j + 3]
        for k in range(3):
            lu[j, k] = sums[d, 4 * j + k] + eps * (1.0 if j == k else 0.0)
    if not solve(lu, rhs):
        return math.nan, math.nan, math.nan
    cu, cv = rhs[0] / 2, rhs[1] / 2
    q = rhs[2] + (cu * cu + cv * cv)
    return cu + mean[d, 0], cv + mean[d, 1], math.sqrt(q if q >= 0.0 or q != q else 0.0)


@jit
def _arcs(keep, own, theta, count):  # type: ignore[no-untyped-def]
    """Each of ``count`` discs' number of ``keep`` edges and the largest angle between
    neighbouring kept rays (``theta``, increasing in each disc's; a full turn where fewer than
    two are kept)."""
    kept = np.zeros(count)
    first, last = np.empty(count, np.intp), np.empty(count, np.intp)
    for d in range(count):
        first[d], last[d] = -1, -1
    for i in range(len(own)):
        if keep[i]:
            kept[own[i]] += 1.0
            if first[own[i]] < 0:
                first[own[i]] = i
            last[own[i]] = i
    gaps = np.empty(count)
    for d in range(count):
        gaps[d] = 2 * math.pi
    for d in range(count):
        if last[d] > first[d]:
            gaps[d] = theta[first[d]] + 2 * math.pi - theta[last[d]]
    before = -1
    for i in range(len(own)):
        if keep[i]:
            if before >= 0 and own[before] == own[i]:
                gap = theta[i] - theta[before]
                if not (gaps[own[i]] >= gap or gaps[own[i]] != gaps[own[i]]):
                    gaps[own[i]] = gap
            before = i
    return kept, gaps


@jit
def _stadium_fits(  # type: ignore[no-untyped-def]
    xy,
    weight,
    keep,
    starts,
    sizes,
    centre,
    r,
    kept,
    gaps,
    fixed,
    radius,
    mpp,
    along,
    moving,
    turned,
):
    """:func:`fit_discs`' smears: each circle's RMS distance (px) from its ``keep`` edges; then,
    in place of ``centre``, ``r`` and ``kept``, where a disc's circle leaves :data:`STADIUM_RMS`
    and it is ``moving`` (``along``: its direction), the stadium along it, or where that fits
    worse than the circle (a bounce has turned it since), along the best of ``turned``, if any
    fits better than the circle (:func:`_stadium_fit`). Returns the RMS distances, the discs
    left to :func:`_smear` (those whose equations were ill-conditioned) and those whose fits
    are good (as :func:`_good`).

    The stadium's centre, half length and radius by weighted Gauss-Newton on the edges'
    distances to it, twice, dropping edges off it by more than 3 robust deviations. The NumPy
    expressions this replaces summed each step's 4 x 4 normal equations by BLAS and solved them
    by ``lstsq`` (an SVD); here they are summed in order and solved by Gaussian elimination:
    the fits agree to rounding (1e-13 px), not to the bit. Not where the edges leave a
    combination of centre, length and radius unfixed, held only by the 1e-12 regularisation
    (edges at one end of the smear only, at neither, or along one side only): there the two
    solvers' rounding, amplified by 1e12, moved centres by up to 0.003 px; such a disc (a pivot
    under 1e-7 of the largest) is left to :func:`_smear`, which fits it as NumPy did."""
    rms = _circle_rms(xy, keep, starts, sizes, centre, r, kept, mpp)
    lu, rhs, res, ranked = np.empty((4, 4)), np.empty(4), np.empty(len(xy)), np.empty(len(xy))
    inner, best = np.empty(len(xy), np.bool_), np.empty(len(xy), np.bool_)
    redo = np.zeros(len(r), np.bool_)
    for d in range(len(r)):
        if not moving[d] or fixed[d] or kept[d] < 6 or rms[d] < STADIUM_RMS:
            continue
        redo[d] = _stadium_fit(
            d, xy, weight, starts, sizes, centre, r, kept, rms, mpp, along, turned,
            inner, best, res, ranked, lu, rhs,
        )  # fmt: skip
    good = np.empty(len(r), np.bool_)
    for d in range(len(r)):
        good[d] = kept[d] >= 6 and (gaps[d] <= MAX_ARC_GAP or fixed[d]) and abs(r[d]) < math.inf
        good[d] &= 0.5 * radius[d] * mpp[d] <= r[d] and r[d] <= 2.5 * radius[d] * mpp[d]
    return rms, np.nonzero(redo)[0], np.nonzero(good)[0]


@jit
def _circle_rms(xy, keep, starts, sizes, centre, r, kept, mpp):  # type: ignore[no-untyped-def]
    """Each disc's circle's RMS distance (px) from its ``keep`` edges (``kept`` of them)."""
    rms = np.zeros(len(r))
    for d in range(len(r)):
        for i in range(starts[d], starts[d] + sizes[d]):
            if keep[i]:
                q = math.hypot(xy[i, 0] - centre[d, 0], xy[i, 1] - centre[d, 1]) - r[d]
                rms[d] += q * q
        rms[d] = math.sqrt(rms[d] / max(kept[d], 1.0)) / mpp[d]
    return rms


@jit
def _stadium_fit(  # type: ignore[no-untyped-def]
    d, xy, weight, starts, sizes, centre, r, kept, rms, mpp, along, turned,
    inner, best, res, ranked, lu, rhs,
):  # fmt: skip
    """:func:`_stadium_fits` for disc ``d``: the stadium along ``along[d]``, or where that
    fits worse than the circle (``rms`` px), along each of ``turned`` (:func:`_stadium_along`);
    the best, where it fits better than the circle, into ``centre``, ``r``, ``rms`` and
    ``kept``. Whether its equations were ill-conditioned (then nothing is changed). ``inner``,
    ``best``, ``res``, ``ranked``, ``lu`` and ``rhs``: room to work in."""
    lo, m = starts[d], sizes[d]
    spread, bu, bv, br = math.inf, 0.0, 0.0, 0.0
    for turn in range(len(turned) + 1):
        way = along[d] if turn == 0 else turned[turn - 1]
        cu, cv, rr, other, ill = _stadium_along(
            xy, weight, lo, m, way, centre[d, 0], centre[d, 1], r[d], inner, res, ranked, lu, rhs
        )
        if ill:
            return True
        if turn == 0 or other < spread:
            spread, bu, bv, br = other, cu, cv, rr
            for i in range(m):
                best[i] = inner[i]
        if turn == 0 and not spread / mpp[d] >= rms[d]:
            break
    if spread / mpp[d] >= rms[d]:
        return False
    centre[d, 0], centre[d, 1], r[d], rms[d] = bu, bv, br, spread / mpp[d]
    kept[d] = 0.0
    for i in range(m):
        kept[d] += 1.0 if best[i] else 0.0
    return False


@jit
def _stadium_along(  # type: ignore[no-untyped-def]
    xy, weight, lo, m, way, cu, cv, r, inner, res, ranked, lu, rhs
):
    """The stadium along the unit vector ``way`` fitted to the ``m`` edges from ``lo`` of a disc
    whose circle has centre ``cu``, ``cv`` and radius ``r``: its centre, half length and radius
    by weighted Gauss-Newton on the edges' distances to it (:func:`_stadium_steps`), twice, the
    edges off it by more than 3 robust deviations (:func:`_stadium_bound`) dropped in between.
    Returns its centre, radius, the RMS distance of the edges kept (``inner``) from it, and
    whether its equations were ill-conditioned (then the rest is meaningless)."""
    h, rr = 0.25 * r, r
    for i in range(m):
        inner[i] = True
    for round_ in range(2):
        cu, cv, h, rr, ill = _stadium_steps(
            xy, weight, lo, m, way, cu, cv, h, rr, r, inner, res, lu, rhs
        )
        if ill:
            return cu, cv, rr, math.nan, True
        if round_ == 0:
            bound = _stadium_bound(res, m, ranked)
            for i in range(m):
                inner[i] = abs(res[i]) <= bound
    total, k = 0.0, 0
    for i in range(m):
        if inner[i]:
            total += res[i] * res[i]
            k += 1
    return cu, cv, rr, math.sqrt(total / k) if k else math.nan, False


@jit
def _stadium_steps(  # type: ignore[no-untyped-def]
    xy, weight, lo, m, way, cu, cv, h, rr, r, inner, res, lu, rhs
):
    """Up to 8 Gauss-Newton steps of a stadium's centre ``cu``, ``cv``, half length ``h`` and
    radius ``rr`` (:func:`_stadium_equations`), until each moves less than 1e-6 of ``r``; each
    edge's distance from the stadium the last step started from left in ``res``. Returns the
    new ones, and whether the equations were ill-conditioned (a pivot under 1e-7 of the
    largest: then where that step started)."""
    for _ in range(8):
        _stadium_equations(xy, weight, lo, m, way, cu, cv, h, rr, inner, res, lu, rhs)
        if not _eliminate(lu, rhs):
            return cu, cv, h, rr, True
        for i in range(3, -1, -1):
            for q in range(i + 1, 4):
                rhs[i] -= lu[i, q] * rhs[q]
            rhs[i] /= lu[i, i]
        cu, cv, h, rr = cu + rhs[0], cv + rhs[1], h + rhs[2], rr + rhs[3]
        if h < 0.0:
            h = 0.0
        small = True
        for p in range(4):
            small &= abs(rhs[p]) < 1e-6 * r
        if small:
            break
    return cu, cv, h, rr, False


@jit
def _stadium_equations(  # type: ignore[no-untyped-def]
    xy, weight, lo, m, way, cu, cv, h, rr, inner, res, lu, rhs
):
    """Into ``lu`` and ``rhs``: the 4 x 4 normal equations of a Gauss-Newton step of the stadium
    (centre ``cu``, ``cv``, half length ``h``, radius ``rr``, along ``way``) on the ``m`` edges
    from ``lo`` that are ``inner``, each weighted by its ``weight``, summed in order; into
    ``res``: each edge's distance from the stadium."""
    for p in range(4):
        rhs[p] = 0.0
        for q in range(4):
            lu[p, q] = 0.0
    for i in range(m):
        t = (xy[lo + i, 0] - cu) * way[0] + (xy[lo + i, 1] - cv) * way[1]
        ts = t if t != t or t > -h else -h  # np.clip(t, -h, h)
        ts = ts if ts != ts or ts < h else h
        ou, ov = xy[lo + i, 0] - (cu + ts * way[0]), xy[lo + i, 1] - (cv + ts * way[1])
        gap = math.hypot(ou, ov)
        gap = gap if gap >= 1e-12 or gap != gap else 1e-12
        uu, uv = ou / gap, ov / gap
        ends = (1.0 if t < 0 else -1.0) * (uu * way[0] + uv * way[1]) if abs(t) > h else 0.0
        jac = (-uu, -uv, ends, -1.0)
        res[i] = gap - rr
        wk = weight[lo + i] * (1.0 if inner[i] else 0.0)
        for p in range(4):
            for q in range(4):
                lu[p, q] += jac[p] * wk * jac[q]
            rhs[p] -= jac[p] * wk * res[i]


@jit
def _eliminate(lu, rhs):  # type: ignore[no-untyped-def]
    """``lu`` plus 1e-12 on its diagonal (4 x 4), and ``rhs``, reduced in place to an upper
    triangle by Gaussian elimination with partial pivoting. Whether it is well-conditioned
    (every pivot at least 1e-7 of the largest so far; else it stops there)."""
    least, most = math.inf, 0.0
    for j in range(4):
        lu[j, j] += 1e-12
    for j in range(4):
        p = j
        for i in range(j + 1, 4):
            if abs(lu[i, j]) > abs(lu[p, j]):
                p = i
        least, most = min(least, abs(lu[p, j])), max(most, abs(lu[p, j]))
        if not least >= 1e-7 * most:
            break
        for q in range(4):
            lu[j, q], lu[p, q] = lu[p, q], lu[j, q]
        rhs[j], rhs[p] = rhs[p], rhs[j]
        for i in range(j + 1, 4):
            f = lu[i, j] / lu[j, j]
            for q in range(j + 1, 4):
                lu[i, q] -= f * lu[j, q]
            rhs[i] -= f * rhs[j]
    return least >= 1e-7 * most


@jit
def _stadium_bound(res, m, ranked):  # type: ignore[no-untyped-def]
    """3 robust deviations (1.4826 times the median, at least 1e-9) of the sizes of the first
    ``m`` of ``res``: ``np.median``, the middle two's mean; NaN if any is. ``ranked``: room to
    sort them in."""
    for i in range(m):
        q = i - 1
        while q >= 0 and (ranked[q] > abs(res[i]) or ranked[q] != ranked[q]):
            ranked[q + 1] = ranked[q]
            q -= 1
        ranked[q + 1] = abs(res[i])
    if ranked[m - 1] != ranked[m - 1]:
        middle = math.nan
    elif m % 2:
        middle = ranked[m // 2]
    else:
        middle = (ranked[m // 2 - 1] + ranked[m // 2]) / 2.0
    bound = 3.0 * (1.4826 * middle)
    if bound < 1e-9:
        bound = 1e-9
    return bound


def _good(
    kept: np.ndarray,
    gaps: np.ndarray,
    fixed: np.ndarray,
    r: np.ndarray,
    radius: np.ndarray,
    mpp: np.ndarray,
) -> np.ndarray:
    """Which discs' fits are good: enough edges kept, of enough of the outline (or of a known
    radius), and a radius (m) of about the disc's (``radius`` px)."""
    good = (kept >= 6) & ((gaps <= MAX_ARC_GAP) | fixed) & np.isfinite(r)
    return good & (0.5 * radius * mpp <= r) & (r <= 2.5 * radius * mpp)


def _circle_of_radius(
    xy: np.ndarray, weight: np.ndarray, start: np.ndarray, r: float
) -> np.ndarray:
    """The centre of the circle of radius ``r`` through ``xy`` (weighted least squares on the
    distances to it, Gauss-Newton from ``start``)."""
    c = np.asarray(start, dtype=float).copy()
    for _ in range(8):
        d = xy - c
        dist = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-12)
        jac = -d / dist[:, None]
        res = dist - r
        jw = jac * weight[:, None]
        step = np.linalg.solve(jw.T @ jac + 1e-12 * np.eye(2), -(jw.T @ res))
        c += step
        if float(np.hypot(*step)) < 1e-6 * r:
            break
    return c


def _smear(
    xy: np.ndarray,
    weight: np.ndarray,
    start: np.ndarray,
    r: float,
    along: np.ndarray,
    rms: float,
    mpp: float,
) -> tuple[np.ndarray, float, float, int] | None:
    """:func:`_stadium_fits` for one disc, in NumPy (for one whose equations are
    ill-conditioned): the stadium's centre, radius, RMS distance (px) and kept edge count, if it
    fits better than the circle (``rms`` px)."""
    c, rd, spread, inner = _stadium(xy, weight, start, r, along)
    if spread / mpp >= rms:
        for a in np.arange(0.0, math.pi, math.pi / TURNS):
            other = _stadium(xy, weight, start, r, np.array([math.cos(a), math.sin(a)]))
            if other[2] < spread:
                c, rd, spread, inner = other
        if spread / mpp >= rms:
            return None
    return c, rd, spread / mpp, int(inner.sum())


def _stadium(
    xy: np.ndarray, weight: np.ndarray, start: np.ndarray, r: float, along: np.ndarray
) -> tuple[np.ndarray, float, float, np.ndarray]:
    """The stadium a disc of radius about ``r`` smears into moving along the unit vector
    ``along``: its centre (the disc's pose at mid-exposure) and radius, fitted to
    edge points ``xy`` by weighted least squares on their distance to it (Gauss-Newton from
    ``start``, twice, dropping points off it by more than 3 robust deviations); the RMS distance
    of the points kept from it; and the mask of them."""
    c = np.asarray(start, dtype=float).copy()
    h, rr = 0.25 * r, r
    keep = np.ones(len(xy), dtype=bool)
    for round_ in range(2):
        for _ in range(8):
            q = xy - c
            t = q @ along
            ends = np.abs(t) > h
            nearest = c + np.clip(t, -h, h)[:, None] * along
            off = xy - nearest
            dist = np.maximum(np.hypot(off[:, 0], off[:, 1]), 1e-12)
            unit = off / dist[:, None]
            jac = np.empty((len(xy), 4))
            jac[:, :2] = -unit
            jac[:, 2] = np.where(ends, -np.sign(t) * (unit @ along), 0.0)
            jac[:, 3] = -1.0
            res = dist - rr
            jw = jac * (weight * keep)[:, None]
            step = np.linalg.lstsq(jw.T @ jac + 1e-12 * np.eye(4), -(jw.T @ res), rcond=None)[0]
            c += step[:2]
            h, rr = max(h + step[2], 0.0), rr + step[3]
            if abs(step).max() < 1e-6 * r:
                break
        if round_ == 0:
            scale = 1.4826 * float(np.median(np.abs(res[keep])))
            keep = np.abs(res) <= max(3.0 * scale, 1e-9)
    return c, rr, float(np.sqrt(np.mean(res[keep] ** 2))), keep


def fit_discs(
    edges: Edges,
    radii: Sequence[float],
    calibration: Calibration,
    mpp: Sequence[float],
    known: Sequence[float | None],
    along: Sequence[np.ndarray | None] | None = None,
    *,
    halos: bool | Sequence[bool] = False,
) -> list[DiscFit | None]:
    """Each disc's centre from its :class:`Edges` (``owner``: the index into ``radii``), fitted
    by a circle on the plane (see the module docstring), all discs at once; ``mpp``: metres per
    pixel at each. ``None`` for a disc whose outline is not a disc's of about its radius (px)
    (too few edges, too little of the outline, another radius). ``known``: a disc's radius on
    the plane (m) as fitted in earlier frames, for an outline seen over too little of its circle
    to fit one freely (then fitted with that radius: ``fixed``). ``along``: for a disc moving
    fast enough to be smeared by the exposure, the unit direction of its motion on the plane;
    its outline is then fitted as the stadium the smear makes, whose centre is the disc's pose
    at mid-exposure (a circle fitted to a stadium's edges leans to whichever end kept more).

    An edge nearer the rays' origin than half the radius, or nearer the fitted centre than 70 %
    of the radius, is not the outline (a highlight's rim, where the rest of a lit side is as
    bright as the wall). Edges count by how surely they are placed: one of little contrast, or
    one that rises out of the noise slowly (a lit limb shows only where the sphere brightens
    inwards, inside the true outline), counts for less than a sharp one. The fit is robust: from
    the circle of the three quarters of a disc's edges that fit it best, edges further than 3
    robust standard deviations (at least 0.75 px) off it are dropped and the circle refitted.

    ``halos`` (for all discs or each): the video stores colour at a lower resolution than
    brightness (4:2:0, 4:2:2), so a coloured rim may bleed outwards: such a disc is fitted
    without its :data:`HALO` edges where it still fits without them (lit spheres of 13 px coded
    as H.264: the centre's bias 0.33 px at the 95th percentile with them, 0.23 px without),
    else with them (a side whose rim is faint throughout, a lit limb as bright as the wall, is
    all halos by that rule). Not for a long smear, whose ends fade out over its length."""
    count = len(radii)
    radius, mpp_ = np.asarray(radii, dtype=float), np.asarray(mpp, dtype=float)
    halo = np.zeros(len(edges.owner), dtype=bool) if edges.halo is None else edges.halo
    flagged = np.zeros(count, dtype=bool)
    flagged[:] = halos
    way, moving = np.zeros((count, 2)), np.zeros(count, dtype=bool)
    for d, a in enumerate(() if along is None else along):
        if a is not None:
            way[d], moving[d] = a, True
    common = (
        edges,
        radius,
        calibration,
        mpp_,
        np.array([math.nan if k is None else k for k in known], dtype=float),
        np.array([k is not None for k in known]),
        way,
        moving,
        along,
    )
    chosen, dropped = _chosen(edges.owner, edges.reach, halo, radius, flagged, False)
    fits = _fit_discs(chosen, *common)
    if dropped and None in fits:  # each disc is fitted on its own edges: refit only those
        failed = np.array([fit is None for fit in fits])
        again = _fit_discs(
            _chosen(edges.owner, edges.reach, halo, radius, failed, True)[0], *common
        )
        for d in np.nonzero(failed)[0]:
            fits[d] = again[d]
    return fits


@jit
def _chosen(owner, reach, halo, radius, discs, again):  # type: ignore[no-untyped-def]
    """The edges that :func:`fit_discs` fits to, those at least half the radius from the rays'
    origin: of every disc, less the :data:`HALO` edges of ``discs`` (a mask); or ``again``, only
    those of ``discs``, halos and all. And whether any halo is left out."""
    chosen, count, dropped = np.empty(len(owner), np.intp), 0, False
    for i in range(len(owner)):
        d = owner[i]
        if d < 0 or d >= len(radius):
            raise IndexError("an edge's owner is not one of the discs")
        out = (not discs[d]) if again else halo[i] and discs[d]
        dropped |= out and not again
        if reach[i] >= 0.5 * radius[d] and not out:
            chosen[count] = i
            count += 1
    return chosen[:count], dropped


def _fit_discs(
    chosen: np.ndarray,
    edges: Edges,
    radius: np.ndarray,
    calibration: Calibration,
    mpp: np.ndarray,
    known: np.ndarray,
    has_known: np.ndarray,
    way: np.ndarray,
    moving: np.ndarray,
    along: Sequence[np.ndarray | None] | None,
) -> list[DiscFit | None]:
    """:func:`fit_discs` on the ``chosen`` edges (``known``: NaN where not ``has_known``;
    ``way``: ``along``'s directions, where ``moving``)."""
    count = len(radius)
    if not len(chosen):
        return [None] * count
    xy = calibration.to_scene(edges.uv[chosen])
    centre, r, weight, keep, kept, gaps, short, sizes, starts = _circle_fits(
        xy, chosen, edges.owner, edges.theta, edges.contrast, edges.width, radius, mpp, has_known
    )
    fixed = np.zeros(count, dtype=bool)
    for d in short:  # too little of the outline: the radius known from earlier frames
        mine = slice(starts[d], starts[d] + sizes[d])
        on = keep[mine]
        centre[d] = _circle_of_radius(xy[mine][on], weight[mine][on], centre[d], known[d])
        r[d], fixed[d] = known[d], True
    rms, redo, good = _stadium_fits(
        xy,
        weight,
        keep,
        starts,
        sizes,
        centre,
        r,
        kept,
        gaps,
        fixed,
        radius,
        mpp,
        way,
        moving,
        _TURNED,
    )
    if len(redo):
        assert along is not None
        for d in redo:
            mine = slice(starts[d], starts[d] + sizes[d])
            smear = _smear(xy[mine], weight[mine], centre[d], r[d], along[d], rms[d], mpp[d])
            if smear is not None:
                centre[d], r[d], rms[d], kept[d] = smear
        good = np.nonzero(_good(kept, gaps, fixed, r, radius, mpp))[0]
    fits: list[DiscFit | None] = [None] * count
    if len(good):
        uv = calibration.to_image(centre[good])
        rl, kl, nl, sl, fl = r.tolist(), kept.tolist(), sizes.tolist(), rms.tolist(), fixed.tolist()
        for k, d in enumerate(good.tolist()):
            fits[d] = DiscFit(centre[d], uv[k], rl[d], kl[d] / nl[d], sl[d], fl[d])
    return fits


def fit_disc(
    edges: Edges,
    radius: float,
    calibration: Calibration,
    mpp: float,
    known: float | None = None,
) -> DiscFit | None:
    """:func:`fit_discs` for the edges of one disc."""
    one = Edges(edges.uv, edges.theta, edges.contrast, edges.width, edges.reach,
                np.zeros(len(edges.uv), dtype=np.intp), edges.halo)  # fmt: skip
    return fit_discs(one, [radius], calibration, [mpp], [known])[0]
