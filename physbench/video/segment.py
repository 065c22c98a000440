"""Per-body masks segmented from a camera's frames, warped into the scene's frame.

The correction loop compares observed and simulated frames pixel by pixel, so a camera's video has
to become the frames the model renderer draws: the world rectangle ``scene.bounds`` filling the
image, y up, one channel layout (``mark``, ``instance`` or ``mask``). :class:`Segmenter` does that
for one frame at a time:

1. foreground: a pixel whose colour differs from the background (a plate of the empty scene or
   the video's median) by more than a threshold;
2. warp: every scene-frame pixel is sampled at ``supersample²`` points spread over it, each mapped
   into the camera image through the calibration (lens included) and read there by bilinear
   interpolation; the mean is the pixel's coverage, anti-aliased like the raster renderer's;
3. instances: a sample belongs to the body whose outline, at the pose the tracker measured in that
   frame, is nearest (signed distance, so touching bodies split along their contact), within
   ``reach`` metres; foreground far from every body (a passer-by, a shadow, clutter) is dropped.

The frames a camera makes differ from sharp renders (motion blur lengthens a fast body, lossy
coding frays edges): that difference is the visual gap ``benchmarks/video_gap.toml`` measures.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.render.raster import image_size
from physbench.scene import Circle

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.scene import Scene

#: Channel layouts a segmenter can produce (those of a mask renderer).
SEGMENT_MODES = ("mark", "instance", "mask")


class SegmentError(PhysbenchError, ValueError):
    """Frames, poses or settings that cannot be segmented: names the value and what fits."""


def difference(image: np.ndarray, background: np.ndarray) -> np.ndarray:
    """The largest absolute difference over the colour channels of two ``(H, W, 3)`` uint8
    images, uint8 ``(H, W)`` (computed in uint8: an order of magnitude faster than in int16)."""
    d = np.maximum(image, background)
    d -= np.minimum(image, background)
    out = np.maximum(d[..., 0], d[..., 1])
    return np.maximum(out, d[..., 2], out=out)


def foreground(image: np.ndarray, background: np.ndarray, threshold: float) -> np.ndarray:
    """Where ``image`` differs from ``background`` (both ``(H, W, 3)`` uint8) by more than
    ``threshold`` grey levels in any colour channel: float32 ``(H, W)`` of 0 and 1."""
    return (difference(image, background) > threshold).astype(np.float32)


def fill_holes(mask: np.ndarray, max_area: float) -> np.ndarray:
    """``mask`` (bool ``(H, W)``) with its holes of at most ``max_area`` pixels filled: a body is
    opaque, but where its colour nears the wall's (a highlight on a light wall) it falls under
    the threshold, and the hole changes the body's shape in the frames an estimator compares.
    Background regions larger than that, or touching the image's edge, stay."""
    from scipy import ndimage

    labels, n = ndimage.label(~mask)
    if n <= 1:
        return mask
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    small = sizes <= max_area
    small[0] = False
    edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    small[edge] = False
    return mask | small[labels] if small.any() else mask


def noise_threshold(image: np.ndarray, background: np.ndarray, *, floor: float = 12.0) -> float:
    """A foreground threshold from the frame's own noise: 6 robust standard deviations (from the
    median absolute difference, which the bodies' few pixels do not move), at least ``floor``."""
    sigma = 1.4826 * float(np.median(difference(image, background)))
    return max(floor, 6.0 * sigma)


def body_threshold(diff: np.ndarray, centres: np.ndarray, floor: float) -> float:
    """Half the median contrast of the bodies (``diff`` at the 3x3 pixels around each centre
    ``(N, 2)`` in pixels ``(u, v)`` that lies in the frame), at least ``floor``: a threshold at
    half contrast puts the outline where an anti-aliased or blurred edge is half covered, so a
    segmented body has its true area (measured on camera clips: within 2 %, where a threshold
    from the noise alone gave 5-7 % too much)."""
    h, w = diff.shape
    values = []
    for u, v in np.rint(np.asarray(centres, dtype=float)).astype(int):
        if 1 <= u < w - 1 and 1 <= v < h - 1:
            values.append(float(np.median(diff[v - 1 : v + 2, u - 1 : u + 2])))
    if not values:
        return floor
    return max(floor, 0.5 * float(np.median(values)))


class Segmenter:
    """Turns camera frames into the model renderer's frames (see the module docstring). Built once
    per video: the sample grid is fixed by the scene's bounds, ``resolution`` and the
    calibration."""

    def __init__(
        self,
        scene: Scene,
        calibration: Calibration,
        image_shape: tuple[int, int],
        *,
        resolution: int | tuple[int, int] = 64,
        mode: str = "mark",
        supersample: int = 4,
        reach: float | None = None,
    ) -> None:
        if mode not in SEGMENT_MODES:
            raise SegmentError(
                f"mode = {mode!r}: segmented frames come in the modes {', '.join(SEGMENT_MODES)}"
            )
        if supersample < 1:
            raise SegmentError(f"supersample = {supersample!r}: expected a whole number >= 1")
        self.scene, self.mode = scene, mode
        self.bodies = scene.body_names
        self.h, self.w = image_size(scene.bounds, resolution)
        ih, iw = image_shape
        xmin, ymin, xmax, ymax = scene.bounds
        px, py = (xmax - xmin) / self.w, (ymax - ymin) / self.h
        # Sub-pixel offsets spread evenly over each pixel (centres of an s x s grid).
        off = (np.arange(supersample) + 0.5) / supersample
        cols = xmin + (np.arange(self.w)[:, None] + off[None, :]).reshape(-1) * px
        rows = ymax - (np.arange(self.h)[:, None] + off[None, :]).reshape(-1) * py
        gx, gy = np.meshgrid(cols, rows)  # (H*s, W*s) scene coordinates of the samples
        self.xy = np.stack([gx, gy], axis=-1)
        uv = calibration.to_image(self.xy.reshape(-1, 2))
        self.coords = np.stack([uv[:, 1], uv[:, 0]])  # (row, col) for map_coordinates
        inside = (
            (uv[:, 0] >= -0.5)
            & (uv[:, 0] <= iw - 0.5)
            & (uv[:, 1] >= -0.5)
            & (uv[:, 1] <= ih - 0.5)
        )
        self.visible = float(inside.mean())
        self.s = supersample
        # A sample may belong to a body up to `reach` metres outside its outline: motion blur and
        # coding smear a body by a few pixels; default 3 camera pixels plus one scene pixel.
        centre = np.array([[(xmin + xmax) / 2, (ymin + ymax) / 2]])
        mpp = calibration.metres_per_pixel(calibration.to_image(centre)[0])
        self.reach = float(3 * mpp + max(px, py)) if reach is None else float(reach)
        self.image_shape = (ih, iw)

    def _signed_distances(self, poses: np.ndarray) -> np.ndarray:
        """``(N, H*s, W*s)`` signed distance (m) of every sample to each body at ``poses``."""
        out = np.empty((len(self.bodies), *self.xy.shape[:2]))
        for i, body in enumerate(self.scene.bodies):
            x, y, a = poses[i]
            dx, dy = self.xy[..., 0] - x, self.xy[..., 1] - y
            shape = body.shape
            if isinstance(shape, Circle):
                out[i] = np.hypot(dx, dy) - shape.radius
                continue
            c, s = np.cos(a), np.sin(a)
            lx, ly = c * dx + s * dy, -s * dx + c * dy  # into the body frame
            verts = np.asarray(shape.vertices(), dtype=float)
            edges = np.roll(verts, -1, axis=0) - verts
            normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)
            normals /= np.linalg.norm(normals, axis=1, keepdims=True)
            d = (normals * verts).sum(axis=1)
            out[i] = np.max(
                lx[None] * normals[:, 0, None, None]
                + ly[None] * normals[:, 1, None, None]
                - d[:, None, None],
                axis=0,
            )
        return out

    def coverage(self, fg: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Per-body coverage ``(N, H, W)`` in [0, 1] of foreground ``fg`` (``(H, W)`` of the camera
        image) with the bodies at ``poses`` (``(N, 3)``: x, y, angle in the scene, in
        ``scene.bodies`` order)."""
        from scipy.ndimage import map_coordinates

        poses = np.asarray(poses, dtype=float)
        if poses.shape != (len(self.bodies), 3):
            raise SegmentError(
                f"poses have shape {poses.shape}; expected ({len(self.bodies)}, 3): x, y, angle "
                f"of {', '.join(self.bodies)}"
            )
        if fg.shape != self.image_shape:
            raise SegmentError(
                f"frame is {fg.shape[1]}x{fg.shape[0]} px; this video's frames are "
                f"{self.image_shape[1]}x{self.image_shape[0]} px"
            )
        samples = map_coordinates(fg, self.coords, order=1, mode="constant", cval=0.0)
        samples = samples.reshape(self.xy.shape[:2])
        sd = self._signed_distances(poses)
        owner = np.argmin(sd, axis=0)
        near = np.take_along_axis(sd, owner[None], axis=0)[0] <= self.reach
        out = np.zeros((len(self.bodies), self.h, self.w), np.float32)
        s = self.s
        for i in range(len(self.bodies)):
            mine = np.where((owner == i) & near, samples, 0.0)
            out[i] = mine.reshape(self.h, s, self.w, s).mean(axis=(1, 3))
        return out

    def frame(self, coverage: np.ndarray, focus: str | None = None) -> np.ndarray:
        """One frame ``(C, H, W)`` in this segmenter's mode from per-body ``coverage``: the
        channels the model renderer draws (``focus`` marks a body in ``mark`` mode)."""
        if focus is not None and focus not in self.bodies:
            raise UnknownNameError("body", focus, self.bodies)
        if self.mode == "instance":
            return coverage.astype(np.float32, copy=True)
        if self.mode == "mask":
            return coverage.max(axis=0, keepdims=True)
        out = np.zeros((2, self.h, self.w), np.float32)
        others = [i for i, b in enumerate(self.bodies) if b != focus]
        if others:
            out[0] = coverage[others].max(axis=0)
        if focus is not None:
            out[1] = coverage[self.bodies.index(focus)]
        return out

    def frames(self, coverages: Sequence[np.ndarray], focus: str | None = None) -> np.ndarray:
        """``(T, C, H, W)`` float32 from a sequence of per-body coverages."""
        return np.stack([self.frame(c, focus) for c in coverages])
