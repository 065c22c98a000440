"""Tracking accuracy: centre error (px) and identity swaps over seeds x rack sizes x engines.

    python benchmarks/track_accuracy.py [--seeds 20] [--out results/track/accuracy.json]

Each case: the bouncing_balls rack with 2-6 balls (seed s gets 2 + s % 5 balls), simulated by
pymunk and box2d, filmed at 640x480 by the camera renderer (motion blur, noise, uneven flickering
light, H.264 at 1.5 Mbit/s), tracked against the plate with the true calibration. Truth is the
camera's projection of the simulated positions.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from physbench.components import create
from physbench.render.camera import CameraRenderer
from physbench.scenes import bouncing_balls
from physbench.video.accuracy import pixel_errors
from physbench.video.track import track_video
from physbench.video.writer import write_clip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--out", default="results/track/accuracy.json")
    args = ap.parse_args()
    cases, every = [], {"pymunk": [], "box2d": []}
    with tempfile.TemporaryDirectory() as tmp:
        for engine in ("pymunk", "box2d"):
            for seed in range(args.seeds):
                n = 2 + seed % 5
                scene = bouncing_balls.generate(seed, n_balls=n)
                traj = create("simulator", engine).simulate(scene)
                cam = CameraRenderer(
                    640, shutter=0.5, subframes=8, noise=0.02, bitrate=1_500_000, seed=seed
                )
                path = Path(tmp) / "clip.mp4"
                write_clip(cam, path, scene, traj)
                res = track_video(path, scene, cam.calibration(scene), background=cam.plate(scene))
                errors, swaps = pixel_errors(scene, traj, cam, res.pixels)
                missing = scene.frames * len(scene.bodies) - errors.size
                every[engine].append(errors)
                cases.append(
                    {
                        "engine": engine,
                        "seed": seed,
                        "balls": n,
                        "median_px": round(float(np.median(errors)), 4),
                        "p95_px": round(float(np.percentile(errors, 95)), 4),
                        "max_px": round(float(errors.max()), 4),
                        "swaps": swaps,
                        "missed": int(missing),
                    }
                )
                print(json.dumps(cases[-1]))
    summary = {}
    for engine, errs in every.items():
        e = np.concatenate(errs)
        summary[engine] = {
            "median_px": round(float(np.median(e)), 4),
            "p95_px": round(float(np.percentile(e, 95)), 4),
            "max_px": round(float(e.max()), 4),
            "swaps": sum(c["swaps"] for c in cases if c["engine"] == engine),
            "missed": sum(c["missed"] for c in cases if c["engine"] == engine),
            "measurements": int(e.size),
        }
        print(engine, summary[engine])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps({"summary": summary, "cases": cases}, indent=2) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
