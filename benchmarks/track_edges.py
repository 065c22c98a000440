"""Where the outline's edge points fall on lit spheres, by side of the sphere and by the difference
they are found on: what is left of the shading bias (``benchmarks/track_shading.py``) and why.

    python benchmarks/track_edges.py [--out results/track/edges.json]

Each case: a still sphere of ``track_shading``'s colours x lights x walls (3 by default), raw
or H.264-coded at CRF 23. In each frame, rays from the true centre with the true radius
(:func:`~physbench.video.silhouette.edge_points`, the tracker's edge finder) find edge points on
two differences from the plate: the tracker's (the largest over the colour channels) and the
luma difference ``|0.299 dR + 0.587 dG + 0.114 dB|``. Each edge's *offset* is its distance from
the true centre less the radius (px; positive: outside the disc), averaged per side: *toward* the
highlight (within 45 degrees of its direction), *away* from it, and the two *sides* between. A
circle fitted to all of a frame's edges (plain least squares, none dropped) gives a *bias* along
the highlight, as in ``track_shading``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
from pathlib import Path

import numpy as np

# The script's folder is first on sys.path when it runs: the clips are track_shading's.
from track_shading import COLOURS, LIGHTS, _clip

from physbench.video.segment import difference
from physbench.video.silhouette import Rays, edge_points

RADII = (6, 13)
#: Foreground threshold of the edge finder (grey levels), about the tracker's on these clips.
LOW = 12.0
LUMA = np.array([0.299, 0.587, 0.114], np.float32)


def luma_difference(image: np.ndarray, plate: np.ndarray) -> np.ndarray:
    """``|dY|`` of two ``(H, W, 3)`` uint8 images, uint8 ``(H, W)``."""
    d = (image.astype(np.float32) - plate.astype(np.float32)) @ LUMA
    return np.minimum(np.abs(d), 255).astype(np.uint8)


def _circle(uv: np.ndarray) -> np.ndarray:
    """The centre of the least-squares circle through ``uv`` ``(n, 2)`` (algebraic fit)."""
    a = np.column_stack([uv, np.ones(len(uv))])
    sol = np.linalg.lstsq(a, (uv**2).sum(axis=1), rcond=None)[0]
    return sol[:2] / 2


def run_case(radius: int, colour: str, light: str, wall: int, coded: bool) -> dict:
    frames, plate, truth, sphere, _ = _clip(
        radius, COLOURS[colour], LIGHTS[light], wall, blur=False, coded=coded
    )
    toward = sphere.highlight()
    heading = math.atan2(toward[1], toward[0])
    row: dict = {"radius": radius, "colour": colour, "light": light, "wall": wall, "coded": coded}
    for name, diff in (("colour", difference), ("luma", luma_difference)):
        sides = {"toward": [], "sides": [], "away": []}
        bias = []
        for img, centre in zip(frames, truth, strict=True):
            rays = [Rays(np.asarray(centre), float(radius), radius + 6.0)]
            e = edge_points(diff(img, plate), (0, 0), rays, LOW)
            if len(e.uv) < 5:
                continue
            off = e.reach - radius
            angle = np.abs((e.theta - heading + math.pi) % (2 * math.pi) - math.pi)
            sides["toward"] += off[angle <= math.pi / 4].tolist()
            sides["away"] += off[angle >= 3 * math.pi / 4].tolist()
            sides["sides"] += off[(angle > math.pi / 4) & (angle < 3 * math.pi / 4)].tolist()
            bias.append(float((_circle(e.uv) - centre) @ toward))
        for side, values in sides.items():
            row[f"{name}_{side}_px"] = round(float(np.mean(values)), 3) if values else None
        row[f"{name}_bias_px"] = round(float(np.mean(bias)), 3) if bias else None
    return row


def summarise(cases: list[dict]) -> list[dict]:
    """Per radius, coding and difference: the median offset on each side and the median and
    95th percentile of the |bias|."""
    rows = []
    for radius, coded, name in itertools.product(RADII, (False, True), ("colour", "luma")):
        mine = [c for c in cases if c["radius"] == radius and c["coded"] == coded]
        row = {"radius": radius, "coded": coded, "difference": name, "cases": len(mine)}
        for side in ("toward", "sides", "away"):
            vals = [c[f"{name}_{side}_px"] for c in mine if c[f"{name}_{side}_px"] is not None]
            row[f"{side}_median_px"] = round(float(np.median(vals)), 3)
        bias = np.abs([c[f"{name}_bias_px"] for c in mine if c[f"{name}_bias_px"] is not None])
        row["bias_median_px"] = round(float(np.median(bias)), 3)
        row["bias_p95_px"] = round(float(np.percentile(bias, 95)), 3)
        rows.append(row)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/track/edges.json")
    ap.add_argument("--walls", type=int, default=3, help="wall seeds per case")
    args = ap.parse_args()
    cases = []
    grid = itertools.product(RADII, COLOURS, LIGHTS, range(args.walls), (False, True))
    for radius, colour, light, wall, coded in grid:
        cases.append(run_case(radius, colour, light, wall, coded))
        print(json.dumps(cases[-1]), flush=True)
    rows = summarise(cases)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"low": LOW, "summary": rows, "cases": cases}, indent=1) + "\n")
    for r in rows:
        print(r)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
