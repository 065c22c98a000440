"""Tracking speed: frames/s and peak memory of ``track_video`` on 5 s and 20 s 640x480 H.264 clips,
against decoding alone (the physical limit) in the same run.

    python benchmarks/track_speed.py [--repeats 5] [--out results/track/speed.json]

Clips: the bouncing_balls rack (6 balls) at 30 fps, filmed by the camera renderer with motion blur,
noise, flickering light and a lossy bitrate, tracked against its plate and against the streamed
median. Pinned to one core (``sched_setaffinity``: decoder and tracker threads share it). Speed is
taken in CPU time (``time.process_time``), the best of ``--repeats`` runs, alternating tracking
and decoding: on a machine shared with other work, wall-clock time counts the others' turns, CPU
time the process's own (the best of several runs least of what sharing the caches costs). Wall
time is recorded beside it. Memory is the peak of Python allocations (tracemalloc) in a separate,
traced run: flat in clip length. ``once``: what a fresh process's first tracking of the 5 s clip
costs on top of the others (CPU s: loading numba and the tracker's compiled loops from their disk
cache, and with an empty cache compiling them: the first run after installing).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import subprocess
import sys
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


def _timed(fn, *args, **kwargs) -> tuple[float, float]:
    """CPU and wall seconds of ``fn(*args, **kwargs)``."""
    c, w = time.process_time(), time.perf_counter()
    fn(*args, **kwargs)
    return time.process_time() - c, time.perf_counter() - w


def _track(path: Path, scene, cal, background):
    """``track_video``, gaps allowed: a ball of this rack comes to rest for over half of the clip,
    where the median background holds it (the tracker says so; the speed is what is measured)."""
    import inspect

    gaps = "allow_gaps" in inspect.signature(track_video).parameters  # older trackers had none
    options = {"allow_gaps": True} if gaps else {}
    return track_video(path, scene, cal, background=background, **options)


def _decode(path: Path) -> None:
    for _ in VideoReader(path).frames():
        pass


#: A fresh process's first and second tracking of a clip (CPU s), for :func:`_once`.
_FIRST_CALLS = """
import pickle, sys, time
from physbench.video.track import track_video
path, scene, cal, bg = pickle.load(open(sys.argv[1], "rb"))
times = []
for _ in range(2):
    c = time.process_time()
    track_video(path, scene, cal, background=bg, allow_gaps=True)
    times.append(time.process_time() - c)
print(times[0], times[1])
"""


def _once(path: Path, scene, cal, plate, cache: str | None) -> float:
    """CPU s a fresh process's first tracking of ``path`` costs over its second, with numba's
    cache in ``cache`` (``None``: where it is kept)."""
    args = Path(path).with_suffix(".pkl")
    args.write_bytes(pickle.dumps((str(path), scene, cal, plate)))
    env = {**os.environ, **({"NUMBA_CACHE_DIR": cache} if cache else {})}
    out = subprocess.run(
        [sys.executable, "-c", _FIRST_CALLS, str(args)],
        capture_output=True, text=True, check=True, env=env,
    )  # fmt: skip
    first, second = (float(x) for x in out.stdout.split())
    return first - second


def main() -> None:
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/track/speed.json")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    rows, once = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        for seconds in (5, 20):
            scene = replace(bouncing_balls.generate(3, n_balls=6), frames=30 * seconds)
            traj = create("simulator", "pymunk").simulate(scene)
            cam = CameraRenderer(640, shutter=0.5, subframes=4, noise=0.02, bitrate=1_500_000)
            path = Path(tmp) / f"clip{seconds}.mp4"
            write_clip(cam, path, scene, traj)
            plate, cal = cam.plate(scene), cam.calibration(scene)
            for background in ("plate", "median"):
                bg = plate if background == "plate" else None
                track, decode = [], []
                for _ in range(args.repeats):
                    track.append(_timed(_track, path, scene, cal, bg))
                    decode.append(_timed(_decode, path))
                tracemalloc.start()
                res = _track(path, scene, cal, bg)
                peak = tracemalloc.get_traced_memory()[1] / 2**20
                tracemalloc.stop()
                n = res.summary.frames
                cpu, wall = n / min(t[0] for t in track), n / min(t[1] for t in track)
                dcpu, dwall = n / min(t[0] for t in decode), n / min(t[1] for t in decode)
                rows.append(
                    {
                        "seconds": seconds,
                        "frames": n,
                        "background": background,
                        "track_fps": round(cpu, 1),
                        "decode_fps": round(dcpu, 1),
                        "ratio": round(cpu / dcpu, 3),
                        "track_wall_fps": round(wall, 1),
                        "decode_wall_fps": round(dwall, 1),
                        "peak_mib": round(peak, 1),
                    }
                )
                print(
                    f"{seconds:>3} s {background:>6}: track {cpu:6.1f} frames/CPU-s "
                    f"({wall:6.1f} wall), decode alone {dcpu:6.1f} (ratio {cpu / dcpu:.2f}), "
                    f"peak {peak:5.1f} MiB",
                    flush=True,
                )
            if seconds == 5:
                _once(path, scene, cal, plate, None)  # the disk cache holds the loops now
                once["cached_s"] = round(_once(path, scene, cal, plate, None), 2)
                once["compiling_s"] = round(_once(path, scene, cal, plate, f"{tmp}/cache"), 2)
                print(
                    f"a fresh process's first tracking costs {once['cached_s']} CPU s more "
                    f"({once['compiling_s']} s with an empty cache: compiling)",
                    flush=True,
                )
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps({"clips": rows, "once": once}, indent=2) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
