"""Tracking speed: frames/s and peak memory of ``track_video`` on 5 s and 20 s 640x480 H.264 clips,
against decoding alone (the physical limit) in the same run.

    python benchmarks/track_speed.py [--out results/track/speed.json]

Clips: the bouncing_balls rack (6 balls) at 30 fps, filmed by the camera renderer with motion blur,
noise and a lossy bitrate, tracked against its plate (and once against the streamed median).
Speed is the best of two untraced runs, pinned to one core (``sched_setaffinity``: decoder and
tracker threads share it); memory is the peak of Python allocations (tracemalloc) in a separate,
traced run: flat in clip length.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
import tracemalloc
from dataclasses import replace
from pathlib import Path

from physbench.components import create
from physbench.render.camera import CameraRenderer
from physbench.scenes import bouncing_balls
from physbench.video.reader import VideoReader
from physbench.video.track import track_video
from physbench.video.writer import write_clip


def decode_fps(path: Path) -> float:
    tic, n = time.perf_counter(), 0
    for _ in VideoReader(path).frames():
        n += 1
    return n / (time.perf_counter() - tic)


def main() -> None:
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/track/speed.json")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seconds in (5, 20):
            scene = replace(bouncing_balls.generate(3, n_balls=6), frames=30 * seconds)
            traj = create("simulator", "pymunk").simulate(scene)
            cam = CameraRenderer(640, shutter=0.5, subframes=4, noise=0.02, bitrate=1_500_000)
            path = Path(tmp) / f"clip{seconds}.mp4"
            write_clip(cam, path, scene, traj)
            plate, cal = cam.plate(scene), cam.calibration(scene)
            decode = max(decode_fps(path) for _ in range(2))
            for background in ("plate", "median"):
                bg = plate if background == "plate" else None
                walls = []
                for _ in range(2):
                    tic = time.perf_counter()
                    res = track_video(path, scene, cal, background=bg)
                    walls.append(time.perf_counter() - tic)
                tracemalloc.start()
                track_video(path, scene, cal, background=bg)
                peak = tracemalloc.get_traced_memory()[1] / 2**20
                tracemalloc.stop()
                fps = res.summary.frames / min(walls)
                rows.append(
                    {
                        "seconds": seconds,
                        "frames": res.summary.frames,
                        "background": background,
                        "track_fps": round(fps, 1),
                        "decode_fps": round(decode, 1),
                        "ratio": round(fps / decode, 3),
                        "peak_mib": round(peak, 1),
                    }
                )
                print(
                    f"{seconds:>3} s {background:>6}: track {fps:6.1f} frames/s, decode alone "
                    f"{decode:6.1f} frames/s (ratio {fps / decode:.2f}), peak {peak:5.1f} MiB"
                )
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps({"clips": rows}, indent=2) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
