"""A second camera for testing the video path on footage physbench's own renderer did not make.

Written apart from the ``camera`` renderer (:mod:`physbench.render.camera`) on purpose, from
different code and a different model, so that a tracker tuned to one is caught by the other. Each
``seed`` draws a new domain (:class:`Domain`); any drawn value can be pinned by keyword.

The model, in the order light goes through it:

- **Pose**: a pinhole at a 3-D point off the plane's normal by ``oblique`` degrees (towards
  ``azimuth``), looking at the middle of the framed rectangle (``view``, default the scene's
  bounds), rolled by ``roll``; horizontal field of view ``fov``; the principal point off the image
  centre by ``principal`` (pixels). The distance is the one at which the rectangle, after the
  lens, fills the image less a ``margin``.
- **Lens**: Brown radial distortion ``k1``, ``k2`` about the principal point, normalised by the
  focal length in pixels (the model :class:`~physbench.calibration.Lens` inverts); pixels are
  undistorted by Newton's method on the radius.
- **Plane**: a texture painted in scene metres (``bricks``, ``planks`` or ``plaster`` with
  posters), lit by a broad spot whose falloff across the view is ``falloff``; statics as dark
  rails and slabs.
- **Bodies**: a circle is a sphere: Lambert shading from a light at ``light_azimuth`` and
  ``light_elevation`` plus a Blinn-Phong highlight (``specular``, ``shininess``) seen from the
  camera's true position; other shapes are flat-shaded with a sheen across their short axis.
- **Exposure**: the shutter is open ``shutter`` of the frame interval, centred on the frame time;
  each body's pose is interpolated between frames (cubic Hermite on the trajectory's velocities)
  at as many instants as keep its image step under 0.75 px, each instant seeing every pixel at
  one of 3 x 3 sample points in turn (space and time sampled together).
- **Light and sensor**: the whole image scaled by a light level ``1 + drift s(t)`` (``s`` a
  smooth seeded curve in [-1, 1] over the clip) and a cos^4 vignette of depth ``vignette``; shot
  noise and read noise in linear light, a 1/2.2 gamma, 8 bits.
- **Codec**: H.264 at ``crf`` (:func:`physbench.codec.h264_round_trip` in :meth:`film`; the
  video writer encodes :meth:`exposure` at the same ``crf``).

Pixel convention: physbench's (pixel centres at integers, ``u`` right, ``v`` down);
:meth:`FieldCamera.calibration` is the true map. :meth:`FieldCamera.plate` is the empty scene at
the nominal light (level 1, which the clip drifts around), the per-pixel median of 9 noisy frames
through the same codec: a plate a person films before the experiment.
"""

from __future__ import annotations

import colorsys
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields, replace
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from physbench.calibration import Calibration, Lens
from physbench.codec import h264_round_trip
from physbench.render.base import Camera, RenderError, check_view
from physbench.scene import Circle, Segment

if TYPE_CHECKING:
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: Spatial samples per pixel along each axis.
SUPERSAMPLE = 3
#: Largest image step (px) of a body between two instants of one exposure.
BLUR_STEP = 0.75
#: Most instants per exposure.
MAX_INSTANTS = 72
#: Plate: frames of the empty scene whose per-pixel median it is.
PLATE_FRAMES = 9
TEXTURES = ("bricks", "planks", "plaster")
GAMMA = 2.2


@dataclass(frozen=True)
class Domain:
    """One draw of the camera's domain (see the module docstring for each value's meaning)."""

    oblique: float  # degrees off the plane's normal
    azimuth: float  # degrees: direction of that tilt in the plane
    roll: float  # degrees
    fov: float  # degrees, horizontal
    principal: tuple[float, float]  # px off the image centre
    margin: float  # fraction of the image left around the view
    k1: float
    k2: float
    texture: str
    falloff: float  # spot light's drop from its centre to the view's far side
    light_azimuth: float  # degrees
    light_elevation: float  # degrees above the plane
    ambient: float
    specular: float
    shininess: float
    drift: float  # light level amplitude over the clip
    drift_shape: tuple[float, float, float, float]  # ramp weight, sign, frequency, phase
    vignette: float
    exposure_level: float
    shot: float  # variance per unit of linear signal
    read: float  # std of read noise (linear)
    shutter: float
    crf: int

    @classmethod
    def draw(cls, seed: int) -> Domain:
        """The domain of ``seed``: light drift of 3-10 %, 0-25 degrees off square-on, CRF
        18-30, ..."""
        rng = np.random.default_rng([seed, 0x5EC0])
        u = rng.uniform
        return cls(
            oblique=float(u(0.0, 25.0)),
            azimuth=float(u(0.0, 360.0)),
            roll=float(u(-4.0, 4.0)),
            fov=float(u(40.0, 70.0)),
            principal=(float(u(-8.0, 8.0)), float(u(-6.0, 6.0))),
            margin=float(u(0.04, 0.14)),
            k1=float(u(-0.12, 0.06)),
            k2=float(u(-0.02, 0.02)),
            texture=TEXTURES[int(rng.integers(len(TEXTURES)))],
            falloff=float(u(0.05, 0.25)),
            light_azimuth=float(u(0.0, 360.0)),
            light_elevation=float(u(30.0, 65.0)),
            ambient=float(u(0.15, 0.35)),
            specular=float(u(0.3, 0.9)),
            shininess=float(u(15.0, 80.0)),
            drift=float(u(0.03, 0.10)),
            drift_shape=(
                float(u(0.0, 1.0)),
                1.0 if rng.random() < 0.5 else -1.0,
                float(u(0.3, 1.2)),
                float(u(0.0, 2 * math.pi)),
            ),
            vignette=float(u(0.1, 0.35)),
            exposure_level=float(u(0.75, 0.95)),
            shot=float(u(2e-4, 1e-3)),
            read=float(u(0.002, 0.006)),
            shutter=float(u(0.15, 0.7)),
            crf=int(rng.integers(18, 31)),
        )

    def check(self) -> None:
        """:class:`RenderError` naming the first value out of its range."""
        limits = {
            "oblique": (0.0, 70.0),
            "azimuth": (-360.0, 360.0),
            "roll": (-360.0, 360.0),
            "light_azimuth": (-360.0, 360.0),
            "light_elevation": (1.0, 90.0),
            "fov": (10.0, 120.0),
            "margin": (0.0, 0.45),
            "k1": (-0.5, 0.5),
            "k2": (-0.2, 0.2),
            "falloff": (0.0, 0.9),
            "ambient": (0.0, 1.0),
            "specular": (0.0, 2.0),
            "shininess": (1.0, 1000.0),
            "drift": (0.0, 0.5),
            "vignette": (0.0, 0.9),
            "exposure_level": (0.05, 1.0),
            "shot": (0.0, 0.1),
            "read": (0.0, 0.2),
            "shutter": (0.0, 1.0),
            "crf": (0, 51),
        }
        for name, (lo, hi) in limits.items():
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not lo <= v <= hi:
                raise RenderError(f"{name} = {v!r}: expected a number in [{lo:g}, {hi:g}]")
        if self.texture not in TEXTURES:
            raise RenderError(f"texture = {self.texture!r}: expected one of {', '.join(TEXTURES)}")

    def level(self, tau: np.ndarray) -> np.ndarray:
        """The light level at clip fractions ``tau`` in [0, 1]: ``1 + drift s(tau)``."""
        w, sign, freq, phase = self.drift_shape
        s = w * (2 * tau - 1) + (1 - w) * np.sin(2 * math.pi * freq * tau + phase)
        return 1 + self.drift * sign * s


# --------------------------------------------------------------------------- geometry


class _Geometry:
    """The pose, and the scene point of every sample of every pixel (for one image size and
    framed rectangle)."""

    def __init__(self, d: Domain, view: Sequence[float], hw: tuple[int, int]) -> None:
        self.h, self.w = hw
        self.f = (self.w / 2) / math.tan(math.radians(d.fov) / 2)
        self.cx = (self.w - 1) / 2 + d.principal[0]
        self.cy = (self.h - 1) / 2 + d.principal[1]
        self.k1, self.k2 = d.k1, d.k2
        x0, y0, x1, y1 = view
        self.target = np.array([(x0 + x1) / 2, (y0 + y1) / 2, 0.0])
        self.size = max(x1 - x0, y1 - y0)
        self.rot = _look(d.oblique, d.azimuth, d.roll)
        self.normal = -self.rot[2]  # from the target towards the camera
        self.centre = self._fit(view, d.margin)
        self._samples()

    def homography(self, centre: np.ndarray | None = None) -> np.ndarray:
        """Scene ``(x, y, 1)`` -> undistorted pixels, up to scale."""
        c = self.centre if centre is None else centre
        k = np.array([[self.f, 0.0, self.cx], [0.0, self.f, self.cy], [0.0, 0.0, 1.0]])
        return k @ np.column_stack([self.rot[:, 0], self.rot[:, 1], -self.rot @ c])

    def distort(self, uv: np.ndarray) -> np.ndarray:
        q = (uv - (self.cx, self.cy)) / self.f
        r2 = (q * q).sum(axis=-1, keepdims=True)
        return q * (1 + self.k1 * r2 + self.k2 * r2 * r2) * self.f + (self.cx, self.cy)

    def undistort(self, uv: np.ndarray) -> np.ndarray:
        """The undistorted pixels of image pixels: the radius ``rho`` with ``rho (1 + k1 rho^2
        + k2 rho^4) = r``, read off a fine table of the (monotonic) forward map, then two Newton
        steps."""
        q = (uv - (self.cx, self.cy)) / self.f
        if not (self.k1 or self.k2):
            return np.array(uv, dtype=float)
        r = np.sqrt((q * q).sum(axis=-1))
        table = np.linspace(0.0, 1.5 * float(r.max()) + 1e-9, 20001)
        ahead = table * (1 + self.k1 * table**2 + self.k2 * table**4)
        grows = np.diff(ahead) > 0
        if not grows.all():  # strong barrel distortion folds back: keep the rising part
            stop = int(np.argmin(grows))
            table, ahead = table[: stop + 1], ahead[: stop + 1]
        if r.max() > ahead[-1]:
            raise RenderError(
                f"k1 = {self.k1!r}, k2 = {self.k2!r}: the lens folds the image over before its "
                "corners; use a smaller |k1|, |k2| or field of view"
            )
        rho = np.interp(r, ahead, table)
        for _ in range(2):
            rho2 = rho * rho
            g = rho * (1 + rho2 * (self.k1 + self.k2 * rho2)) - r
            dg = 1 + rho2 * (3 * self.k1 + 5 * self.k2 * rho2)
            rho = rho - g / dg
        scale = np.where(r > 1e-12, rho / np.maximum(r, 1e-12), 1.0)
        return q * scale[..., None] * self.f + (self.cx, self.cy)

    def project(self, xy: np.ndarray, centre: np.ndarray | None = None) -> np.ndarray:
        """Image pixels (distorted) of scene points ``(..., 2)``."""
        h = self.homography(centre)
        p = np.asarray(xy, dtype=float) @ h[:, :2].T + h[:, 2]
        return self.distort(p[..., :2] / p[..., 2:3])

    def _fit(self, view: Sequence[float], margin: float) -> np.ndarray:
        """The camera centre on the normal at which the view's outline just fits the image less
        ``margin`` (bisection on the log of the distance)."""
        x0, y0, x1, y1 = view
        s = np.linspace(0.0, 1.0, 25)
        outline = np.concatenate(
            [
                np.column_stack([x0 + (x1 - x0) * s, np.full_like(s, y0)]),
                np.column_stack([x0 + (x1 - x0) * s, np.full_like(s, y1)]),
                np.column_stack([np.full_like(s, x0), y0 + (y1 - y0) * s]),
                np.column_stack([np.full_like(s, x1), y0 + (y1 - y0) * s]),
            ]
        )
        mu, mv = margin * self.w / 2, margin * self.h / 2

        def fits(dist: float) -> bool:
            c = self.target + dist * self.normal
            depth = (outline - c[:2]) @ self.rot[2, :2] - c[2] * self.rot[2, 2]
            if (depth <= 0.05 * dist).any():
                return False
            uv = self.project(outline, c)
            return bool(
                np.isfinite(uv).all()
                and uv[:, 0].min() >= mu - 0.5
                and uv[:, 0].max() <= self.w - 0.5 - mu
                and uv[:, 1].min() >= mv - 0.5
                and uv[:, 1].max() <= self.h - 0.5 - mv
            )

        lo, hi = math.log(1e-3 * self.size), math.log(1e3 * self.size)
        if not fits(math.exp(hi)):
            raise RenderError(
                f"k1 = {self.k1!r}, k2 = {self.k2!r}: the distorted view does not fit the image"
            )
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if fits(math.exp(mid)):
                hi = mid
            else:
                lo = mid
        return self.target + math.exp(hi) * self.normal

    def _samples(self) -> None:
        """Scene ``(x, y)`` of each of the ``SUPERSAMPLE``^2 samples per pixel; rays that miss
        the plane are flagged."""
        n = SUPERSAMPLE
        offs = (np.arange(n) + 0.5) / n - 0.5
        v = (np.arange(self.h)[:, None] + offs[None, :]).ravel()
        u = (np.arange(self.w)[:, None] + offs[None, :]).ravel()
        uu, vv = np.meshgrid(u, v)
        und = self.undistort(np.stack([uu, vv], axis=-1))
        ray_cam = np.concatenate(
            [(und - (self.cx, self.cy)) / self.f, np.ones((*und.shape[:2], 1))], axis=-1
        )
        ray = ray_cam @ self.rot  # camera -> scene: rot.T @ r for each ray
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -self.centre[2] / ray[..., 2]
        self.hit = np.isfinite(s) & (s > 0)
        s = np.where(self.hit, s, 0.0)
        self.x = (self.centre[0] + s * ray[..., 0]).astype(np.float32)
        self.y = (self.centre[1] + s * ray[..., 1]).astype(np.float32)

    def box(self, centres: np.ndarray, radius: float) -> tuple[int, int, int, int] | None:
        """Sample rows and columns ``(r0, r1, c0, c1)`` covering discs of ``radius`` (m) about
        scene points ``centres`` (N, 2)."""
        a = np.linspace(0, 2 * math.pi, 24, endpoint=False)
        ring = 1.1 * radius * np.column_stack([np.cos(a), np.sin(a)])
        uv = self.project((centres[:, None, :] + ring[None]).reshape(-1, 2))
        if not np.isfinite(uv).all():
            return 0, self.h * SUPERSAMPLE, 0, self.w * SUPERSAMPLE
        n = SUPERSAMPLE
        c0 = max(0, math.floor(uv[:, 0].min() - 2)) * n
        c1 = min(self.w, math.ceil(uv[:, 0].max() + 3)) * n
        r0 = max(0, math.floor(uv[:, 1].min() - 2)) * n
        r1 = min(self.h, math.ceil(uv[:, 1].max() + 3)) * n
        return None if c0 >= c1 or r0 >= r1 else (r0, r1, c0, c1)

    def outline_box(self, outline: np.ndarray) -> tuple[int, int, int, int] | None:
        """Sample rows and columns covering the scene points ``outline`` (N, 2), padded by 3 px
        (a distorted edge bulges between its points)."""
        uv = self.project(outline)
        if not np.isfinite(uv).all():
            return 0, self.h * SUPERSAMPLE, 0, self.w * SUPERSAMPLE
        n = SUPERSAMPLE
        c0 = max(0, math.floor(uv[:, 0].min() - 3)) * n
        c1 = min(self.w, math.ceil(uv[:, 0].max() + 4)) * n
        r0 = max(0, math.floor(uv[:, 1].min() - 3)) * n
        r1 = min(self.h, math.ceil(uv[:, 1].max() + 4)) * n
        return None if c0 >= c1 or r0 >= r1 else (r0, r1, c0, c1)


def _outline(shape: Any, px: float, py: float, ang: float) -> np.ndarray:
    """Scene points on a polygon body's outline at pose ``(px, py, ang)``: its vertices and the
    middles of its edges."""
    pts = np.asarray(shape.vertices(), dtype=float)
    pts = np.concatenate([pts, 0.5 * (pts + np.roll(pts, -1, axis=0))])
    c, s = math.cos(ang), math.sin(ang)
    return pts @ np.array([[c, s], [-s, c]]) + (px, py)


def _look(oblique: float, azimuth: float, roll: float) -> np.ndarray:
    """Rows: the camera's x (right), y (down) and z (forward) axes in scene coordinates, for a
    camera ``oblique`` degrees off the plane's normal towards ``azimuth``, rolled by ``roll``."""
    th, ph = math.radians(oblique), math.radians(azimuth)
    towards = np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])
    z = -towards
    up = np.array([0.0, 1.0, 0.0])
    y = -(up - (up @ z) * z)
    y /= np.linalg.norm(y)
    x = np.cross(y, z)
    c, s = math.cos(math.radians(roll)), math.sin(math.radians(roll))
    x, y = c * x + s * y, -s * x + c * y
    return np.stack([x, y, z])


# --------------------------------------------------------------------------- textures


def _lattice_noise(
    x: np.ndarray, y: np.ndarray, cell: float, rng: np.random.Generator
) -> np.ndarray:
    """Smooth noise in [0, 1]: a random 64 x 64 table, tiled, read bilinearly with cosine
    easing at ``cell``-metre spacing."""
    table = rng.random((64, 64)).astype(np.float32)
    fx, fy = x / cell, y / cell
    i, j = np.floor(fx), np.floor(fy)
    tx = 0.5 - 0.5 * np.cos(np.pi * (fx - i))
    ty = 0.5 - 0.5 * np.cos(np.pi * (fy - j))
    i, j = i.astype(np.int64) % 64, j.astype(np.int64) % 64
    i1, j1 = (i + 1) % 64, (j + 1) % 64
    top = table[j, i] * (1 - tx) + table[j, i1] * tx
    bottom = table[j1, i] * (1 - tx) + table[j1, i1] * tx
    return (top * (1 - ty) + bottom * ty).astype(np.float32)


def _cell_random(i: np.ndarray, j: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A random value in [0, 1) per integer cell ``(i, j)`` (a 97 x 89 table, tiled)."""
    table = rng.random((89, 97)).astype(np.float32)
    return table[j.astype(np.int64) % 89, i.astype(np.int64) % 97]


def _rgb(h: float | np.ndarray, s: float | np.ndarray, v: float | np.ndarray) -> np.ndarray:
    """HSV display values (arrays broadcast) to linear RGB ``(..., 3)`` float32."""
    h, s, v = (np.asarray(c, dtype=np.float32) for c in (h, s, v))
    out = []
    for n in (5.0, 3.0, 1.0):
        k = (n + h * 6) % 6
        out.append(v - v * s * np.clip(np.minimum(k, 4 - k), 0, 1))
    rgb = np.stack(np.broadcast_arrays(*out), axis=-1)
    return (rgb**GAMMA).astype(np.float32)


def _bricks(x: np.ndarray, y: np.ndarray, size: float, rng: np.random.Generator) -> np.ndarray:
    bw, bh = size * 0.06 * rng.uniform(0.8, 1.2), size * 0.025 * rng.uniform(0.8, 1.2)
    mortar = 0.12 * bh
    row = np.floor(y / bh)
    xs = x / bw + 0.5 * (row % 2)
    col = np.floor(xs)
    hue0 = rng.uniform(0.0, 0.09)
    jitter = _cell_random(col, row, rng)
    brick = _rgb(
        hue0 + 0.02 * jitter, rng.uniform(0.35, 0.55), 0.45 + 0.25 * _cell_random(row, col, rng)
    )
    grain = 0.9 + 0.2 * _lattice_noise(x, y, 0.15 * bh, rng)
    brick = brick * grain[..., None]
    fy, fx = y - row * bh, (xs - col) * bw
    joint = (fy < mortar) | (fx < mortar)
    return np.where(joint[..., None], _rgb(0.1, 0.08, 0.72), brick)


def _planks(x: np.ndarray, y: np.ndarray, size: float, rng: np.random.Generator) -> np.ndarray:
    a = rng.uniform(0, math.pi)
    along = x * math.cos(a) + y * math.sin(a)
    across = -x * math.sin(a) + y * math.cos(a)
    width, length = size * rng.uniform(0.04, 0.08), size * rng.uniform(0.3, 0.6)
    lane = np.floor(across / width)
    shift = _cell_random(lane, lane * 0, rng) * length
    piece = np.floor((along + shift) / length)
    tone = _cell_random(piece, lane, rng)
    wobble = _lattice_noise(along * 0.2, across, 0.3 * width, rng)
    grain = 0.92 + 0.08 * np.sin(2 * math.pi * (across / (0.11 * width) + 3 * wobble))
    wood = _rgb(0.07 + 0.04 * tone, 0.35 + 0.15 * tone, (0.5 + 0.25 * tone) * grain)
    seam = ((across - lane * width) < 0.05 * width) | (((along + shift) % length) < 0.01 * length)
    return np.where(seam[..., None], wood * 0.45, wood)


def _plaster(x: np.ndarray, y: np.ndarray, size: float, rng: np.random.Generator) -> np.ndarray:
    hue, sat = rng.uniform(), rng.uniform(0.05, 0.25)
    blotch = _lattice_noise(x, y, 0.2 * size, rng)
    fine = _lattice_noise(x, y, 0.004 * size, rng)
    img = _rgb(hue, sat, 0.62 + 0.12 * blotch + 0.06 * fine)
    x0, y0 = float(np.median(x)), float(np.median(y))
    for _ in range(int(rng.integers(2, 6))):  # posters: muted rectangles with a darker frame
        cx, cy = x0 + rng.uniform(-0.5, 0.5) * size, y0 + rng.uniform(-0.4, 0.4) * size
        hw, hh = size * rng.uniform(0.05, 0.15), size * rng.uniform(0.05, 0.15)
        inside = (np.abs(x - cx) < hw) & (np.abs(y - cy) < hh)
        frame = inside & ((np.abs(x - cx) > 0.92 * hw) | (np.abs(y - cy) > 0.92 * hh))
        img = np.where(inside[..., None], _rgb(rng.uniform(), rng.uniform(0.1, 0.4), 0.55), img)
        img = np.where(frame[..., None], _rgb(0.0, 0.0, 0.3), img)
    return img


def _downsample(a: np.ndarray) -> np.ndarray:
    """The mean of each pixel's ``SUPERSAMPLE`` x ``SUPERSAMPLE`` samples."""
    n = SUPERSAMPLE
    h, w = a.shape[0] // n, a.shape[1] // n
    return a.reshape(h, n, w, n, *a.shape[2:]).mean(axis=(1, 3))


# --------------------------------------------------------------------------- the camera


class FieldCamera(Camera):
    """The second, independent camera (see the module docstring). ``resolution``: image width
    with a 4:3 sensor, or ``(H, W)``; ``seed`` draws the :class:`Domain`, and keyword ``pins``
    fix any of its values (``crf=30``, ``drift=0.1``, ``texture="planks"``, ...); ``view``
    frames part of the plane ``[xmin, ymin, xmax, ymax]`` (m)."""

    name: ClassVar[str] = "field_camera"
    modes: ClassVar[tuple[str, ...]] = ("rgb",)

    def __init__(
        self,
        resolution: int | tuple[int, int] = 640,
        mode: str = "rgb",
        *,
        seed: int = 0,
        view: Sequence[float] | None = None,
        **pins: Any,
    ) -> None:
        super().__init__(resolution, mode)
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise RenderError(f"seed = {seed!r}: expected a whole number >= 0")
        known = {f.name for f in fields(Domain)}
        unknown = sorted(set(pins) - known)
        if unknown:
            raise RenderError(f"{unknown[0]}: unknown option; known: {', '.join(sorted(known))}")
        self.seed = int(seed)
        self.view = None if view is None else check_view(view)
        self.domain = replace(Domain.draw(self.seed), **pins)
        self.domain.check()
        self.crf = int(self.domain.crf)
        self.transfer = "linear" if GAMMA == 1 else f"gamma{GAMMA:g}"  # the writer's tag
        self._cache: dict[Any, tuple[_Geometry, np.ndarray, np.ndarray]] = {}

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_cache": {}}  # rebuilt on demand; not shipped to workers

    def __repr__(self) -> str:
        return f"FieldCamera(resolution={self.resolution!r}, seed={self.seed})"

    def describe(self) -> dict[str, Any]:
        """The drawn domain, for a results file."""
        return {"seed": self.seed, **asdict(self.domain)}

    def image_size(self) -> tuple[int, int]:
        r = self.resolution
        return r if isinstance(r, tuple) else (max(1, round(3 * r / 4)), r)

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        return (scene.frames if frames is None else frames, 3, *self.image_size())

    # ------------------------------------------------------------------ the static view

    def _static(self, scene: Scene) -> tuple[_Geometry, np.ndarray, np.ndarray]:
        """The geometry, the lit plane's radiance per pixel ``(H, W, 3)`` and the light and
        vignette factor per pixel ``(H, W)`` (cached per framed rectangle and statics)."""
        view = self.view if self.view is not None else scene.bounds
        key = (tuple(view), scene.statics)
        if key not in self._cache:
            if len(self._cache) >= 2:
                self._cache.pop(next(iter(self._cache)))
            geo = _Geometry(self.domain, view, self.image_size())
            rng = np.random.default_rng([self.seed, 0x7E7])
            paint = {"bricks": _bricks, "planks": _planks, "plaster": _plaster}
            albedo = paint[self.domain.texture](geo.x, geo.y, geo.size, rng)
            albedo = _statics(albedo, geo, scene)
            albedo[~geo.hit] = 0.01
            radiance = _downsample(albedo * self._spot(geo, geo.x, geo.y)[..., None])
            self._cache[key] = (geo, radiance.astype(np.float32), self._vignette(geo))
        return self._cache[key]

    def _spot(self, geo: _Geometry, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Irradiance on the plane: 1 at the spot's centre, ``1 - falloff`` a view away."""
        rng = np.random.default_rng([self.seed, 0x5B07])
        sx, sy = geo.target[:2] + rng.uniform(-0.4, 0.4, 2) * geo.size
        d2 = ((x - sx) ** 2 + (y - sy) ** 2) / geo.size**2
        return (1 - self.domain.falloff * np.minimum(d2, 1.0)).astype(np.float32)

    def _vignette(self, geo: _Geometry) -> np.ndarray:
        v, u = np.mgrid[0 : geo.h, 0 : geo.w].astype(np.float64)
        r2 = ((u - geo.cx) ** 2 + (v - geo.cy) ** 2) / geo.f**2
        c4 = 1 / (1 + r2) ** 2
        corner = 1 / (1 + ((geo.w / 2) ** 2 + (geo.h / 2) ** 2) / geo.f**2) ** 2
        return (1 - self.domain.vignette * (1 - c4) / (1 - corner)).astype(np.float32)

    # ------------------------------------------------------------------ Camera contract

    def calibration(self, scene: Scene) -> Calibration:
        """The true map from this camera's pixels to ``scene``'s metres."""
        geo = self._static(scene)[0]
        inv = np.linalg.inv(geo.homography())
        lens = None
        if geo.k1 or geo.k2:
            lens = Lens(geo.k1, geo.k2, (geo.cx, geo.cy), geo.f)
        return Calibration(inv / inv[2, 2], lens, 0.0, repr(self))

    def image_points(self, scene: Scene, xy: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        return self._static(scene)[0].project(np.asarray(xy, dtype=float))

    def plate(self, scene: Scene) -> np.ndarray:
        """The empty scene at the nominal light: the per-pixel median of
        :data:`PLATE_FRAMES` noisy frames through the codec."""
        _, radiance, shade = self._static(scene)
        rng = np.random.default_rng([self.seed, 0x91A7E])
        linear = radiance * (shade * self.domain.exposure_level)[..., None]
        frames = np.stack([self._sensor(linear, rng) for _ in range(PLATE_FRAMES)])
        frames = h264_round_trip(frames, 30.0, 0, self.crf)
        return np.median(frames, axis=0).round().astype(np.uint8)

    def film(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """:meth:`exposure` through H.264 at ``crf``."""
        return h264_round_trip(self.exposure(scene, traj), scene.fps, 0, self.crf)

    def exposure(self, scene: Scene, traj: Trajectory) -> np.ndarray:
        """The frames the sensor records, before encoding: ``(T, H, W, 3)`` uint8."""
        states = np.asarray(traj.states, dtype=float)
        if states.ndim != 3 or states.shape[1] != len(scene.bodies):
            raise RenderError(
                f"trajectory bodies {list(traj.bodies)} do not match the scene's bodies "
                f"{list(scene.body_names)}"
            )
        if not np.isfinite(states[:, :, :6]).all():
            raise RenderError("the trajectory holds a state that is not finite")
        geo, radiance, shade = self._static(scene)
        times = np.asarray(traj.times, dtype=float)
        n = len(times)
        span = times[-1] - times[0] if n > 1 else 1.0
        level = self.domain.level((times - times[0]) / (span or 1.0))
        interval = float(np.median(np.diff(times))) if n > 1 else scene.dt
        colours = _body_colours(len(scene.bodies), self.seed, self.domain.texture)
        rng = np.random.default_rng([self.seed, 0x0153])
        out = np.empty((n, geo.h, geo.w, 3), np.uint8)
        for k in range(n):
            img = radiance.copy()
            for i, body in enumerate(scene.bodies):
                poses = self._poses(times, states[:, i], k, interval, geo, body.shape.extent())
                self._draw(img, geo, body.shape, poses, colours[i])
            img *= (shade * (level[k] * self.domain.exposure_level))[..., None]
            out[k] = self._sensor(img, rng)
        return out

    # ------------------------------------------------------------------ one frame

    def _poses(
        self,
        times: np.ndarray,
        state: np.ndarray,
        k: int,
        interval: float,
        geo: _Geometry,
        extent: float,
    ) -> np.ndarray:
        """``(S, 3)`` poses ``(x, y, angle)`` of one body at the instants of frame ``k``'s
        exposure: enough instants that its image moves at most :data:`BLUR_STEP` between
        two."""
        half = 0.5 * self.domain.shutter * interval
        ends = _hermite(times, state, np.array([times[k] - half, times[k] + half]))
        mpp = geo.size / geo.w
        sweep = float(np.hypot(*(ends[1, :2] - ends[0, :2]))) + extent * abs(
            ends[1, 2] - ends[0, 2]
        )
        count = int(np.clip(math.ceil(sweep / mpp / BLUR_STEP), 1, MAX_INSTANTS))
        count = SUPERSAMPLE**2 * math.ceil(count / SUPERSAMPLE**2)  # whole rounds of samples
        tq = times[k] + half * ((np.arange(count) + 0.5) / count * 2 - 1)
        return _hermite(times, state, tq)

    def _draw(
        self, img: np.ndarray, geo: _Geometry, shape: Any, poses: np.ndarray, colour: np.ndarray
    ) -> None:
        """Composite one body, averaged over its ``poses``, into ``img`` (linear radiance).
        Space and time are sampled together: each instant sees every pixel at one of its
        ``SUPERSAMPLE``^2 sample points, in turn (so ``len(poses)`` is a multiple of that), and is
        evaluated only in its own box. A body's radiance is ``shade x colour + highlight``,
        accumulated as those two numbers."""
        n = SUPERSAMPLE
        box = geo.box(poses[:, :2], shape.extent())
        if box is None:
            return
        r0, r1, c0, c1 = (v // n for v in box)
        cover = np.zeros((r1 - r0, c1 - c0), np.float32)
        shade = np.zeros_like(cover)
        spec = np.zeros_like(cover)
        for k, (px, py, ang) in enumerate(poses):
            if isinstance(shape, Circle):
                sub = geo.box(np.array([[px, py]]), shape.extent())
            else:
                sub = geo.outline_box(_outline(shape, px, py, ang))
            if sub is None:
                continue
            a0, a1 = max(sub[0] // n, r0), min(sub[1] // n, r1)
            b0, b1 = max(sub[2] // n, c0), min(sub[3] // n, c1)
            if a0 >= a1 or b0 >= b1:
                continue
            i, j = divmod((4 * k) % (n * n), n)  # a stride through the sample points
            rows, cols = slice(a0 * n + i, a1 * n, n), slice(b0 * n + j, b1 * n, n)
            dx = geo.x[rows, cols] - np.float32(px)
            dy = geo.y[rows, cols] - np.float32(py)
            if isinstance(shape, Circle):
                inside, s, h = self._sphere(geo, dx, dy, px, py, shape.radius)
            else:
                inside, s, h = self._slab(dx, dy, ang, shape)
            inside &= geo.hit[rows, cols]
            region = (slice(a0 - r0, a1 - r0), slice(b0 - c0, b1 - c0))
            cover[region] += inside
            shade[region] += np.where(inside, s, 0)
            spec[region] += np.where(inside, h, 0)
        mid = geo.x[r0 * n + n // 2 : r1 * n : n, c0 * n + n // 2 : c1 * n : n]
        mid_y = geo.y[r0 * n + n // 2 : r1 * n : n, c0 * n + n // 2 : c1 * n : n]
        spot = self._spot(geo, mid, mid_y) / len(poses)
        alpha = cover / len(poses)
        lit = (shade * spot)[..., None] * colour + (spec * spot)[..., None]
        part = img[r0:r1, c0:c1]
        part *= (1 - alpha)[..., None]
        part += lit

    def _sphere(
        self,
        geo: _Geometry,
        dx: np.ndarray,
        dy: np.ndarray,
        px: float,
        py: float,
        r: float,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inside mask, shade and highlight of a lit sphere of radius ``r`` centred at
        ``(px, py)``."""
        d = self.domain
        rho2 = (dx * dx + dy * dy) / np.float32(r * r)
        inside = rho2 < 1
        nz = np.sqrt(np.clip(1 - rho2, 0, 1))
        nx, ny = dx / np.float32(r), dy / np.float32(r)
        la, le = math.radians(d.light_azimuth), math.radians(d.light_elevation)
        lx, ly, lz = math.cos(le) * math.cos(la), math.cos(le) * math.sin(la), math.sin(le)
        diffuse = np.clip(nx * lx + ny * ly + nz * lz, 0, 1)
        # The viewer: from the sphere's surface point towards the camera's true position.
        vx = np.float32(geo.centre[0] - px) - dx
        vy = np.float32(geo.centre[1] - py) - dy
        vz = np.float32(geo.centre[2]) - nz * np.float32(r)
        norm = np.sqrt(vx * vx + vy * vy + vz * vz)
        hx, hy, hz = vx / norm + lx, vy / norm + ly, vz / norm + lz
        hn = np.sqrt(hx * hx + hy * hy + hz * hz)
        spec = np.clip((nx * hx + ny * hy + nz * hz) / hn, 0, 1) ** np.float32(d.shininess)
        shade = d.ambient + (1 - d.ambient) * diffuse
        return inside, shade, d.specular * spec

    def _slab(
        self, dx: np.ndarray, dy: np.ndarray, ang: float, shape: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inside mask, shade and highlight of a convex polygon body at angle ``ang``: brighter
        along its middle, as a rounded rod or a bevelled block is."""
        c, s = math.cos(ang), math.sin(ang)
        bx, by = c * dx + s * dy, -s * dx + c * dy
        pts = np.asarray(shape.vertices(), dtype=np.float32)
        inside = np.ones(dx.shape, bool)
        for a, b in zip(pts, np.roll(pts, -1, axis=0), strict=True):
            inside &= (b[0] - a[0]) * (by - a[1]) - (b[1] - a[1]) * (bx - a[0]) >= 0
        vals, vecs = np.linalg.eigh(pts.T @ pts / len(pts))
        across = (bx * vecs[0, 0] + by * vecs[1, 0]) / np.float32(math.sqrt(vals[0]) + 1e-9)
        sheen = np.clip(1 - across * across, 0, 1)
        shade = self.domain.ambient + (1 - self.domain.ambient) * (0.55 + 0.45 * sheen)
        return inside, shade, 0.25 * self.domain.specular * sheen**8

    def _sensor(self, linear: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Linear radiance ``(H, W, 3)`` -> 8-bit pixels: shot and read noise, gamma."""
        x = np.clip(linear, 0, None)
        std = np.sqrt(self.domain.shot * x + self.domain.read**2)
        x = x + rng.standard_normal(x.shape, dtype=np.float32) * std
        y = np.clip(x, 0, 1) ** np.float32(1 / GAMMA)
        return np.rint(y * 255).astype(np.uint8)


def _hermite(times: np.ndarray, state: np.ndarray, tq: np.ndarray) -> np.ndarray:
    """``(len(tq), 3)`` poses from the frame states ``(T, 6)`` (x, y, angle, vx, vy, omega):
    cubic Hermite between frames, straight lines on the velocity beyond the ends."""
    out = np.empty((len(tq), 3))
    if len(times) == 1:
        for c in range(3):
            out[:, c] = state[0, c] + state[0, c + 3] * (tq - times[0])
        return out
    k = np.clip(np.searchsorted(times, tq, side="right") - 1, 0, len(times) - 2)
    dt = times[k + 1] - times[k]
    s = (tq - times[k]) / dt
    for c in range(3):
        p0, p1 = state[k, c], state[k + 1, c]
        m0, m1 = state[k, c + 3] * dt, state[k + 1, c + 3] * dt
        inner = (
            (2 * s**3 - 3 * s**2 + 1) * p0
            + (s**3 - 2 * s**2 + s) * m0
            + (-2 * s**3 + 3 * s**2) * p1
            + (s**3 - s**2) * m1
        )
        before = p0 + m0 * s  # s < 0: before the first frame
        after = p1 + m1 * (s - 1)  # s > 1: after the last
        out[:, c] = np.where(s < 0, before, np.where(s > 1, after, inner))
    return out


def _statics(albedo: np.ndarray, geo: _Geometry, scene: Scene) -> np.ndarray:
    """Static geometry painted on the plane: dark rails (segments) and grey slabs (polygons)."""
    x, y = geo.x, geo.y
    rail = _rgb(0.6, 0.15, 0.22)
    slab = _rgb(0.08, 0.05, 0.4)
    for st in scene.statics:
        if isinstance(st, Segment):
            ax, ay = st.a
            ex, ey = st.b[0] - ax, st.b[1] - ay
            ll = ex * ex + ey * ey or 1.0
            t = np.clip(((x - ax) * ex + (y - ay) * ey) / ll, 0, 1)
            dist = np.hypot(x - ax - t * ex, y - ay - t * ey)
            inside = dist <= max(st.radius, 0.004 * geo.size)
            albedo = np.where(inside[..., None], rail, albedo)
        else:
            pts = np.asarray(st.points, dtype=float)
            inside = np.ones(x.shape, bool)
            for a, b in zip(pts, np.roll(pts, -1, axis=0), strict=True):
                inside &= (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) >= 0
            albedo = np.where(inside[..., None], slab, albedo)
    return albedo


def _body_colours(n: int, seed: int, texture: str) -> list[np.ndarray]:
    """Saturated colours, one per body, with hues spread apart and away from the texture's
    (bricks and planks are orange-brown; plaster may be any hue, so it is kept pale)."""
    rng = np.random.default_rng([seed, 0xC010])
    avoid = {"bricks": 0.05, "planks": 0.09, "plaster": None}[texture]
    start = rng.uniform()
    out = []
    for i in range(n):
        hue = (start + i / max(n, 3) + rng.uniform(-0.04, 0.04)) % 1.0
        if avoid is not None and min(abs(hue - avoid), 1 - abs(hue - avoid)) < 0.15:
            hue = (avoid + 0.5 + (hue - avoid)) % 1.0
        rgb = colorsys.hsv_to_rgb(hue, rng.uniform(0.75, 0.95), rng.uniform(0.7, 0.95))
        out.append((np.asarray(rgb, np.float32) ** GAMMA).astype(np.float32))
    return out


def domains(seeds: Sequence[int]) -> Mapping[int, Domain]:
    """The domain each seed draws (for a report)."""
    return {s: Domain.draw(s) for s in seeds}
