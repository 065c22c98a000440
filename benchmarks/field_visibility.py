"""Whether the field camera's refused clips hold their small bodies at all: per frame, the
matched filter's significance (:mod:`physbench.video.faint`) at each body's *true* pixel centre,
against the same filter's significance at random places 15-40 px away in the same frame.

No tracker is involved: this measures what the encoded pixels hold, so that a refusal of a clip
can be told apart from a tracker's miss. A body is "not in the frame" where its true position's
significance is below the 99th percentile of that clip's places without it.

    python benchmarks/field_visibility.py --results results/video_discover_field/results.json \\
        --out results/video_discover_field/visibility.json [--max-px 2.5]

A results file of a rerun at another resolution (``video_discover.py --resolution``) is filmed
at that resolution.

Reads the refused rows (their ``field.failure``) whose smallest body is under ``--max-px`` px in
radius (default 2.5), films each clip again exactly as the field grid did, and writes one row per
clip and body: frames in view, frames where the body is not in the pixels, the significance at
the truth (median) and the null's 99th percentile; the summary says how many of the refused
clips lose more than a tenth of their frames in the pixels themselves.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

#: Places without the body sampled per frame for the null distribution.
NULLS = 8


def _case(row: dict):
    from physbench.discover.synthetic import make_case
    from physbench.simulators.box2d_sim import Box2DSimulator
    from physbench.simulators.pymunk_sim import PymunkSimulator

    sim = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}[row["engine"]]()
    return make_case(row["effect"], row["scene"], int(row["seed"]), sim)


def visibility(row: dict, resolution: int = 640) -> list[dict]:
    """One refused field-grid row, filmed ``resolution`` pixels wide -> per body: how often its
    true position shows in the pixels."""
    import av

    from physbench.testing.field_camera import FieldCamera
    from physbench.testing.field_footage import camera_seed
    from physbench.video import faint
    from physbench.video.footage import frame_trajectory, motion_view
    from physbench.video.photometry import LightMeter
    from physbench.video.writer import write_clip

    case = _case(row)
    sc = case.run.scene
    traj = frame_trajectory(case.trajectory, np.arange(sc.frames) / sc.fps)
    name = "/".join(
        str(row[k]) if row[k] is not None else "control"
        for k in ("effect", "scene", "engine", "seed")
    )
    cam = FieldCamera(resolution, seed=camera_seed(name), view=motion_view(sc, traj))
    plate = cam.plate(sc)
    meter = LightMeter(plate)
    with tempfile.TemporaryDirectory() as tmp:
        clip = Path(tmp) / "run.mp4"
        write_clip(cam, clip, sc, traj)
        with av.open(str(clip)) as box:
            frames = [f.to_ndarray(format="rgb24") for f in box.decode(video=0)]
    rng = np.random.default_rng(0)
    out = []
    h, w = plate.shape[:2]
    for b, body in enumerate(sc.bodies):
        uv = cam.image_points(sc, traj.states[:, b, :2])
        mpp = cam.calibration(sc).metres_per_pixel(uv[0])
        radius = body.shape.extent() / mpp
        truth, null = [], []
        for k, image in enumerate(frames):
            if not (2 <= uv[k][0] < w - 2 and 2 <= uv[k][1] < h - 2):
                continue
            light = meter.measure(
                image, [(float(u), float(v), 8.0 + 3 * radius) for u, v in uv[k : k + 1]]
            )
            smear = 0.5 * (uv[k] - uv[k - 1]) if k else np.zeros(2)
            got = faint.find_faint(
                image, plate, light, uv[k], 1.5, radius, smear, significance=-np.inf
            )
            truth.append(got.significance if got is not None else 0.0)
            for _ in range(NULLS):
                a = rng.uniform(0, 2 * np.pi)
                place = uv[k] + rng.uniform(15, 40) * np.array([np.cos(a), np.sin(a)])
                q = faint.find_faint(
                    image, plate, light, place, 1.5, radius, smear, significance=-np.inf
                )
                null.append(q.significance if q is not None else 0.0)
        truth_a, null_a = np.array(truth), np.array(null)
        floor = float(np.percentile(null_a, 99))
        out.append(
            {
                "case": name,
                "body": body.name,
                "radius_px": round(float(radius), 2),
                "crf": row["field"]["domain"]["crf"],
                "texture": row["field"]["domain"]["texture"],
                "in_view": len(truth),
                "absent": int((truth_a < floor).sum()),
                "truth_median": round(float(np.median(truth_a)), 1),
                "null_p99": round(floor, 2),
                "failure": row["field"]["failure"][:120],
            }
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--results", type=Path, default=Path("results/video_discover_field/results.json")
    )
    ap.add_argument(
        "--out", type=Path, default=Path("results/video_discover_field/visibility.json")
    )
    ap.add_argument("--max-px", type=float, default=2.5)
    a = ap.parse_args()
    results = json.loads(a.results.read_text())
    resolution = results.get("resolution", 640)  # the grid's, or a rerun's --resolution
    rows = results["rows"]
    todo = [r for r in rows if r["field"].get("failure") and r["body_px"] < a.max_px]
    table = []
    for i, r in enumerate(todo):
        for got in visibility(r, resolution):
            table.append(got)
            print(
                f"[{i + 1}/{len(todo)}] {got['case']} {got['body']}: r {got['radius_px']} px, "
                f"absent in {got['absent']}/{got['in_view']} frames",
                flush=True,
            )
    worst = {}
    for t in table:
        worst[t["case"]] = max(worst.get(t["case"], 0.0), t["absent"] / max(t["in_view"], 1))
    summary = {
        "resolution": resolution,
        "clips": len(worst),
        "clips_absent_over_10pct": sum(v > 0.10 for v in worst.values()),
        "note": "absent: the matched filter's significance at the true centre is below the "
        "99th percentile of the same filter at places without the body, in the same clip",
    }
    a.out.write_text(json.dumps({"summary": summary, "rows": table}, indent=1) + "\n")
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
