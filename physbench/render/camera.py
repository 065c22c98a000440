"""A simulated camera: films a scene the way a real one would, for testing the video path
(tracking, calibration, segmentation) on realistic footage. Frames are ``rgb`` images.

Model, in the order light goes through it:

- **Scene**: the plane ``z = 0`` holding the scene's ``(x, y)`` metres, ``y`` up. A wall texture
  (or clutter, or plain grey) and the static geometry are painted on it; bodies are shaded in a
  distinct saturated colour each (a lit sphere for circles, a gentle gradient for polygons).
- **Pose**: a pinhole camera aimed at the centre of ``scene.bounds``, turned by ``tilt``, ``yaw``
  and ``roll``, at the distance where the bounds plus a ``margin`` just fill the view. The scene
  maps to the undistorted image by the homography ``K [r1 r2 t]``. A steep view may see past
  the plane's horizon: those pixels are dark (and textures alias near it, as they would).
- **Lens**: Brown's radial distortion ``k1``, ``k2`` about the image centre, normalised by the
  focal length in pixels (:class:`physbench.calibration.Lens`).
- **Exposure**: the shutter is open for ``shutter`` of the frame interval, centred on the frame
  time; ``subframes`` poses (from each body's pose and velocity) are averaged: motion blur that
  keeps the blob's centroid at the frame-time position.
- **Light**: uneven illumination (a gradient and a vignette, amplitude ``light``) and a light
  that changes over time (``flicker``), both multiplicative.
- **Sensor**: Gaussian noise of std ``noise``, quantised to 8 bits; optionally a real H.264
  encode and decode (``bitrate`` or ``crf``), so the frames are what a video file would hold.

Pixel convention (that of :mod:`physbench.calibration`): ``u`` right, ``v`` down, pixel
centres at integer coordinates. :meth:`CameraRenderer.calibration` is the true map.

Every pixel's scene coordinates, the background and the light field are computed once per scene
bounds, statics and resolution (the camera does not move); each body is evaluated only inside its
image bounding box over the exposure, for all sub-frames at once. A 30-frame 640x480 clip of 3-7
bodies with 8 sub-frames takes about a second on one core.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.calibration import Calibration, Lens
from physbench.codec import h264_round_trip
from physbench.hookspecs import hookimpl
from physbench.render.base import Camera, RenderError, check_view
from physbench.scene import Circle, Segment

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: Background kinds (see :class:`CameraRenderer`).
BACKGROUNDS = ("texture", "clutter", "plain")
#: Body colours (linear RGB in [0, 1]) by body index; more bodies get golden-ratio hues.
PALETTE = (
    (0.86, 0.12, 0.10),
    (0.10, 0.32, 0.92),
    (0.10, 0.70, 0.20),
    (0.96, 0.80, 0.08),
    (0.80, 0.14, 0.76),
    (0.05, 0.74, 0.86),
    (0.98, 0.48, 0.04),
    (0.46, 0.20, 0.86),
)
#: Colour of static geometry (walls, floors, ramps): part of the background.
STATIC_COLOUR = (0.32, 0.30, 0.28)
#: Unit vector towards the light that shades bodies: upper left, in front of the plane.
_LIGHT = np.array([-0.45, 0.55, 0.70]) / np.linalg.norm([-0.45, 0.55, 0.70])
#: Half-way between the light and the viewer (straight out of the plane): the highlight's normal.
_HALF = (_LIGHT + np.array([0.0, 0.0, 1.0])) / np.linalg.norm(_LIGHT + np.array([0.0, 0.0, 1.0]))
#: Views (pixel geometry, background, light) kept per renderer instance.
_CACHE_SIZE = 4
#: The view must not look along the plane: largest angle between the optical axis and the
#: plane's normal (degrees).
MAX_OBLIQUE = 85.0


def _number(name: str, value: object, low: float, high: float, *, open_: bool = False) -> float:
    bad = isinstance(value, bool) or not isinstance(value, int | float | np.number)
    if not bad:
        v = float(value)  # type: ignore[arg-type]
        bad = not math.isfinite(v) or (not (low < v < high) if open_ else not (low <= v <= high))
    if bad:
        span = f"({low:g}, {high:g})" if open_ else f"[{low:g}, {high:g}]"
        raise RenderError(f"{name} = {value!r}: expected a number in {span}")
    return float(value)  # type: ignore[arg-type]


def _whole(name: str, value: object, low: int, high: int) -> int:
    if (
        isinstance(value, bool)
        or not isinstance(value, int | np.integer)
        or not low <= value <= high
    ):
        raise RenderError(f"{name} = {value!r}: expected a whole number in [{low}, {high}]")
    return int(value)


def _rotation(axis: int, deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    i, j = [k for k in range(3) if k != axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def _hash(i: np.ndarray, j: np.ndarray, seed: int, salt: int = 0) -> np.ndarray:
    """Uniform [0, 1) from integer lattice coordinates (splitmix64 finaliser): the same value for
    the same cell whatever the pose or resolution."""
    with np.errstate(over="ignore"):
        h = i.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15)
        h ^= j.astype(np.uint64) * np.uint64(0xC2B2AE3D27D4EB4F)
        h ^= np.uint64((seed * 0x165667B1 + salt * 0x27D4EB2F) & 0xFFFFFFFFFFFFFFFF)
        h ^= h >> np.uint64(30)
        h *= np.uint64(0xBF58476D1CE4E5B9)
        h ^= h >> np.uint64(27)
        h *= np.uint64(0x94D049BB133111EB)
        h ^= h >> np.uint64(31)
    return (h >> np.uint64(11)).astype(np.float64) / float(1 << 53)


def _value_noise(x: np.ndarray, y: np.ndarray, scale: float, seed: int, salt: int) -> np.ndarray:
    """Smooth noise in [0, 1] with features ``scale`` metres across."""
    fx, fy = x / scale, y / scale
    i, j = np.floor(fx), np.floor(fy)
    tx, ty = fx - i, fy - j
    tx, ty = tx * tx * (3 - 2 * tx), ty * ty * (3 - 2 * ty)
    i, j = i.astype(np.int64), j.astype(np.int64)
    a, b = _hash(i, j, seed, salt), _hash(i + 1, j, seed, salt)
    c, d = _hash(i, j + 1, seed, salt), _hash(i + 1, j + 1, seed, salt)
    return (a + (b - a) * tx) * (1 - ty) + (c + (d - c) * tx) * ty


def body_colour(index: int) -> tuple[float, float, float]:
    """The colour of body ``index`` (scene order)."""
    if index < len(PALETTE):
        return PALETTE[index]
    import colorsys

    return colorsys.hsv_to_rgb((0.13 + index * 0.618034) % 1.0, 0.85, 0.9)


class _View:
    """Everything that depends only on the camera, the scene's bounds and statics and the image
    size: the pose, every pixel's scene point and footprint, the background and the light."""

    def __init__(self, cam: CameraRenderer, scene: Scene, hw: tuple[int, int]) -> None:
        self.h, self.w = h, w = hw
        self.fov_deg = cam.fov
        self.f = (w / 2) / math.tan(math.radians(cam.fov) / 2)
        self.centre = ((w - 1) / 2, (h - 1) / 2)
        self.k = np.array([[self.f, 0, self.centre[0]], [0, self.f, self.centre[1]], [0, 0, 1]])
        self.lens = (
            Lens(cam.k1, cam.k2, self.centre, self.f) if cam.k1 != 0 or cam.k2 != 0 else None
        )
        self._check_lens()
        # scene -> undistorted pixels
        self.to_image_h = self._pose(cam, scene.bounds if cam.view is None else cam.view)
        self.to_scene_h = np.linalg.inv(self.to_image_h)
        self.to_scene_h /= self.to_scene_h[2, 2]
        self._pixels()
        self.background = _background(cam, scene, self)
        self.light = _light(cam, self)

    # ------------------------------------------------------------------ geometry

    def _check_lens(self) -> None:
        if self.lens is None:
            return
        # Distortion r -> r (1 + k1 r^2 + k2 r^4) must grow (no folding) until it reaches the
        # image's corners: every pixel then sees exactly one point of the plane.
        corner = math.hypot(*self.centre) / self.f + 1 / self.f
        r = np.linspace(0.0, 4 * corner, 4001)
        k1, k2 = self.lens.k1, self.lens.k2
        grows = 1 + 3 * k1 * r**2 + 5 * k2 * r**4 > 0.05
        reach = r * (1 + k1 * r**2 + k2 * r**4) >= corner
        folds = np.argmin(grows) if not grows.all() else len(r)
        if not reach[:folds].any():
            raise RenderError(
                f"k1 = {k1!r}, k2 = {k2!r}: with fov = {self.fov_deg:g} the distortion folds the "
                "image over before its corners; use a smaller |k1|, |k2| or field of view"
            )

    def project(self, xy: np.ndarray, h: np.ndarray | None = None) -> np.ndarray:
        """Image pixels (distorted) of scene points ``(..., 2)``."""
        h = self.to_image_h if h is None else h
        q = xy @ h[:, :2].T + h[:, 2]
        uv = q[..., :2] / q[..., 2:3]
        return uv if self.lens is None else self.lens.distort(uv)

    def _pose(self, cam: CameraRenderer, bounds: tuple[float, float, float, float]) -> np.ndarray:
        xmin, ymin, xmax, ymax = bounds
        target = np.array([(xmin + xmax) / 2, (ymin + ymax) / 2, 0.0])
        mx, my = cam.margin * (xmax - xmin), cam.margin * (ymax - ymin)
        # Camera axes in the scene (columns): x right, y down (scene -y), z into the plane (-z);
        # then the turns about the camera's own axes.
        r_wc = (
            np.diag([1.0, -1.0, -1.0])
            @ _rotation(1, cam.yaw)
            @ _rotation(0, -cam.tilt)
            @ _rotation(2, cam.roll)
        )
        axis = r_wc[:, 2]
        if -axis[2] <= math.cos(math.radians(MAX_OBLIQUE)):
            raise RenderError(
                f"tilt = {cam.tilt!r}, yaw = {cam.yaw!r}: the camera looks along the scene's "
                f"plane or away from it; keep the view within {MAX_OBLIQUE:g} degrees of facing it"
            )
        r_cw = r_wc.T
        # The outline of the bounds plus margin, sampled densely (a distorted edge bulges).
        s = np.linspace(0.0, 1.0, 33)[:-1]
        x0, x1, y0, y1 = xmin - mx, xmax + mx, ymin - my, ymax + my
        edge = np.concatenate(
            [
                np.stack([x0 + (x1 - x0) * s, np.full_like(s, y0)], 1),
                np.stack([np.full_like(s, x1), y0 + (y1 - y0) * s], 1),
                np.stack([x1 - (x1 - x0) * s, np.full_like(s, y1)], 1),
                np.stack([np.full_like(s, x0), y1 - (y1 - y0) * s], 1),
            ]
        )
        q = (np.column_stack([edge, np.zeros(len(edge))]) - target) @ r_cw.T
        hw, hh = self.w / 2, self.h / 2  # from the centre to the image's edge, u = -0.5 or W - 0.5
        # The closest distance with every outline point inside the undistorted image:
        # f |q_x| / (q_z + d) <= half width, and the same for y.
        size = max(x1 - x0, y1 - y0)
        d = float(
            max(
                (self.f * np.abs(q[:, 0]) / hw - q[:, 2]).max(),
                (self.f * np.abs(q[:, 1]) / hh - q[:, 2]).max(),
                (1e-3 * size - q[:, 2]).max(),
            )
        )
        d *= 1 + 1e-9  # the outline exactly on the edge could round out of it
        for _ in range(400):
            centre = target - d * axis
            t = -r_cw @ centre
            g = self.k @ np.column_stack([r_cw[:, 0], r_cw[:, 1], t])
            g /= g[2, 2]
            uv = self.project(edge, g)
            if (
                uv[:, 0].min() >= -0.5
                and uv[:, 0].max() <= self.w - 0.5
                and uv[:, 1].min() >= -0.5
                and uv[:, 1].max() <= self.h - 0.5
            ):
                return g
            d *= 1.01  # only lens distortion pushes the outline out: back off until it fits
        raise RenderError(
            f"k1 = {cam.k1!r}, k2 = {cam.k2!r}: the distorted scene does not fit in the image"
        )

    def _pixels(self) -> None:
        """Scene point and footprint (metres per pixel) of every pixel centre."""
        v, u = np.mgrid[0 : self.h, 0 : self.w].astype(np.float64)
        uv = np.stack([u, v], axis=-1)
        if self.lens is not None:
            uv = self.lens.undistort(uv)
        hs = self.to_scene_h
        q = uv @ hs[:, :2].T + hs[:, 2]
        # Pixels whose ray misses the plane (above its horizon) keep w of the other sign.
        w0 = (hs @ [self.centre[0], self.centre[1], 1.0])[2]
        self.valid = q[..., 2] * np.sign(w0) > 1e-12
        wq = np.where(self.valid, q[..., 2], np.sign(w0))
        self.x = np.where(self.valid, q[..., 0] / wq, 0.0)
        self.y = np.where(self.valid, q[..., 1] / wq, 0.0)
        dxdv, dxdu = np.gradient(self.x) if min(self.h, self.w) > 1 else (0.0, 0.0)
        dydv, dydu = np.gradient(self.y) if min(self.h, self.w) > 1 else (0.0, 0.0)
        area = np.abs(np.asarray(dxdu * dydv - dxdv * dydu, dtype=np.float64))
        if min(self.h, self.w) <= 1:  # a one-pixel row or column: from the homography's scale
            area = np.full((self.h, self.w), abs(np.linalg.det(hs[:2, :2])))
        foot = np.sqrt(area)
        self.foot = np.where(self.valid, np.maximum(foot, 1e-9), 1e9)
        self.x32, self.y32 = self.x.astype(np.float32), self.y.astype(np.float32)
        self.foot32 = self.foot.astype(np.float32)

    def box(self, centres: np.ndarray, radius: float) -> tuple[int, int, int, int] | None:
        """Pixel rows and columns ``(r0, r1, c0, c1)`` holding discs of ``radius`` around scene
        points ``centres`` (N, 2), or ``None`` when they miss the image."""
        k = 16
        a = np.arange(k) * (2 * math.pi / k)
        ring = np.stack([np.cos(a), np.sin(a)], 1) * (radius / math.cos(math.pi / k))
        pts = (centres[:, None, :] + ring[None]).reshape(-1, 2)
        pts = np.concatenate([pts, centres])
        hs = self.to_image_h
        q = pts @ hs[:, :2].T + hs[:, 2]
        if (q[:, 2] <= 0).any():  # part of the disc lies beyond the horizon: take everything
            return 0, self.h, 0, self.w
        uv = self.project(pts)
        c0 = max(0, math.floor(uv[:, 0].min()) - 2)
        c1 = min(self.w, math.ceil(uv[:, 0].max()) + 3)
        r0 = max(0, math.floor(uv[:, 1].min()) - 2)
        r1 = min(self.h, math.ceil(uv[:, 1].max()) + 3)
        if c0 >= c1 or r0 >= r1:
            return None
        return r0, r1, c0, c1


def _coverage(sd: np.ndarray, foot: np.ndarray) -> np.ndarray:
    """Anti-aliased pixel coverage from the signed distance (metres) and the pixel footprint."""
    return np.clip(np.float32(0.5) - sd / foot, 0.0, 1.0)


def _segment_distance(
    x: np.ndarray, y: np.ndarray, a: Sequence[float], b: Sequence[float]
) -> np.ndarray:
    """Distance (metres) from scene points to the segment ``a``-``b``."""
    ax, ay = a
    ex, ey = b[0] - ax, b[1] - ay
    ll = ex * ex + ey * ey
    t = np.clip(((x - ax) * ex + (y - ay) * ey) / ll, 0.0, 1.0) if ll > 0 else 0.0
    return np.hypot(x - ax - t * ex, y - ay - t * ey)


def _polygon_sd(x: np.ndarray, y: np.ndarray, points: Sequence[Sequence[float]]) -> np.ndarray:
    """Signed distance (max of the edges' half-planes: exact along edges) to a convex polygon
    with counter-clockwise vertices."""
    pts = np.asarray(points, dtype=float)
    sd = None
    for k in range(len(pts)):
        (x0, y0), (x1, y1) = pts[k], pts[(k + 1) % len(pts)]
        ln = math.hypot(x1 - x0, y1 - y0)
        if ln == 0:
            continue
        nx, ny = (y1 - y0) / ln, -(x1 - x0) / ln
        e = (x - x0) * nx + (y - y0) * ny
        sd = e if sd is None else np.maximum(sd, e)
    assert sd is not None
    return sd


def _paint(img: np.ndarray, cov: np.ndarray, colour: np.ndarray) -> None:
    """``img`` (H, W, 3) covered by ``colour`` (3,) or (H, W, 3) with coverage ``cov``."""
    img *= (1 - cov)[..., None]
    img += cov[..., None] * colour


def _background(cam: CameraRenderer, scene: Scene, view: _View) -> np.ndarray:
    """The empty scene: wall, clutter or grey, then the static geometry; (H, W, 3) float32."""
    x, y, foot = view.x, view.y, view.foot
    xmin, ymin, xmax, ymax = scene.bounds
    size = max(xmax - xmin, ymax - ymin)
    seed = cam.seed
    img = np.empty((view.h, view.w, 3), np.float64)
    if cam.background == "plain":
        img[...] = 0.55
    elif cam.background == "texture":
        # Stone tiles in a running bond, each of its own tone, with mortar and smooth stains.
        bw, bh = size / 10, size / 20
        row = np.floor(y / bh)
        fx = x / bw + 0.5 * (row % 2)
        col = np.floor(fx)
        tone = _hash(col.astype(np.int64), row.astype(np.int64), seed, 1)
        hue = _hash(col.astype(np.int64), row.astype(np.int64), seed, 2)
        base = np.array([0.66, 0.61, 0.53])
        img[...] = base * (0.82 + 0.22 * tone)[..., None]
        img[..., 0] += 0.05 * (hue - 0.5)
        img[..., 2] -= 0.05 * (hue - 0.5)
        fy = y / bh - row
        d = np.minimum(bw * np.minimum(fx - col, col + 1 - fx), bh * np.minimum(fy, 1 - fy))
        mortar = 0.012 * size
        _paint(img, _coverage(d - mortar / 2, foot), np.array([0.80, 0.79, 0.75]))
        stain = 0.6 * _value_noise(x, y, size / 3, seed, 3) + 0.4 * _value_noise(
            x, y, size / 9, seed, 4
        )
        img *= (0.8 + 0.35 * stain)[..., None]
    else:  # clutter: static shapes of many colours on a mottled light wall
        img[...] = 0.62 + 0.12 * (_value_noise(x, y, size / 4, seed, 5) - 0.5)[..., None]
        rng = np.random.default_rng([seed, 7])
        span = 0.75 * size
        cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
        import colorsys

        for _ in range(36):
            px, py = cx + rng.uniform(-span, span), cy + rng.uniform(-span, span)
            r = size * rng.uniform(0.02, 0.08)
            colour = np.array(
                colorsys.hsv_to_rgb(rng.uniform(), rng.uniform(0.2, 0.7), rng.uniform(0.3, 0.85))
            )
            kind = rng.integers(3)
            if kind == 0:
                sd = np.hypot(x - px, y - py) - r
            else:
                n = 3 if kind == 1 else 4
                a0 = rng.uniform(0, 2 * math.pi)
                aspect = 1.0 if n == 3 else rng.uniform(0.4, 1.0)
                pts = [
                    (
                        px + r * math.cos(a0 + 2 * math.pi * k / n),
                        py + aspect * r * math.sin(a0 + 2 * math.pi * k / n),
                    )
                    for k in range(n)
                ]
                sd = _polygon_sd(x, y, pts)
            _paint(img, _coverage(sd, foot), colour)
    dull = np.asarray(STATIC_COLOUR)
    for st in scene.statics:
        if isinstance(st, Segment):
            # A zero-width wall is still seen: at least a pixel and a half across.
            sd = _segment_distance(x, y, st.a, st.b) - np.maximum(st.radius, 0.75 * foot)
            _paint(img, _coverage(sd, foot), dull)
        else:
            sd = _polygon_sd(x, y, st.points)
            shade = 1.0 + 0.08 * (_value_noise(x, y, size / 12, seed, 6) - 0.5)
            _paint(img, _coverage(sd, foot), dull * shade[..., None])
    img[~view.valid] = 0.08  # beyond the plane's horizon: a dark room
    return img.astype(np.float32)


def _light(cam: CameraRenderer, view: _View) -> np.ndarray:
    """Multiplicative illumination (H, W) float32 in [1 - light, 1]: a seeded gradient across the
    image and a vignette."""
    v, u = np.mgrid[0 : view.h, 0 : view.w].astype(np.float64)
    cu, cv = view.centre
    half = math.hypot(cu, cv) or 1.0
    rng = np.random.default_rng([cam.seed, 11])
    phi = rng.uniform(0, 2 * math.pi)
    grad = ((u - cu) * math.cos(phi) + (v - cv) * math.sin(phi)) / half  # in [-1, 1]
    vignette = 1 - ((u - cu) ** 2 + (v - cv) ** 2) / half**2  # 1 centre, 0 corners
    s = 0.5 * (0.5 + 0.5 * grad) + 0.5 * vignette
    return ((1 - cam.light) + cam.light * s).astype(np.float32)


class CameraRenderer(Camera):
    """A camera filming the scene: ``rgb`` frames with perspective, lens distortion, motion blur,
    a textured background, shaded bodies, uneven and flickering light, sensor noise and
    (optionally) lossy H.264 encoding. ``focus`` is ignored: a camera does not mark bodies.

    ``resolution``: an int is the image width with a 4:3 sensor (``H = round(3 W / 4)``); an
    ``(H, W)`` pair is taken as is (square pixels). Keyword options, all deterministic given
    ``seed``:

    - ``tilt`` (deg, default 0): turn about the image's horizontal axis, an oblique view; > 0
      raises the camera so that the top of the scene is nearer. In (-90, 90).
    - ``yaw`` (deg, default 0): turn about the image's vertical axis; > 0 moves the camera to the
      right so that the scene's right side is nearer. In (-90, 90).
    - ``roll`` (deg, default 0): turn about the optical axis; > 0 turns the picture of the scene
      counter-clockwise. In [-360, 360].
    - ``fov`` (deg, default 50): horizontal field of view, in [5, 150].
    - ``margin`` (fraction of the bounds' width and height, default 0.08): space around
      ``scene.bounds`` in the view, in [0, 2].
    - ``view`` (``[xmin, ymin, xmax, ymax]`` in metres, default ``scene.bounds``): the part of
      the plane to frame, e.g. where the motion happens in a large world.
    - ``k1``, ``k2`` (default 0): Brown radial lens distortion about the image centre, normalised
      by the focal length in pixels (< 0 barrel, > 0 pincushion); each in [-1, 1].
    - ``shutter`` (fraction of the frame interval, default 0.5): exposure time, in [0, 1].
    - ``subframes`` (default 8): poses averaged over the exposure, in [1, 256].
    - ``background`` (default ``"texture"``): ``"texture"`` (stone tiles and stains, painted on
      the plane so it warps with the view), ``"clutter"`` (static shapes of many colours) or
      ``"plain"`` (uniform grey).
    - ``light`` (default 0.25): amplitude of uneven illumination across the image, in [0, 1].
    - ``flicker`` (default 0.05): amplitude of the light's change over time, in [0, 1].
    - ``noise`` (default 0.01): std of Gaussian sensor noise on [0, 1] values, in [0, 1].
    - ``seed`` (default 0): background, light and noise.
    - ``bitrate`` (bits/s, default 0): when > 0, :meth:`film` and :meth:`render` pass the frames
      through an H.264 encode and decode; 0: no encoding.
    - ``crf`` (default None): H.264 quality (0-51) instead of a bitrate (encodes too).

    An instance caches its views between calls: use one instance per thread.
    """

    name: ClassVar[str] = "camera"
    modes: ClassVar[tuple[str, ...]] = ("rgb",)

    def __init__(
        self,
        resolution: int | tuple[int, int] = 640,
        mode: str = "rgb",
        *,
        tilt: float = 0.0,
        yaw: float = 0.0,
        roll: float = 0.0,
        fov: float = 50.0,
        margin: float = 0.08,
        k1: float = 0.0,
        k2: float = 0.0,
        shutter: float = 0.5,
        subframes: int = 8,
        background: str = "texture",
        light: float = 0.25,
        flicker: float = 0.05,
        noise: float = 0.01,
        seed: int = 0,
        bitrate: float = 0,
        crf: int | None = None,
        view: Sequence[float] | None = None,
    ) -> None:
        super().__init__(resolution, mode)
        self.view = None if view is None else check_view(view)
        self.tilt = _number("tilt", tilt, -90, 90, open_=True)
        self.yaw = _number("yaw", yaw, -90, 90, open_=True)
        self.roll = _number("roll", roll, -360, 360)
        self.fov = _number("fov", fov, 5, 150)
        self.margin = _number("margin", margin, 0, 2)
        self.k1 = _number("k1", k1, -1, 1)
        self.k2 = _number("k2", k2, -1, 1)
        self.shutter = _number("shutter", shutter, 0, 1)
        self.subframes = _whole("subframes", subframes, 1, 256)
        if background not in BACKGROUNDS:
            raise RenderError(
                f"background = {background!r}: expected one of {', '.join(BACKGROUNDS)}"
            )
        self.background = background
        self.light = _number("light", light, 0, 1)
        self.flicker = _number("flicker", flicker, 0, 1)
        self.noise = _number("noise", noise, 0, 1)
        self.seed = _whole("seed", seed, 0, 2**63 - 1)
        self.bitrate = _number("bitrate", bitrate, 0, 1e10)
        self.crf = None if crf is None else _whole("crf", crf, 0, 51)
        self._views: dict[Any, _View] = {}

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_views": {}}  # rebuilt on demand; not shipped to workers

    def __repr__(self) -> str:
        return f"CameraRenderer(resolution={self.resolution!r}, background={self.background!r})"

    # ------------------------------------------------------------------ sizes

    def image_size(self) -> tuple[int, int]:
        """``(H, W)`` of every frame."""
        r = self.resolution
        return r if isinstance(r, tuple) else (max(1, round(3 * r / 4)), r)

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        """``(T, 3, H, W)`` of a render of ``frames`` frames (default ``scene.frames``)."""
        return (scene.frames if frames is None else frames, 3, *self.image_size())

    def _view(self, scene: Scene) -> _View:
        key = (scene.bounds, scene.statics, self.view)
        view = self._views.get(key)
        if view is None:
            if len(self._views) >= _CACHE_SIZE:
                self._views.pop(next(iter(self._views)))
            view = self._views[key] = _View(self, scene, self.image_size())
        return view

    # ------------------------------------------------------------------ the public views

    def calibration(self, scene: Scene) -> Calibration:
        """The true map from this camera's image pixels to ``scene``'s metres (the pose's
        homography and, with ``k1`` or ``k2`` set, its lens)."""
        view = self._view(scene)
        return Calibration(view.to_scene_h.copy(), view.lens, 0.0, f"camera renderer {self!r}")

    def image_points(self, scene: Scene, xy: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        """Where scene points ``(N, 2)`` (metres) land in the image (pixels, distorted)."""
        return self._view(scene).project(np.asarray(xy, dtype=float))

    def plate(self, scene: Scene) -> np.ndarray:
        """The empty scene as this camera films it before the experiment: background and static
        geometry in the light of frame 0, noise-free; ``(H, W, 3)`` uint8."""
        view = self._view(scene)
        img = view.background * (view.light * np.float32(self._flicker(np.zeros(1))[0]))[..., None]
        return _quantise(img)

    def film(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """The frames as they go into a video file: ``(T, H, W, 3)`` uint8, after the H.264
        round trip when ``bitrate`` or ``crf`` is set."""
        frames = self.exposure(scene, traj)
        if self.bitrate > 0 or self.crf is not None:
            frames = h264_round_trip(frames, scene.fps, self.bitrate, self.crf)
        return frames

    # ------------------------------------------------------------------ the exposure

    def _flicker(self, t: np.ndarray) -> np.ndarray:
        """Light level over time (s from the first frame): 1 + flicker x a seeded slow drift and a
        faster wobble."""
        rng = np.random.default_rng([self.seed, 13])
        f1, f2 = rng.uniform(0.3, 1.5), rng.uniform(4.0, 9.0)
        p1, p2 = rng.uniform(0, 2 * math.pi, 2)
        w = 0.7 * np.sin(2 * math.pi * f1 * t + p1) + 0.3 * np.sin(2 * math.pi * f2 * t + p2)
        return 1 + self.flicker * w

    def exposure(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """The frames the sensor records, before any encoding: ``(T, H, W, 3)`` uint8."""
        states = np.asarray(traj.states, dtype=float)
        n = len(scene.bodies)
        if (
            states.ndim != 3
            or states.shape[1] != n
            or (traj.bodies and tuple(traj.bodies) != scene.body_names)
        ):
            raise RenderError(
                f"trajectory bodies {list(traj.bodies)} do not match the scene's bodies "
                f"{list(scene.body_names)}"
            )
        if not np.isfinite(states[:, :, :6]).all():
            t, i = np.argwhere(~np.isfinite(states[:, :, :6]).all(axis=2))[0]
            raise RenderError(
                f"trajectory state of body {scene.bodies[i].name!r} at frame {t} is not finite"
            )
        view = self._view(scene)
        frames_n = states.shape[0]
        times = np.asarray(traj.times, dtype=float)
        if frames_n > 1:
            dt = np.abs(np.diff(times))
            dt = np.append(dt, dt[-1])
        else:
            dt = np.full(frames_n, scene.dt)
        s = self.subframes
        # Sub-frame offsets from the frame time, symmetric: the mean pose is the frame's.
        frac = (np.arange(s) + 0.5) / s - 0.5
        offsets = self.shutter * dt[:, None] * frac[None, :]  # (T, S)
        light = self._flicker(times - times[0] if frames_n else times)
        rng = np.random.default_rng([self.seed, 17])
        out = np.empty((frames_n, view.h, view.w, 3), np.uint8)
        colours = [np.asarray(body_colour(i), np.float32) for i in range(n)]
        img = np.empty((view.h, view.w, 3), np.float32)
        for t in range(frames_n):
            np.copyto(img, view.background)
            for i, body in enumerate(scene.bodies):
                x, y, a, vx, vy, w = states[t, i]
                px, py = x + vx * offsets[t], y + vy * offsets[t]
                ang = a + w * offsets[t]
                box = view.box(np.stack([px, py], 1), body.shape.extent())
                if box is None:
                    continue
                _draw_body(img, view, box, body.shape, px, py, ang, colours[i])
            img *= (view.light * np.float32(light[t]))[..., None]
            if self.noise > 0:
                img += rng.standard_normal(img.shape, dtype=np.float32) * np.float32(self.noise)
            out[t] = _quantise(img)
        return out


def _draw_body(
    img: np.ndarray,
    view: _View,
    box: tuple[int, int, int, int],
    shape: Any,
    px: np.ndarray,
    py: np.ndarray,
    ang: np.ndarray,
    colour: np.ndarray,
) -> None:
    """Composite one body, averaged over its sub-frame poses, into ``img`` inside ``box``."""
    r0, r1, c0, c1 = box
    x = view.x32[r0:r1, c0:c1][None]
    y = view.y32[r0:r1, c0:c1][None]
    foot = view.foot32[r0:r1, c0:c1][None]
    dx = x - px.astype(np.float32)[:, None, None]
    dy = y - py.astype(np.float32)[:, None, None]
    if isinstance(shape, Circle):
        r = np.float32(shape.radius)
        rho2 = dx * dx + dy * dy
        cov = _coverage(np.sqrt(rho2) - r, foot)
        # A lit sphere: Lambert shading from the surface normal plus a small highlight.
        nz = np.sqrt(np.clip(1 - rho2 / (r * r), 0.0, 1.0))
        nx, ny = dx / r, dy / r
        lam = np.clip(nx * _LIGHT[0] + ny * _LIGHT[1] + nz * _LIGHT[2], 0.0, 1.0)
        spec = np.clip(nx * _HALF[0] + ny * _HALF[1] + nz * _HALF[2], 0.0, 1.0) ** 24
        shade = np.float32(0.3) + np.float32(0.7) * lam
        col = shade[..., None] * colour + (np.float32(0.35) * spec)[..., None]
    else:
        c = np.cos(ang).astype(np.float32)[:, None, None]
        s = np.sin(ang).astype(np.float32)[:, None, None]
        bx, by = c * dx + s * dy, c * dy - s * dx  # body frame
        cov = _coverage(_polygon_sd(bx, by, shape.vertices()), foot)
        # A gentle gradient across the body, turning with it.
        shade = np.float32(0.85) + np.float32(0.15 / shape.extent()) * by
        col = shade[..., None] * colour
    alpha = cov.mean(axis=0)
    premult = (cov[..., None] * col).mean(axis=0)
    part = img[r0:r1, c0:c1]
    part *= (1 - alpha)[..., None]
    part += premult


def _quantise(img: np.ndarray) -> np.ndarray:
    return np.rint(np.clip(img, 0.0, 1.0) * np.float32(255)).astype(np.uint8)


@hookimpl
def register_renderers() -> list[type]:
    return [CameraRenderer]
