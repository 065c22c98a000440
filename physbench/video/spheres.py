"""Lit spheres painted with numpy on a textured wall: frames with known centres, for measuring
what shading does to a tracker's centres (``benchmarks/track_shading.py``, the tracking tests).

Independent of the ``camera`` renderer on purpose (different code, its own shading model): a
sphere of ``radius`` px at a sub-pixel centre, Lambert shading with an ambient term from a light
in any direction, a white Blinn-Phong highlight that may saturate, anti-aliased by supersampling,
over a wall of random tiles, stains and grain; a global gain and offset per frame (the light),
Gaussian noise, optionally a camera's transfer function, and 8-bit quantisation. Pixel centres
are at integer ``(u, v)``, ``v`` down.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Sphere:
    """A lit sphere as the painter draws it: ``colour`` (linear RGB in [0, 1]), ``light`` (unit
    vector towards the light in image axes: ``u`` right, ``v`` down, ``z`` towards the viewer),
    ``ambient`` share of the light, ``specular`` strength and ``shininess`` of the highlight."""

    radius: float
    colour: tuple[float, float, float]
    light: tuple[float, float, float] = (-0.45, -0.55, 0.70)
    ambient: float = 0.25
    specular: float = 0.6
    shininess: float = 30.0

    def highlight(self) -> np.ndarray:
        """Unit vector ``(u, v)`` from the centre towards the highlight in the image."""
        # The half vector between the light and the view (0, 0, 1) has the light's (u, v)
        # direction.
        lu, lv = self.light[0], self.light[1]
        n = math.hypot(lu, lv)
        return np.array([lu / n, lv / n]) if n > 0 else np.zeros(2)


def wall(shape: tuple[int, int], seed: int, *, contrast: float = 1.0) -> np.ndarray:
    """A textured wall ``(H, W, 3)`` float32 in [0, 1]: tiles of random tone and tint, smooth
    stains and pixel grain (``contrast`` scales all three)."""
    h, w = shape
    rng = np.random.default_rng([seed, 31])
    vv, uu = np.mgrid[0:h, 0:w].astype(np.float32)
    tile = 8 + int(rng.integers(0, 24))
    ti, tj = (vv // tile).astype(np.int64), (uu // tile).astype(np.int64)
    table = rng.uniform(-1, 1, (h // tile + 2, w // tile + 2, 3)).astype(np.float32)
    base = np.asarray(rng.uniform(0.35, 0.7, 3), np.float32)
    img = base + contrast * 0.08 * table[ti, tj]
    for _ in range(3):
        k = rng.uniform(0.01, 0.06, 2)
        phase = rng.uniform(0, 2 * math.pi)
        img += (contrast * 0.05 * np.sin(k[0] * uu + k[1] * vv + phase))[..., None]
    img += contrast * 0.02 * rng.standard_normal((h, w, 3)).astype(np.float32)
    return np.clip(img, 0.0, 1.0)


def paint(
    img: np.ndarray,
    sphere: Sphere,
    centres: Sequence[Sequence[float]] | np.ndarray,
    *,
    supersample: int = 4,
) -> None:
    """Paint ``sphere`` into ``img`` (``(H, W, 3)`` float, in place), averaged over the
    ``centres`` ``(S, 2)`` (px) of one exposure: one centre is a still sphere, several a motion
    blur."""
    c = np.atleast_2d(np.asarray(centres, dtype=np.float64))
    r = float(sphere.radius)
    h, w = img.shape[:2]
    c0 = max(0, math.floor(c[:, 0].min() - r) - 2)
    c1 = min(w, math.ceil(c[:, 0].max() + r) + 3)
    r0 = max(0, math.floor(c[:, 1].min() - r) - 2)
    r1 = min(h, math.ceil(c[:, 1].max() + r) + 3)
    if c0 >= c1 or r0 >= r1:
        return
    off = (np.arange(supersample) + 0.5) / supersample - 0.5
    vv, uu = np.mgrid[r0:r1, c0:c1].astype(np.float64)
    su = (uu[..., None, None] + off[None, None, None, :]).reshape(*uu.shape, -1)
    sv = (vv[..., None, None] + off[None, None, :, None]).reshape(*vv.shape, -1)
    light = np.asarray(sphere.light, dtype=float) / np.linalg.norm(sphere.light)
    half = light + np.array([0.0, 0.0, 1.0])
    half /= np.linalg.norm(half)
    colour = np.asarray(sphere.colour, dtype=np.float64)
    alpha = np.zeros(uu.shape)
    premult = np.zeros((*uu.shape, 3))
    for cu, cv in c:
        nx, ny = (su - cu) / r, (sv - cv) / r
        rho2 = nx * nx + ny * ny
        inside = rho2 <= 1.0
        nz = np.sqrt(np.clip(1.0 - rho2, 0.0, 1.0))
        lam = np.clip(nx * light[0] + ny * light[1] + nz * light[2], 0.0, None)
        spec = np.clip(nx * half[0] + ny * half[1] + nz * half[2], 0.0, None) ** sphere.shininess
        shade = sphere.ambient + (1 - sphere.ambient) * lam
        col = shade[..., None] * colour + (sphere.specular * spec)[..., None]
        cov = inside.astype(np.float64)
        alpha += cov.mean(axis=-1)
        premult += (cov[..., None] * col).mean(axis=-2)
    alpha /= len(c)
    premult /= len(c)
    part = img[r0:r1, c0:c1]
    part *= (1 - alpha)[..., None]
    part += premult


def expose(
    img: np.ndarray,
    rng: np.random.Generator,
    *,
    gain: float | Sequence[float] = 1.0,
    offset: float = 0.0,
    noise: float = 0.01,
    gamma: float = 1.0,
) -> np.ndarray:
    """What the sensor records of the light ``img`` (``(H, W, 3)`` float in [0, 1]): times
    ``gain`` (one or per channel) plus ``offset``, Gaussian noise of std ``noise``, encoded by a
    ``1 / gamma`` power (a camera's transfer function: 2.2 for about BT.709 or sRGB; 1 keeps it
    linear), 8 bits."""
    out = img * np.asarray(gain, dtype=np.float64) + offset
    if noise > 0:
        out = out + noise * rng.standard_normal(out.shape)
    out = np.clip(out, 0.0, 1.0)
    if gamma != 1.0:
        out = out ** (1.0 / gamma)
    return np.rint(out * 255).astype(np.uint8)
