"""Discovery from video, end to end: physbench's hidden-effect runs filmed by the ``camera``
renderer as H.264 video, tracked, and discovered, next to the same runs' clean tracks.

For every effect and its scenes (``physbench.discover.synthetic.EFFECT_SCENES``), both engines and
the given seeds, plus the controls (every synthetic scene without an effect): the run's true motion
is filmed at 640x480 (oblique view, motion blur, sensor noise, flickering light, 2 Mbit/s H.264),
tracked with a four-point calibration, and handed to ``discover``; the clean synthetic tracks
(Gaussian tracking noise) go through ``discover`` too. Writes ``results.json`` (one row per case)
and ``table.md`` (per effect: named first, magnitude error, for clean and filmed) into ``--out``.

    python benchmarks/video_discover.py --seeds 0 1 2 --out results/video_discover
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from physbench.discover import discover
from physbench.discover.synthetic import (
    EFFECT_SCENES,
    FILM,
    SCENES,
    filmed_run,
    magnitude_error,
    make_case,
)
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
TOLERANCE = 0.15


def cases(seeds: list[int]) -> list[tuple[str | None, str, str, int]]:
    hidden = [
        (e, sc, eng, s)
        for e, scenes in EFFECT_SCENES.items()
        for sc in scenes
        for eng in ENGINES
        for s in seeds
    ]
    controls = [(None, sc, eng, s) for sc in sorted(SCENES) for eng in ENGINES for s in seeds]
    return hidden + controls


def body_px(effect: str | None, scene: str, engine: str, seed: int) -> float:
    """The smallest body's radius in the filmed image (px): how big the camera saw it."""
    from physbench.render.camera import CameraRenderer
    from physbench.video.footage import frame_trajectory, motion_view

    case = make_case(effect, scene, seed, ENGINES[engine]())
    sc = case.run.scene
    traj = frame_trajectory(case.trajectory, np.arange(sc.frames) / sc.fps)
    cam = CameraRenderer(**{**FILM, "view": motion_view(sc, traj)})
    cal = cam.calibration(sc)
    centre = cal.to_image(np.asarray(sc.bodies[0].position, dtype=float))
    return round(min(b.shape.extent() for b in sc.bodies) / cal.metres_per_pixel(centre), 2)


def evaluate(effect, disc, truth) -> dict:
    found = disc.cause_results[0] if effect is not None and disc.causes[:1] == [effect] else None
    err = magnitude_error(effect, truth, found.params) if found is not None else None
    ok = (
        disc.causes == []
        if effect is None
        else (found is not None and err is not None and err <= TOLERANCE)
    )
    return {"causes": disc.causes, "error": err, "gain": disc.gain, "ok": bool(ok)}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    p.add_argument("--out", default="results/video_discover")
    p.add_argument("--only", default=None, help="run only cases whose name contains this")
    p.add_argument(
        "--merge",
        nargs="+",
        metavar="RESULTS.json",
        help="run nothing: join these results files (e.g. seeds run in parallel) into --out",
    )
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.merge:
        parts = [json.loads(Path(f).read_text()) for f in args.merge]
        rows = [r for part in parts for r in part["rows"]]
        for r in rows:
            r.setdefault("body_px", body_px(r["effect"], r["scene"], r["engine"], r["seed"]))
        seeds = sorted({s for part in parts for s in part["seeds"]})
        payload = {"camera": FILM, "seeds": seeds, "tolerance": TOLERANCE, "rows": rows}
        (out / "results.json").write_text(json.dumps(payload, indent=1) + "\n")
        (out / "table.md").write_text(table(rows))
        print(table(rows))
        return 0
    rows = []
    todo = cases(args.seeds)
    if args.only:
        todo = [c for c in todo if args.only in f"{c[0]}/{c[1]}/{c[2]}/{c[3]}"]
    t0 = time.perf_counter()
    for i, (effect, scene, engine, seed) in enumerate(todo):
        sim = ENGINES[engine]()
        case = make_case(effect, scene, seed, sim)
        row: dict = {"effect": effect, "scene": scene, "engine": engine, "seed": seed}
        row["truth"] = case.truth
        row["body_px"] = body_px(effect, scene, engine, seed)
        row["clean"] = evaluate(effect, discover([case.run], sim, diagnose=False), case.truth)
        try:
            filmed = filmed_run(case, seed)
        except Exception as exc:  # a failed track is a result to report
            row["filmed"] = {"causes": None, "error": None, "gain": None, "ok": False}
            row["filmed_failure"] = f"{type(exc).__name__}: {exc}"
        else:
            row["filmed"] = evaluate(effect, discover([filmed], sim, diagnose=False), case.truth)
        rows.append(row)
        f = row["filmed"]
        err = "" if f["error"] is None else f"err {f['error']:.1%}"
        print(
            f"[{i + 1}/{len(todo)}] {effect or 'control'}/{scene}/{engine}/{seed}: clean "
            f"{row['clean']['causes']} filmed {f['causes']} "
            f"{err} "
            f"{'ok' if f['ok'] else 'FAIL'} ({time.perf_counter() - t0:.0f} s)",
            file=sys.stderr,
        )
    (out / "results.json").write_text(
        json.dumps(
            {"camera": FILM, "seeds": args.seeds, "tolerance": TOLERANCE, "rows": rows},
            indent=1,
        )
        + "\n"
    )
    (out / "table.md").write_text(table(rows))
    print(table(rows))
    return 0


def table(rows: list[dict]) -> str:
    """Per effect (and the controls): cases, named first with magnitude within 15 %, median
    magnitude error, for the clean tracks and the filmed video."""
    groups: dict[str, list[dict]] = defaultdict(list)
    for r in rows:
        groups[r["effect"] or "(controls: no cause)"].append(r)
    lines = [
        "| effect | cases | clean: right | filmed: right | clean: median error | "
        "filmed: median error |",
        "|---|---|---|---|---|---|",
    ]
    for name, rs in groups.items():

        def med(kind: str, rs: list[dict] = rs) -> str:
            errs = [r[kind]["error"] for r in rs if r[kind]["error"] is not None]
            return f"{np.median(errs):.1%}" if errs else "-"

        lines.append(
            f"| {name} | {len(rs)} | {sum(r['clean']['ok'] for r in rs)} | "
            f"{sum(r['filmed']['ok'] for r in rs)} | {med('clean')} | {med('filmed')} |"
        )
    misses = [
        f"- {r['effect'] or 'control'}/{r['scene']}/{r['engine']}/{r['seed']}: clean "
        f"{r['clean']['causes']}, filmed {r['filmed']['causes']} (smallest body "
        f"{r.get('body_px', float('nan')):.1f} px in radius)"
        for r in rows
        if not r["filmed"]["ok"] or (r["effect"] and (r["filmed"]["causes"] or [])[1:])
    ]
    if misses:
        lines += ["", "Filmed cases that missed, or named more than the hidden effect:", *misses]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
