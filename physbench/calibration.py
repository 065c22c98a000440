"""Camera calibration: image pixels to the scene's metres, for a planar scene.

A :class:`Calibration` is a plane homography ``H`` (3 x 3) from undistorted pixel coordinates
``(u, v)`` (``u`` to the right, ``v`` down, pixel centres at integers: the centre of the top-left
pixel is ``(0, 0)``, its top-left corner ``(-0.5, -0.5)``) to scene coordinates ``(x, y)`` in
metres (``y`` up), plus optional radial lens distortion. :func:`load_calibration` reads it from
one of these files:

A TOML file with exactly one of four tables (:func:`loads_calibration`):

``[scale]``
    ``metres_per_pixel`` and ``origin_pixel`` (the pixel of the scene's origin): a camera looking
    straight at the plane of motion.
``[[points]]``
    four or more ``image = [u, v]`` / ``scene = [x, y]`` pairs: any view of the plane, oblique
    included. The homography is the direct linear transform on normalised coordinates, refined by
    least squares on the reprojection error in pixels.
``[body]``
    ``pixels`` and ``metres``: the size of an object of known size in the image (e.g. a ball's
    diameter) and in the scene, with ``origin_pixel``; the same as ``[scale]`` with the scale from
    that object.
``[homography]``
    ``matrix``: the 3 x 3 homography itself, rows of ``[a, b, c]`` mapping ``(u, v, 1)`` to
    ``(x, y, 1)`` up to scale, with an optional top-level ``reprojection_error_px``. This is what
    :meth:`Calibration.to_toml` writes: any calibration, saved exactly.

``[lens]`` (optional, with any of them) holds Brown's radial distortion ``k1``, ``k2`` about the
principal point ``centre`` (pixels) with focal length ``focal`` (pixels): a pixel at normalised
radius ``r`` from the centre was seen at ``r (1 + k1 r² + k2 r⁴)``.

A CSV file (``.csv``, :func:`loads_calibration_csv`) of image <-> scene point pairs, one per
row, under a header naming the columns ``u, v, x, y`` (in any order; lines starting with ``#``
are skipped): the same as ``[[points]]``, for points measured in another program. Mind its pixel
convention: a program that puts the top-left *corner* of the image at ``(0, 0)`` (Tracker, ImageJ)
has pixel centres at ``.5``; subtract 0.5 from its ``u`` and ``v``.

A Tracker project (``.trz`` or ``.trk``, :mod:`physbench.tracker_files`): its fixed coordinate
system (origin, axis angle in degrees, scale in pixels per length unit, converted to metres), with
Tracker's pixel centres at ``.5`` shifted to physbench's integers.

:attr:`Calibration.reprojection_error` is the RMS distance in pixels between the given image
points and the scene points mapped back into the image (0 for a scale, which fits no points).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from physbench.errors import PhysbenchError

#: Largest ratio of the smallest to the largest singular value of the centred scene or image
#: points below which the points count as collinear: they cannot fix a plane homography.
COLLINEAR = 1e-6
_KEYS = {"scale", "points", "body", "lens"}
_LENS_KEYS = {"k1", "k2", "centre", "focal"}


class CalibrationError(PhysbenchError, ValueError):
    """A calibration that cannot map pixels to metres: names the key or points and why."""


@dataclass(frozen=True)
class Lens:
    """Brown's radial distortion: ``k1``, ``k2`` about ``centre`` (px), normalised by ``focal``
    (px)."""

    k1: float = 0.0
    k2: float = 0.0
    centre: tuple[float, float] = (0.0, 0.0)
    focal: float = 1.0

    def distort(self, uv: np.ndarray) -> np.ndarray:
        """Where undistorted pixels ``(..., 2)`` appear in the image."""
        p = (np.asarray(uv, dtype=float) - self.centre) / self.focal
        r2 = (p * p).sum(axis=-1, keepdims=True)
        return p * (1 + self.k1 * r2 + self.k2 * r2 * r2) * self.focal + self.centre

    def undistort(self, uv: np.ndarray) -> np.ndarray:
        """The undistorted pixels of image pixels ``(..., 2)`` (fixed-point inverse of
        :meth:`distort`, converged to 1e-12 of the focal length for the distortion of real
        lenses)."""
        q = (np.asarray(uv, dtype=float) - self.centre) / self.focal
        p = q.copy()
        for _ in range(50):
            r2 = (p * p).sum(axis=-1, keepdims=True)
            nxt = q / (1 + self.k1 * r2 + self.k2 * r2 * r2)
            if np.abs(nxt - p).max(initial=0.0) < 1e-12:
                p = nxt
                break
            p = nxt
        return p * self.focal + self.centre


@dataclass(frozen=True)
class Calibration:
    """Pixels -> metres on the scene's plane (see the module docstring)."""

    homography: np.ndarray  # (3, 3): undistorted (u, v, 1) -> (x, y, 1) up to scale
    lens: Lens | None = None
    reprojection_error: float = 0.0  # px, RMS over the fitted points
    source: str = ""

    def to_scene(self, uv: Sequence[float] | np.ndarray) -> np.ndarray:
        """Scene metres ``(..., 2)`` of image pixels ``(..., 2)``."""
        uv = np.asarray(uv, dtype=float)
        if self.lens is not None:
            uv = self.lens.undistort(uv)
        return _apply(self.homography, uv)

    @cached_property
    def _inverse(self) -> np.ndarray:
        """The homography's inverse: scene metres to undistorted pixels (the tracker maps its
        predictions with it several times a frame)."""
        return np.linalg.inv(self.homography)

    def to_image(self, xy: Sequence[float] | np.ndarray) -> np.ndarray:
        """Image pixels ``(..., 2)`` of scene metres ``(..., 2)``."""
        uv = _apply(self._inverse, np.asarray(xy, dtype=float))
        return uv if self.lens is None else self.lens.distort(uv)

    def metres_per_pixel(self, uv: Sequence[float]) -> float:
        """The local scale at pixel ``uv``: the geometric mean of how far one pixel right and one
        pixel down move in the scene."""
        p = np.asarray(uv, dtype=float)
        x0, xu, xv = self.to_scene(p + np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
        return math.sqrt(float(np.linalg.norm(xu - x0) * np.linalg.norm(xv - x0)))

    # ----------------------------------------------------------------- the three ways

    @classmethod
    def from_scale(
        cls,
        metres_per_pixel: float,
        origin_pixel: Sequence[float],
        *,
        lens: Lens | None = None,
        source: str = "",
    ) -> Calibration:
        """A camera looking straight at the plane: ``metres_per_pixel``, and the pixel of the
        scene's origin (``y`` up, so ``v`` down is ``-y``)."""
        s = _positive("scale.metres_per_pixel", metres_per_pixel)
        u0, v0 = _pair("scale.origin_pixel", origin_pixel)
        h = np.array([[s, 0.0, -s * u0], [0.0, -s, s * v0], [0.0, 0.0, 1.0]])
        return cls(h, lens, 0.0, source)

    @classmethod
    def from_points(
        cls,
        image: Sequence[Sequence[float]] | np.ndarray,
        scene: Sequence[Sequence[float]] | np.ndarray,
        *,
        lens: Lens | None = None,
        source: str = "",
    ) -> Calibration:
        """The homography through four or more image <-> scene point pairs (image points are
        undistorted with ``lens`` first)."""
        uv = np.asarray(image, dtype=float)
        xy = np.asarray(scene, dtype=float)
        if uv.ndim != 2 or uv.shape[1:] != (2,) or uv.shape != xy.shape:
            raise CalibrationError(
                f"points: expected pairs of [u, v] image and [x, y] scene points, got "
                f"{uv.shape[0] if uv.ndim else 0} image and {xy.shape[0] if xy.ndim else 0} scene "
                "points"
            )
        if len(uv) < 4:
            raise CalibrationError(
                f"points: {len(uv)} pairs given; a plane homography needs at least 4"
            )
        if not (np.isfinite(uv).all() and np.isfinite(xy).all()):
            raise CalibrationError("points: every coordinate must be a finite number")
        for what, pts in (("scene", xy), ("image", uv)):
            if _collinear(pts):
                raise CalibrationError(
                    f"points: the {what} points {pts.tolist()} lie on one line (or coincide); "
                    "they cannot fix the plane: give 4 or more points, no 3 of them on a line"
                )
        und = uv if lens is None else lens.undistort(uv)
        h = _refine(_dlt(und, xy), und, xy)
        cal = cls(h, lens, 0.0, source)
        err = np.linalg.norm(cal.to_image(xy) - uv, axis=1)
        return cls(h, lens, float(np.sqrt(np.mean(err * err))), source)

    @classmethod
    def from_body_size(
        cls,
        pixels: float,
        metres: float,
        origin_pixel: Sequence[float],
        *,
        lens: Lens | None = None,
        source: str = "",
    ) -> Calibration:
        """The scale from an object of known size: ``pixels`` across in the image, ``metres``
        across in the scene."""
        p = _positive("body.pixels", pixels)
        m = _positive("body.metres", metres)
        return cls.from_scale(m / p, origin_pixel, lens=lens, source=source)

    # ----------------------------------------------------------------- files

    def to_toml(self) -> str:
        """The calibration as a ``[homography]`` TOML table (what :func:`load_calibration` reads
        back exactly), with the lens and the reprojection error."""
        import tomli_w

        data: dict[str, Any] = {
            "homography": {"matrix": [[float(v) for v in row] for row in self.homography]},
            "reprojection_error_px": float(self.reprojection_error),
        }
        if self.lens is not None:
            data["lens"] = {
                "k1": self.lens.k1,
                "k2": self.lens.k2,
                "centre": list(self.lens.centre),
                "focal": self.lens.focal,
            }
        return tomli_w.dumps(data)


def _apply(h: np.ndarray, p: np.ndarray) -> np.ndarray:
    q = p @ h[:, :2].T + h[:, 2]
    return q[..., :2] / q[..., 2:3]


def _collinear(pts: np.ndarray) -> bool:
    centred = pts - pts.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    return bool(s[0] == 0 or s[-1] / s[0] < COLLINEAR)


def _normaliser(pts: np.ndarray) -> np.ndarray:
    """Hartley's normalisation: centre on the mean, mean distance sqrt(2)."""
    c = pts.mean(axis=0)
    d = np.sqrt(((pts - c) ** 2).sum(axis=1)).mean()
    s = math.sqrt(2) / d
    return np.array([[s, 0, -s * c[0]], [0, s, -s * c[1]], [0, 0, 1]])


def _dlt(uv: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """The direct linear transform ``uv -> xy`` on normalised points."""
    tu, tx = _normaliser(uv), _normaliser(xy)
    a, b = _apply(tu, uv), _apply(tx, xy)
    rows = []
    for (u, v), (x, y) in zip(a, b, strict=True):
        rows.append([-u, -v, -1, 0, 0, 0, x * u, x * v, x])
        rows.append([0, 0, 0, -u, -v, -1, y * u, y * v, y])
    _, _, vt = np.linalg.svd(np.asarray(rows))
    hn = vt[-1].reshape(3, 3)
    h = np.linalg.inv(tx) @ hn @ tu
    return h / h[2, 2]


def _refine(h0: np.ndarray, uv: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """``h0`` refined to the least-squares reprojection error in pixels (scene points mapped into
    the image), which is what a person marking points in the image gets wrong."""
    if len(uv) == 4:
        return h0  # exact through four points
    from scipy.optimize import least_squares

    def residuals(p: np.ndarray) -> np.ndarray:
        inv = np.append(p, 1.0).reshape(3, 3)
        return (_apply(inv, xy) - uv).ravel()

    inv0 = np.linalg.inv(h0)
    fit = least_squares(residuals, (inv0 / inv0[2, 2]).ravel()[:8], method="lm")
    h = np.linalg.inv(np.append(fit.x, 1.0).reshape(3, 3))
    return h / h[2, 2]


def _number(key: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise CalibrationError(f"{key} = {value!r}: expected a finite number")
    return float(value)


def _positive(key: str, value: object) -> float:
    v = _number(key, value)
    if v <= 0:
        raise CalibrationError(f"{key} = {value!r}: expected a number > 0")
    return v


def _pair(key: str, value: object) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise CalibrationError(f"{key} = {value!r}: expected a pair [u, v] of numbers")
    return (_number(f"{key}[0]", value[0]), _number(f"{key}[1]", value[1]))


def _table(data: Mapping[str, Any], key: str, allowed: set[str]) -> Mapping[str, Any]:
    table = data[key]
    if not isinstance(table, dict):
        raise CalibrationError(f"{key}: expected a table [{key}], got {table!r}")
    extra = sorted(set(table) - allowed)
    if extra:
        raise CalibrationError(
            f"{key}.{extra[0]}: unknown key; known: {', '.join(sorted(allowed))}"
        )
    return table


def _lens(data: Mapping[str, Any]) -> Lens | None:
    if "lens" not in data:
        return None
    t = _table(data, "lens", _LENS_KEYS)
    missing = sorted({"centre", "focal"} - set(t))
    if missing:
        raise CalibrationError(
            f"lens: missing {', '.join(missing)} (the principal point and focal)"
        )
    return Lens(
        k1=_number("lens.k1", t.get("k1", 0.0)),
        k2=_number("lens.k2", t.get("k2", 0.0)),
        centre=_pair("lens.centre", t["centre"]),
        focal=_positive("lens.focal", t["focal"]),
    )


def loads_calibration(text: str, *, source: str = "") -> Calibration:
    """A calibration from TOML text (see the module docstring for the tables)."""
    where = f"{source}: " if source else ""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CalibrationError(f"{where}not valid TOML: {exc}") from None
    known = {*_KEYS, "homography", "reprojection_error_px"}
    extra = sorted(set(data) - known)
    if extra:
        raise CalibrationError(f"{where}{extra[0]}: unknown key; known: {', '.join(sorted(known))}")
    ways = [k for k in ("scale", "points", "body", "homography") if k in data]
    if len(ways) != 1:
        raise CalibrationError(
            f"{where}expected exactly one of [scale], [[points]], [body] or [homography], got "
            f"{', '.join(ways) or 'none'}"
        )
    try:
        lens = _lens(data)
        way = ways[0]
        if way == "scale":
            t = _table(data, "scale", {"metres_per_pixel", "origin_pixel"})
            return Calibration.from_scale(
                t.get("metres_per_pixel"), t.get("origin_pixel"), lens=lens, source=source
            )
        if way == "body":
            t = _table(data, "body", {"pixels", "metres", "origin_pixel"})
            return Calibration.from_body_size(
                t.get("pixels"), t.get("metres"), t.get("origin_pixel"), lens=lens, source=source
            )
        if way == "points":
            pts = data["points"]
            if not isinstance(pts, list) or not all(isinstance(p, dict) for p in pts):
                raise CalibrationError("points: expected [[points]] tables with image and scene")
            image, scene = [], []
            for i, p in enumerate(pts):
                bad = sorted(set(p) - {"image", "scene"})
                if bad:
                    raise CalibrationError(
                        f"points[{i}].{bad[0]}: unknown key; known: image, scene"
                    )
                image.append(_pair(f"points[{i}].image", p.get("image")))
                scene.append(_pair(f"points[{i}].scene", p.get("scene")))
            return Calibration.from_points(image, scene, lens=lens, source=source)
        t = _table(data, "homography", {"matrix"})
        h = np.asarray(t.get("matrix"), dtype=float)
        if h.shape != (3, 3) or not np.isfinite(h).all() or abs(np.linalg.det(h)) < 1e-300:
            raise CalibrationError("homography.matrix: expected an invertible 3 x 3 matrix")
        err = _number("reprojection_error_px", data.get("reprojection_error_px", 0.0))
        return Calibration(h, lens, err, source)
    except CalibrationError as exc:
        raise CalibrationError(f"{where}{exc}") from None


def loads_calibration_csv(text: str, *, source: str = "") -> Calibration:
    """A calibration through the image <-> scene point pairs of CSV text with the columns ``u, v,
    x, y`` (see the module docstring)."""
    import csv
    import io

    where = f"{source}: " if source else ""
    rows = [
        (n, r)
        for n, r in enumerate(csv.reader(io.StringIO(text.removeprefix("\ufeff"))), start=1)
        if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")
    ]
    if not rows:
        raise CalibrationError(f"{where}empty; expected a header u,v,x,y and 4 or more rows")
    line, header = rows[0]
    names = [c.strip() for c in header]
    want = ("u", "v", "x", "y")
    if sorted(names) != sorted(want):
        raise CalibrationError(
            f"{where}line {line}: header {','.join(names)}; expected the columns u, v, x, y "
            "(image pixels, scene metres) in any order"
        )
    col = {name: names.index(name) for name in want}
    image, scene = [], []
    for line, r in rows[1:]:
        if len(r) != 4:
            raise CalibrationError(f"{where}line {line}: {len(r)} values; expected 4 (u, v, x, y)")
        try:
            vals = {k: float(r[i]) for k, i in col.items()}
        except ValueError:
            raise CalibrationError(
                f"{where}line {line}: {r} holds a value that is not a number"
            ) from None
        image.append((vals["u"], vals["v"]))
        scene.append((vals["x"], vals["y"]))
    try:
        return Calibration.from_points(image, scene, source=source)
    except CalibrationError as exc:
        raise CalibrationError(f"{where}{exc}") from None


def load_calibration(path: str | Path) -> Calibration:
    """Read a calibration file (TOML, CSV of point pairs, or a Tracker project: see the module
    docstring); errors name the file and the key."""
    from physbench.tracker_files import is_tracker_file, read_tracker_project, tracker_path

    tracker = is_tracker_file(path)
    p = tracker_path(path)[0] if tracker else Path(path)
    if not p.is_file():
        raise CalibrationError(f"calibration file {str(p)!r} does not exist")
    if tracker:
        project = read_tracker_project(path)
        return Calibration(project.homography(), None, 0.0, project.source)
    suffix = p.suffix.lower()
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CalibrationError(f"{p}: cannot read as UTF-8 text ({exc})") from None
    if suffix == ".csv":
        return loads_calibration_csv(text, source=str(p))
    return loads_calibration(text, source=str(p))
