"""Centre bias on lit spheres with a highlight: the tracker's outline fit against the weighted
centroid it used before, over radii x colours x lights x walls, raw and H.264-coded, still and
motion-blurred.

    python benchmarks/track_shading.py [--out results/track/shading.json]
    python benchmarks/track_shading.py --gamma 2.2 --out results/track/shading_gamma22.json
    python benchmarks/track_shading.py --gamma 2.2 --flat --out results/track/flat_gamma22.json

Each case: a sphere painted with numpy (:mod:`physbench.video.spheres`, not the ``camera``
renderer: Lambert shading with an ambient share, a white Blinn-Phong highlight that may clip)
drifting slowly across a textured wall for 16 frames (320x240, noise 1 %), optionally blurred
over half the frame interval and coded as H.264 at CRF 23, tracked against the wall's plate. The
*bias* is the mean centre error along the direction of the highlight (px; negative: away from
it), the *error* the mean distance. The *centroid* columns weigh the blob's pixels by their
difference to the wall, as the tracker did before its centres came from the outline.
``--gamma 2.2`` encodes the painted light by a 1/2.2 power, about as a camera's BT.709 or sRGB
transfer does (the default keeps it linear, as the painter makes it). ``--flat`` paints the
same discs unshaded (all ambient light, no highlight): what is left of their bias is not the
shading's (the *bias* is then taken along the same light's highlight direction).
"""

from __future__ import annotations

import argparse
import itertools
import json
from pathlib import Path

import numpy as np

from physbench.calibration import Calibration
from physbench.codec import h264_round_trip
from physbench.scene import Body, Circle, Scene
from physbench.video.detect import find_blobs, plane_pose
from physbench.video.segment import difference, noise_threshold
from physbench.video.spheres import Sphere, expose, paint, wall
from physbench.video.track import track_frames

RADII = (6, 13, 17, 22)
COLOURS = {
    "red": (0.85, 0.15, 0.10),
    "blue": (0.10, 0.30, 0.90),
    "green": (0.20, 0.60, 0.20),
    "yellow": (0.90, 0.80, 0.10),
    "white": (0.90, 0.90, 0.90),
    "light grey": (0.65, 0.65, 0.65),
    "steel": (0.45, 0.47, 0.50),
    "black": (0.08, 0.08, 0.08),
}
LIGHTS = {
    "upper left": (-0.45, -0.55, 0.70),
    "upper right": (0.60, -0.30, 0.74),
    "above": (0.0, -0.80, 0.60),
    "low left": (-0.85, 0.10, 0.52),
}
SIZE = (240, 320)
FRAMES = 16
FPS = 30.0
MPP = 0.01


def _clip(
    radius: float,
    colour: tuple,
    light: tuple,
    seed: int,
    *,
    blur: bool,
    coded: bool,
    gamma: float = 1.0,
    flat: bool = False,
):
    """Frames, plate, true centres ``(T, 2)`` and the sphere of one case (``gamma``: the
    camera's transfer, :func:`~physbench.video.spheres.expose`; ``flat``: unshaded)."""
    rng = np.random.default_rng(seed)
    plate = wall(SIZE, seed)
    shading = {"ambient": 1.0, "specular": 0.0} if flat else {"ambient": 0.2, "specular": 0.7}
    sphere = Sphere(radius, colour, light, shininess=25.0, **shading)
    start = np.array([110.0, 110.0]) + rng.uniform(0, 1, 2)
    velocity = np.array([4.3, 1.7]) if blur else np.array([0.37, 0.21])  # px per frame
    offsets = np.linspace(-0.25, 0.25, 9) if blur else np.zeros(1)  # half the frame interval
    frames, truth = [], []
    for k in range(FRAMES):
        img = plate.astype(np.float64)
        centre = start + velocity * k
        paint(img, sphere, centre + velocity * offsets[:, None])
        frames.append(expose(img, rng, gamma=gamma))
        truth.append(centre)
    # The plate: the empty wall filmed by the same camera (its noise averaged away, as over a
    # few seconds of an empty scene), coded with the clip.
    clean = expose(plate.astype(np.float64), rng, noise=0.0, gamma=gamma)
    frames = np.stack([clean, *frames])
    if coded:
        frames = h264_round_trip(frames, FPS, 0, 23)
    return frames[1:], frames[0], np.array(truth), sphere, velocity


def _centroids(frames: np.ndarray, plate: np.ndarray, truth: np.ndarray, radius: float):
    """The weighted centroid (px) of the blob at each true centre, with the thresholds the
    tracker took from the first frame before (a share of the ball's contrast over the noise)."""
    diff0 = difference(frames[0], plate)
    r = max(1, int(0.4 * radius))
    u, v = np.rint(truth[0]).astype(int)
    contrast = float(np.percentile(diff0[v - r : v + r + 1, u - r : u + r + 1], 90))
    low = max(noise_threshold(frames[0], plate), 0.2 * contrast)
    high = max(low + 1.0, 0.5 * contrast)
    cal = Calibration.from_scale(1.0, (0.0, 0.0))
    out = []
    for img, (cu, cv) in zip(frames, truth, strict=True):
        blobs = find_blobs(difference(img, plate), low, high, min_area=0.15 * np.pi * radius**2)
        if not blobs:
            out.append((np.nan, np.nan))
            continue
        _, bu, bv, bw = min(blobs, key=lambda b: np.hypot(b[0].u - cu, b[0].v - cv))
        xy = plane_pose(bu, bv, bw, cal).xy
        out.append((xy[0], -xy[1]))  # back to image axes
    return np.array(out)


def run_case(
    radius, colour, light, seed, *, blur, coded, gamma: float = 1.0, flat: bool = False
) -> dict:
    frames, plate, truth, sphere, velocity = _clip(
        radius, COLOURS[colour], LIGHTS[light], seed, blur=blur, coded=coded, gamma=gamma,
        flat=flat,
    )  # fmt: skip
    h = SIZE[0]
    cal = Calibration.from_scale(MPP, (0.0, h - 1.0))
    x0, y0 = cal.to_scene(truth[0])
    vel = (velocity[0] * MPP * FPS, -velocity[1] * MPP * FPS)
    body = Body("ball", Circle(radius * MPP), (float(x0), float(y0)), velocity=vel)
    scene = Scene(
        "sphere", (body,), bounds=(0.0, 0.0, 3.2, 2.4), gravity=(0.0, 0.0), fps=FPS, frames=FRAMES
    ).validate()
    from physbench.video.reader import Frame

    result = track_frames(
        [Frame(k, k / FPS, img) for k, img in enumerate(frames)],
        scene,
        cal,
        plate,
        allow_gaps=True,
        subsampled=coded,  # H.264 at 4:2:0, as track_video reads from the file
        transfer="linear" if gamma == 1.0 else f"gamma{gamma:g}",
    )
    px = result.pixels["ball"]
    k = np.rint(px[:, 0] * FPS).astype(int)
    err = px[:, 1:] - truth[k]
    toward = sphere.highlight()
    cen = _centroids(frames, plate, truth, radius) - truth
    cen = cen[np.isfinite(cen).all(axis=1)]
    return {
        "radius": radius,
        "colour": colour,
        "light": light,
        "wall": seed,
        "blur": blur,
        "coded": coded,
        "frames": len(px),
        "centroid_frames": int(result.summary.centroids.get("ball", 0)),
        "bias_px": round(float(np.mean(err @ toward)), 4),
        "error_px": round(float(np.mean(np.hypot(*err.T))), 4),
        "centroid_bias_px": round(float(np.mean(cen @ toward)), 4),
        "centroid_error_px": round(float(np.mean(np.hypot(*cen.T))), 4),
    }


def summarise(cases: list[dict]) -> list[dict]:
    rows = []
    for radius in RADII:
        mine = [c for c in cases if c["radius"] == radius]
        bias = np.abs([c["bias_px"] for c in mine])
        cen = np.abs([c["centroid_bias_px"] for c in mine])
        raw = np.abs([c["bias_px"] for c in mine if not c["coded"]])
        coded = np.abs([c["bias_px"] for c in mine if c["coded"]])
        rows.append(
            {
                "radius": radius,
                "cases": len(mine),
                "missed_frames": sum(FRAMES - c["frames"] for c in mine),
                "centroid_frames": sum(c["centroid_frames"] for c in mine),
                "bias_median_px": round(float(np.median(bias)), 3),
                "bias_p95_px": round(float(np.percentile(bias, 95)), 3),
                "bias_max_px": round(float(bias.max()), 3),
                "bias_p95_raw_px": round(float(np.percentile(raw, 95)), 3),
                "bias_p95_coded_px": round(float(np.percentile(coded, 95)), 3),
                "centroid_bias_median_px": round(float(np.median(cen)), 3),
                "centroid_bias_p95_px": round(float(np.percentile(cen, 95)), 3),
                "centroid_bias_max_px": round(float(cen.max()), 3),
            }
        )
    return rows


def table(rows: list[dict]) -> str:
    head = (
        "| radius (px) | cases | frames missed | frames by centroid | bias: median | p95 | max | "
        "centroid bias: median | p95 | max |\n|---|---|---|---|---|---|---|---|---|---|\n"
    )
    body = "".join(
        f"| {r['radius']} | {r['cases']} | {r['missed_frames']} | {r['centroid_frames']} | "
        f"{r['bias_median_px']:.3f} | "
        f"{r['bias_p95_px']:.3f} | {r['bias_max_px']:.3f} | {r['centroid_bias_median_px']:.3f} | "
        f"{r['centroid_bias_p95_px']:.3f} | {r['centroid_bias_max_px']:.3f} |\n"
        for r in rows
    )
    return head + body


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/track/shading.json")
    ap.add_argument("--walls", type=int, default=3, help="wall seeds per case")
    ap.add_argument(
        "--gamma",
        type=float,
        default=1.0,
        choices=(1.0, 2.2, 2.8),
        help="the camera's transfer: the light encoded by a 1/gamma power (default 1: linear)",
    )
    ap.add_argument("--flat", action="store_true", help="unshaded discs: the coding's own bias")
    args = ap.parse_args()
    cases = []
    grid = itertools.product(
        RADII, COLOURS, LIGHTS, range(args.walls), (False, True), (False, True)
    )
    for radius, colour, light, seed, blur, coded in grid:
        cases.append(
            run_case(
                radius,
                colour,
                light,
                seed,
                blur=blur,
                coded=coded,
                gamma=args.gamma,
                flat=args.flat,
            )
        )
        print(json.dumps(cases[-1]), flush=True)
    rows = summarise(cases)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(
        json.dumps(
            {"gamma": args.gamma, "flat": args.flat, "summary": rows, "cases": cases}, indent=1
        )
        + "\n"
    )
    light = "linear light" if args.gamma == 1.0 else f"light encoded by a 1/{args.gamma:g} power"
    flag = ("" if args.gamma == 1.0 else f" --gamma {args.gamma:g}") + (
        " --flat" if args.flat else ""
    )
    what = "unshaded discs" if args.flat else "lit spheres with a highlight"
    out.with_suffix(".md").write_text(
        f"# Centre bias on {what} (px, |mean error along the highlight|)\n\n"
        f"`python benchmarks/track_shading.py{flag}` ({light}): the tracker's outline fit "
        "against the weighted centroid it used before; per radius over colours x lights x walls "
        "x (still, blurred) x (raw, H.264 CRF 23).\n\n" + table(rows)
    )
    print(table(rows))
    print(f"wrote {out} and {out.with_suffix('.md')}")


if __name__ == "__main__":
    main()
