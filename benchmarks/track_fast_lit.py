"""A fast ball's centre along its smear: a tossed ball filmed by the field camera, lit (its
default sphere: Lambert shading and a highlight) and flat-lit, over camera seeds.

    python benchmarks/track_fast_lit.py [--seeds 11 12 ...] [--out results/track/fast_lit.json]

Each case: a 4 cm ball tossed at (2, 3) m/s in a 1.6 x 1.2 m view at 30 fps (about 15 px in
radius, 25-43 px a frame: an exposure of a sixth to three fifths of the frame interval smears it
over 4-27 px), filmed square-on without a lens's distortion or a light drift, each seed drawing
the rest of the camera's domain (light direction, shutter, texture, CRF). Tracked against the
plate with the true calibration. Per clip: the median centre error (px) and the mean error
*along* the ball's motion (px; negative: the centre trails the ball), the shutter and the
light's azimuth. A flat-lit ball's smear is symmetric about its pose at mid-exposure; a lit one's
ends differ (one end is the lit limb, the other the shaded one).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from physbench.scene import Body, Circle, Scene
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.testing.field_camera import FieldCamera
from physbench.video.track import track_video
from physbench.video.writer import write_clip

#: Square-on, no lens distortion, steady light (as tests/commands/test_own_footage.py).
SQUARE_ON = {"oblique": 0.0, "k1": 0.0, "k2": 0.0, "drift": 0.0, "roll": 0.0}
#: A flat-lit ball: no shading, no highlight.
FLAT = {"ambient": 1.0, "specular": 0.0}


def toss() -> Scene:
    ball = Body("ball", Circle(0.04), (0.2, 0.3), velocity=(2.0, 3.0), mass=0.06)
    return Scene("toss", (ball,), bounds=(0.0, 0.0, 1.6, 1.2), fps=30.0, frames=18, substeps=20)


def run_case(seed: int, lit: bool) -> dict:
    scene = toss()
    traj = PymunkSimulator().simulate(scene)
    cam = FieldCamera(seed=seed, **SQUARE_ON, **({} if lit else FLAT))
    with tempfile.TemporaryDirectory() as tmp:
        clip = Path(tmp) / "toss.mp4"
        write_clip(cam, clip, scene, traj)
        result = track_video(clip, scene, cam.calibration(scene), background=cam.plate(scene))
    px = result.pixels["ball"]
    truth = cam.image_points(scene, np.asarray(traj.states)[:, 0, :2])
    k = np.rint(px[:, 0] * scene.fps).astype(int)
    err = px[:, 1:3] - truth[k]
    motion = np.gradient(truth, axis=0)[k]
    along = (err * motion).sum(axis=1) / np.hypot(*motion.T)
    domain = cam.describe()
    return {
        "seed": seed,
        "lit": lit,
        "frames": len(px),
        "median_px": round(float(np.median(np.hypot(*err.T))), 3),
        "along_px": round(float(np.mean(along)), 3),
        "speed_px": round(float(np.median(np.hypot(*motion.T))), 1),
        "shutter": round(float(domain["shutter"]), 3),
        "light_azimuth": round(float(domain["light_azimuth"]), 1),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=list(range(11, 19)))
    ap.add_argument("--out", default="results/track/fast_lit.json")
    args = ap.parse_args()
    cases = []
    for lit in (True, False):
        for seed in args.seeds:
            cases.append(run_case(seed, lit))
            print(json.dumps(cases[-1]), flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"cases": cases}, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
