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

from physbench.video.compiled import jit

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
    edge each finds: :class:`Edges`' arrays, for the rays inside their window that find one.

    Along a ray, samples every :data:`STEP` px from 70 % of the radius less :data:`INNER` to
    the reach, read bilinearly (clamped to the window). The outermost run of :data:`RUN`
    samples at or above ``low`` ends at the edge: a speck of the wall's texture the light does
    not quite match, a pixel or so past the rim, is not it. The edge's inner level is where the
    profile stops falling steeply, walking in from its steepest point near the threshold
    crossing: the rim's own brightness, not the shading further in (a lit sphere brightens
    inwards from a limb as dark as the wall). An edge whose inner level is under ``low`` over
    the outside is placed by the threshold, not by its half-way point: it adds nothing."""
    n = 0
    for d in range(len(discs)):
        n += int(discs[d, 4])
    radius = np.empty(n)
    start = np.empty(n)
    owner = np.empty(n, np.intp)
    ray = 0
    for d in range(len(discs)):
        for _ in range(int(discs[d, 4])):
            radius[ray] = discs[d, 2]
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
    p = np.empty(m)
    s = np.empty(m, np.float32)
    near = np.empty(m + 2)
    outer = max(1, round(2.0 / STEP))
    count = 0
    for j in range(n):
        d = owner[j]
        win = int(discs[d, 6])
        h, w = shape[win, 0], shape[win, 1]
        cu, cv = discs[d, 0] - origin[win, 1], discs[d, 1] - origin[win, 0]
        du, dv = directions[j, 1], directions[j, 2]
        length = discs[d, 3] - start[j]
        steps = min(int(np.floor(length / STEP)) + 1, m)
        # Rays are straight: inside the window where both their ends are.
        inside = True
        for far in (start[j], start[j] + STEP * (steps - 1)):
            eu, ev = cu + du * far, cv + dv * far
            inside &= eu >= 0 and eu <= w - 1 and ev >= 0 and ev <= h - 1
        top_row, top_col = np.float32(h - 1.001), np.float32(w - 1.001)
        fu, fv, fdu, fdv = np.float32(cu), np.float32(cv), np.float32(du), np.float32(dv)
        b = base[win]
        for i in range(m):
            s[i] = np.float32(start[j] + STEP * i)
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
        last = -1
        for i in range(min(steps, m) - 1, RUN - 2, -1):
            run = True
            for q in range(i - RUN + 1, i + 1):
                run &= p[q] >= low
            if run:
                last = i
                break
        good = inside and last >= 0 and last < steps - 1
        if last < 0:
            last = m - 1
        k = int(discs[d, 5])
        for t in range(k + 2):  # inside out
            near[t] = p[min(max(last - k + t, 0), m - 1)]
        # The steepest fall over one step out of the last `outer` (the first of equals).
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
        if not good:
            continue
        peak = near[0]
        for t in range(1, k + 2):
            peak = max(peak, near[t])
        uv[count, 0] = discs[d, 0] + du * dist
        uv[count, 1] = discs[d, 1] + dv * dist
        theta[count] = directions[j, 0]
        contrast[count] = inner - outside
        width[count] = np.float64(s[last] + np.float32(0.5 * STEP)) - dist
        reach[count] = dist
        kept[count] = d
        halo[count] = inner - outside < HALO * (peak - outside)
        count += 1
    return (uv[:count], theta[:count], contrast[:count], width[:count], reach[:count],
            kept[:count], halo[:count])  # fmt: skip


@dataclass(frozen=True)
class _Groups:
    """Points in ``count`` contiguous groups (``owner`` increasing): each group's ``sizes`` and
    the index of its first point (``starts``)."""

    owner: np.ndarray
    count: int
    sizes: np.ndarray
    starts: np.ndarray

    @classmethod
    def of(cls, owner: np.ndarray, count: int) -> _Groups:
        sizes = np.bincount(owner, minlength=count)
        return cls(owner, count, sizes, np.cumsum(sizes) - sizes)

    def rank(self, values: np.ndarray) -> np.ndarray:
        """Each value's rank (0: smallest) within its group."""
        order = np.lexsort((values, self.owner))
        rank = np.empty(len(values), dtype=np.intp)
        rank[order] = np.arange(len(values)) - self.starts[self.owner[order]]
        return rank

    def median(self, values: np.ndarray) -> np.ndarray:
        """Each group's (lower) median of ``values`` (inf values sort last); 0 if empty."""
        order = np.lexsort((values, self.owner))
        at = np.clip(self.starts + (self.sizes - 1) // 2, 0, len(values) - 1)
        return np.where(self.sizes > 0, values[order][at], 0.0)

    def total(self, values: np.ndarray) -> np.ndarray:
        return np.bincount(self.owner, values, self.count)


_ROW, _COLUMN = np.repeat(np.arange(3), 4), np.tile(np.arange(4), 3)
_EYE = np.eye(3)


@dataclass(frozen=True)
class _Centred:
    """Points ``xy`` ``(n, 2)`` about their group's mean, as the algebraic circle fit's normal
    equations use them: built once for the weightings :func:`fit_discs` tries."""

    mean: np.ndarray  # (count, 2)
    rows: np.ndarray  # (n, 12): a_i of the products a_i a_j (i < 3, j < 4)
    columns: np.ndarray  # (n, 12): a_j

    @classmethod
    def of(cls, xy: np.ndarray, g: _Groups) -> _Centred:
        some = g.sizes > 0
        mean = np.zeros((g.count, 2))
        mean[some] = np.add.reduceat(xy, g.starts[some], axis=0) / g.sizes[some, None]
        a = np.ones((len(xy), 4))
        a[:, :2] = xy - mean[g.owner]
        a[:, 3] = a[:, 0] ** 2 + a[:, 1] ** 2
        return cls(mean, a[:, _ROW], a[:, _COLUMN])


def _circles(points: _Centred, weight: np.ndarray, g: _Groups) -> tuple[np.ndarray, np.ndarray]:
    """Each group's weighted least-squares circle through its ``points`` (algebraic: Kasa, by
    its normal equations), as centres ``(count, 2)`` and radii ``(count,)``; NaN for a group
    without three weighted points."""
    some = g.sizes > 0
    # The products a_i a_j (weighted, i < 3, j < 4) as 12 columns: an (n, 3, 4) broadcast costs
    # several times as much for the same values.
    outer = points.rows * weight[:, None] * points.columns  # (n, 12)
    m = np.zeros((g.count, 3, 4))
    m[some] = np.add.reduceat(outer, g.starts[some], axis=0).reshape(-1, 3, 4)
    sol = np.full((g.count, 3), np.nan)
    ok = g.total(weight > 0) >= 3
    if ok.any():
        lhs = m[ok, :, :3]
        lhs += 1e-12 * np.trace(lhs, axis1=1, axis2=2)[:, None, None] * _EYE
        sol[ok] = np.linalg.solve(lhs, m[ok, :, 3:])[:, :, 0]
    c = sol[:, :2] / 2
    r = np.sqrt(np.maximum(sol[:, 2] + (c * c).sum(axis=1), 0.0))
    return c + points.mean, r


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


def _arc_gaps(theta: np.ndarray, g: _Groups) -> np.ndarray:
    """Each group's largest angle (rad) between neighbouring rays ``theta`` (increasing within
    a group) round the circle; 2 pi for a group of fewer than two."""
    gaps = np.full(g.count, 2 * math.pi)
    full = g.sizes >= 2
    if full.any():
        ends = g.starts + g.sizes - 1
        gaps[full] = theta[g.starts[full]] + 2 * math.pi - theta[ends[full]]
        same = g.owner[1:] == g.owner[:-1]
        np.maximum.at(gaps, g.owner[1:][same], np.diff(theta)[same])
    return gaps


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
    per = np.broadcast_to(np.asarray(halos, dtype=bool), (len(radii),))
    if edges.halo is None or not (edges.halo & per[edges.owner]).any():
        return _fit_discs(edges, radii, calibration, mpp, known, along)
    fits = _fit_discs(
        edges.select(~(edges.halo & per[edges.owner])), radii, calibration, mpp, known, along
    )
    failed = [d for d, fit in enumerate(fits) if fit is None]
    if failed:  # each disc is fitted on its own edges: refit only those
        mine = edges.select(np.isin(edges.owner, failed))
        again = _fit_discs(mine, radii, calibration, mpp, known, along)
        for d in failed:
            fits[d] = again[d]
    return fits


def _fit_discs(
    edges: Edges,
    radii: Sequence[float],
    calibration: Calibration,
    mpp: Sequence[float],
    known: Sequence[float | None],
    along: Sequence[np.ndarray | None] | None,
) -> list[DiscFit | None]:
    """:func:`fit_discs` on all of ``edges``."""
    count = len(radii)
    radius = np.asarray(radii, dtype=float)
    mpp_ = np.asarray(mpp, dtype=float)
    e = edges.select(edges.reach >= 0.5 * radius[edges.owner])
    if not len(e.owner):
        return [None] * count
    g = _Groups.of(e.owner, count)
    own = e.owner
    xy = calibration.to_scene(e.uv)
    top = np.zeros(count)
    np.maximum.at(top, own, e.contrast)
    sharp = np.minimum(1.0, g.median(e.width)[own] / np.maximum(e.width, 1e-3))
    weight = (np.minimum(1.0, e.contrast / (0.5 * top[own])) * sharp) ** 2
    points = _Centred.of(xy, g)
    centre, r = _circles(points, weight, g)
    res = np.abs(np.hypot(*(xy - centre[own]).T) - r[own])
    # Least trimmed squares: the three quarters nearest the circle (a highlight's rim is a tight
    # cluster of edges inside the outline, which a fit to all of them leans to).
    trim = g.rank(np.where(np.isnan(res), np.inf, res)) < np.maximum(6, 3 * g.sizes // 4)[own]
    centre, r = _circles(points, weight * trim, g)
    dist = np.hypot(*(xy - centre[own]).T)
    res = dist - r[own]
    scale = 1.4826 * g.median(np.where(trim, np.abs(res), np.inf))
    bound = np.maximum(3.0 * scale, 0.75 * mpp_)
    keep = (np.abs(res) <= bound[own]) & (dist >= 0.7 * np.maximum(r, radius * mpp_)[own])
    centre, r = _circles(points, weight * keep, g)
    kept = g.total(keep)
    gaps = _arc_gaps(e.theta[keep], _Groups.of(own[keep], count))
    fixed = np.zeros(count, dtype=bool)
    for d in np.nonzero((gaps > MAX_ARC_GAP) & (kept >= 6))[0]:
        if known[d] is not None and gaps[d] <= 2 * math.pi - MIN_ARC:
            mine = keep & (own == d)
            centre[d] = _circle_of_radius(xy[mine], weight[mine], centre[d], known[d])
            r[d], fixed[d] = known[d], True
    res = np.hypot(*(xy - centre[own]).T) - r[own]
    rms = np.sqrt(g.total(np.where(keep, res * res, 0.0)) / np.maximum(kept, 1)) / mpp_
    for d in range(count):
        # A stadium where the circle does not fit its edges: a smear, not a still disc.
        if along is None or along[d] is None or fixed[d] or kept[d] < 6 or rms[d] < STADIUM_RMS:
            continue
        mine = own == d
        c, rd, spread, inner = _stadium(xy[mine], weight[mine], centre[d], r[d], along[d])
        if spread / mpp_[d] >= rms[d]:
            # Not a smear along the track's last direction of motion (a bounce has turned it
            # since): the direction that fits the edges best, if any fits better than a circle.
            for a in np.arange(0.0, math.pi, math.pi / TURNS):
                way = np.array([math.cos(a), math.sin(a)])
                other = _stadium(xy[mine], weight[mine], centre[d], r[d], way)
                if other[2] < spread:
                    c, rd, spread, inner = other
            if spread / mpp_[d] >= rms[d]:
                continue
        centre[d], r[d], rms[d] = c, rd, spread / mpp_[d]
        kept[d] = inner.sum()
    good = (kept >= 6) & ((gaps <= MAX_ARC_GAP) | fixed) & np.isfinite(r)
    good &= (0.5 * radius * mpp_ <= r) & (r <= 2.5 * radius * mpp_)
    fits: list[DiscFit | None] = [None] * count
    if good.any():
        uv = calibration.to_image(centre[good])
        for k, d in enumerate(np.nonzero(good)[0]):
            share = float(kept[d] / g.sizes[d])
            fits[d] = DiscFit(centre[d], uv[k], float(r[d]), share, float(rms[d]), bool(fixed[d]))
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
