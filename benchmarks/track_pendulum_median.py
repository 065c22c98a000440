"""Pendulums filmed by the second camera and tracked without a plate: how far the clip's median
background puts the arms off, against the plate, and what measuring a cut-short arm from its
seen end (``Tracker._from_one_end``) changes.

    python benchmarks/track_pendulum_median.py [--seeds 0 2] \
        [--out results/track/pendulum_median.json]

Cases: every hidden-effect case on a pendulum scene (``EFFECT_SCENES``), both engines, each seed,
filmed as ``benchmarks/video_discover.py --camera field`` films it (its own camera domain, a
four-point calibration), tracked three ways: against the camera's plate; against the clip's
median with both ends of a rod always taken as seen (``ENDS_WHOLE = 0``: the tracker before
``held.Held.unknown``); against the median as the tracker does now. Per body: the centre
error's median, 95th percentile and largest (px, the tracked metres projected against the true
ones), the accuracy the tracker states, and the bodies the median held.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from physbench.calibration import Calibration
from physbench.discover.synthetic import EFFECT_SCENES, make_case
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator
from physbench.testing.field_camera import FieldCamera
from physbench.testing.field_footage import camera_seed, centre_errors
from physbench.video import track
from physbench.video.footage import frame_trajectory, motion_view
from physbench.video.writer import write_clip

ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
WAYS = ("plate", "median, both ends", "median")


def run_case(effect: str, scene_name: str, engine: str, seed: int, tmp: Path) -> dict:
    """One case filmed and tracked the three ways of :data:`WAYS`."""
    name = f"{effect}/{scene_name}/{engine}/{seed}"
    case = make_case(effect, scene_name, seed, ENGINES[engine]())
    sc = case.run.scene
    assert case.trajectory is not None
    traj = frame_trajectory(case.trajectory, np.arange(sc.frames) / sc.fps)
    cam = FieldCamera(640, seed=camera_seed(name), view=motion_view(sc, traj))
    assert cam.view is not None
    x0, y0, x1, y1 = cam.view
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    cal = Calibration.from_points(
        cam.image_points(sc, corners), corners, lens=cam.calibration(sc).lens
    )
    clip = write_clip(cam, tmp / "clip.mp4", sc, traj)
    row: dict = {"case": name}
    whole = track.ENDS_WHOLE
    for way in WAYS:
        track.ENDS_WHOLE = 0.0 if way == "median, both ends" else whole
        try:
            got = track.track_video(
                clip, sc, cal, background=cam.plate(sc) if way == "plate" else None,
                allow_gaps=True,
            )  # fmt: skip
        except Exception as exc:  # a refused clip is a result to report
            row[way] = {"failure": f"{type(exc).__name__}: {exc}"}
            continue
        finally:
            track.ENDS_WHOLE = whole
        s = got.summary
        row[way] = {
            "centre_px": centre_errors(cam, sc, traj, got.recording),
            "accuracy_px": dict(s.accuracy_px),
            "held": list(s.held),
            "lost": {b: len(v) for b, v in s.lost.items()},
        }
    return row


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 2])
    ap.add_argument("--out", default="results/track/pendulum_median.json")
    args = ap.parse_args(argv)
    rows = []
    cases = [
        (e, sc, eng, s)
        for s in args.seeds
        for e, scenes in EFFECT_SCENES.items()
        for sc in scenes
        if "pendulum" in sc
        for eng in ENGINES
    ]
    with tempfile.TemporaryDirectory(prefix="physbench-pendulum-") as tmp:
        for k, case in enumerate(cases, 1):
            row = run_case(*case, Path(tmp))
            rows.append(row)
            p95 = {
                way: {b: e["p95"] for b, e in row[way].get("centre_px", {}).items()} for way in WAYS
            }
            print(f"[{k}/{len(cases)}] {row['case']}: p95 {p95}", flush=True)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"ways": list(WAYS), "rows": rows}, indent=1) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
