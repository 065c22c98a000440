"""What the tracker's near search for a small disc (``physbench.video.track.NEAR``) changes on the
field camera's refused clips: each clip filmed again as the grid filmed it, tracked with gaps
allowed with and without the near search, every measured centre against the true one.

    python benchmarks/faint_near.py \\
        --results results/video_discover_field/hires_1280/results.json \\
        --out results/video_discover_field/hires_1280/near_search.json

Reads the refused rows (their ``field.failure``) of a results file of ``video_discover.py --camera
field`` (at the ``resolution`` it records, else 640). Per clip and body: frames seen without and
with the near search, the frames only one of them found, the errors (px) of those found only with
it, and the 95th percentile of each run's errors; per clip, whether either run missed a body in
more than a tenth of the clip's frames (the tracker refuses a clip that loses a body in more than a
tenth of the frames where it is in view, without ``--allow-gaps``; the balls of these throws stay
in view). Without the near search is ``NEAR_SIGNIFICANCE = inf``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np


def _clip(name: str, resolution: int, out: Path):
    from physbench.components import create
    from physbench.discover.synthetic import make_case
    from physbench.testing.field_camera import FieldCamera
    from physbench.testing.field_footage import camera_seed
    from physbench.video.footage import frame_trajectory, motion_view
    from physbench.video.writer import write_clip

    effect, scene, engine, seed = name.split("/")
    effect_name = None if effect == "control" else effect
    case = make_case(effect_name, scene, int(seed), create("simulator", engine))
    sc = case.run.scene
    traj = frame_trajectory(case.trajectory, np.arange(sc.frames) / sc.fps)
    cam = FieldCamera(resolution, seed=camera_seed(name), view=motion_view(sc, traj))
    write_clip(cam, out, sc, traj)
    states = np.asarray(traj.states)
    truth = {b.name: cam.image_points(sc, states[:, k, :2]) for k, b in enumerate(sc.bodies)}
    return sc, cam, truth


def _errors(result, truth: dict, fps: float) -> dict[str, dict[int, float]]:
    out = {}
    for body, px in result.pixels.items():
        k = np.rint(px[:, 0] * fps).astype(int)
        err = np.hypot(*(px[:, 1:] - truth[body][k]).T)
        out[body] = dict(zip(k.tolist(), err.tolist(), strict=True))
    return out


def run_case(name: str, resolution: int) -> dict:
    from physbench.video import track

    row: dict = {"case": name}
    with tempfile.TemporaryDirectory() as tmp:
        clip = Path(tmp) / "run.mp4"
        sc, cam, truth = _clip(name, resolution, clip)
        runs = {}
        for label, level in (("without", np.inf), ("with", track.NEAR_SIGNIFICANCE)):
            old = track.NEAR_SIGNIFICANCE
            track.NEAR_SIGNIFICANCE = level
            try:
                got = track.track_video(
                    clip, sc, cam.calibration(sc), background=cam.plate(sc), allow_gaps=True
                )
            except Exception as exc:  # a clip refused in its first frame either way
                row["failure"] = f"{type(exc).__name__}: {exc}"[:160]
                return row
            finally:
                track.NEAR_SIGNIFICANCE = old
            runs[label] = _errors(got, truth, sc.fps)
    bodies = {}
    for body, before in runs["without"].items():
        after = runs["with"].get(body, {})
        gained = sorted(after[k] for k in after if k not in before)
        bodies[body] = {
            "frames": sc.frames,
            "seen_without": len(before),
            "seen_with": len(after),
            "gained": len(gained),
            "dropped": sum(1 for k in before if k not in after),
            "gained_error_px": [round(e, 2) for e in gained],
            "p95_without_px": round(float(np.percentile(list(before.values()), 95)), 2),
            "p95_with_px": round(float(np.percentile(list(after.values()), 95)), 2),
        }
    row["bodies"] = bodies
    lost = {k: max(b["frames"] - b[f"seen_{k}"] for b in bodies.values()) for k in runs}
    row["refused_without"] = lost["without"] > 0.1 * sc.frames
    row["refused_with"] = lost["with"] > 0.1 * sc.frames
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results/video_discover_field/hires_1280/results.json")
    ap.add_argument("--out", default="results/video_discover_field/hires_1280/near_search.json")
    args = ap.parse_args()
    grid = json.loads(Path(args.results).read_text())
    resolution = grid.get("resolution", 640)
    rows = grid["rows"]
    refused = [r for r in rows if r["field"].get("failure")]
    out = []
    for r in refused:
        name = f"{r['effect'] or 'control'}/{r['scene']}/{r['engine']}/{r['seed']}"
        out.append(run_case(name, resolution))
        print(json.dumps(out[-1]), flush=True)
    done = [r for r in out if "bodies" in r]
    gained = [e for r in done for b in r["bodies"].values() for e in b["gained_error_px"]]
    summary = {
        "resolution": resolution,
        "clips": len(out),
        "refused_in_first_frame": len(out) - len(done),
        "refused_without": sum(r["refused_without"] for r in done),
        "refused_with": sum(r["refused_with"] for r in done),
        "frames_gained": len(gained),
        "frames_dropped": sum(b["dropped"] for r in done for b in r["bodies"].values()),
        "gained_error_median_px": round(float(np.median(gained)), 2) if gained else None,
        "gained_error_max_px": round(float(np.max(gained)), 2) if gained else None,
    }
    Path(args.out).write_text(json.dumps({"summary": summary, "rows": out}, indent=1) + "\n")
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
