"""Measurement errors against real forces: does discovery tell a calibration error from a force?

    python benchmarks/discover_measurement.py                 # 144 cases, both engines
    python benchmarks/discover_measurement.py --seeds 0 1     # fewer
    python benchmarks/discover_measurement.py --out out/dm    # elsewhere
    python benchmarks/discover_measurement.py --summarise     # re-summarise cases.jsonl

Two kinds of case (:func:`physbench.discover.synthetic.measurement_case`), in a ball's free flight
(side view) and a puck with two kicks of known size (from above), simulated by physbench with
tracking noise:

* **measurement**: no force at all, but the recording is distorted: a length scale 1-3 % off, a
  clock 1-3 % off, axes turned by 0.3-1°, or all three. The claim: the verdict lists a
  measurement cause (as a cause, or as an explanation it cannot tell apart from the cause) and
  never names a physical cause alone.
* **physical**: a real force of the same size (a uniform pull of 0.1-0.3 m/s² in a random
  direction, or linear drag slowing the body about as much) and no distortion, with the length
  scale and the frame rate fixed by a reference (``Settings(references=("scale", "clock"))``:
  a reference length in the plane and a known frame rate, as a calibrated tracker states them).
  The claim: the verdict names the physical cause first. Whether it is named alone is reported
  too: with only scale and clock fixed, a horizontal pull in free flight is still a turn of the
  axes.

Writes ``cases.jsonl`` (one line per case), ``summary.json`` and ``summary.md`` into
``results/discover_measurement/``; ``tests/results/test_discover_measurement.py`` holds the
committed results to the claims. Runs are deterministic.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from physbench.discover import discover
from physbench.discover.synthetic import (
    DISTORTIONS,
    MEASUREMENT_SCENES,
    REAL_FORCES,
    judge_measurement,
    measurement_case,
)
from physbench.simulators.box2d_sim import Box2DSimulator
from physbench.simulators.pymunk_sim import PymunkSimulator

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "results" / "discover_measurement"
ENGINES = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}
SEEDS = (0, 1, 2, 3, 4, 5)


def cases(seeds: Sequence[int]) -> list[tuple[str, str, str, int]]:
    """(kind, scene, label, seed) of every case."""
    out = []
    for scene in MEASUREMENT_SCENES:
        out += [("measurement", scene, d, s) for d in DISTORTIONS for s in seeds]
        out += [("physical", scene, e, s) for e in REAL_FORCES[scene] for s in seeds]
    return out


def run_case(kind: str, scene: str, label: str, seed: int, engine: str) -> dict[str, Any]:
    sim = ENGINES[engine]()
    mc = measurement_case(kind, scene, label, seed, sim)
    t0 = time.process_time()
    disc = discover([mc.case.run], sim, settings=mc.settings, diagnose=False)
    row = {
        "kind": kind,
        "scene": scene,
        "label": label,
        "seed": seed,
        "engine": engine,
        "distortion": mc.case.distortion,
        "truth": mc.case.truth,
        "references": list(mc.settings.references),
        **judge_measurement(mc, disc),
        "cpu_seconds": time.process_time() - t0,
    }
    return row


def summarise(rows: list[dict[str, Any]]) -> tuple[dict[str, Any], list[str]]:
    groups: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault((r["kind"], r["scene"], r["label"]), []).append(r)
    table = []
    for (kind, scene, label), rs in groups.items():
        entry: dict[str, Any] = {
            "kind": kind,
            "scene": scene,
            "label": label,
            "cases": len(rs),
            "ok": sum(r["ok"] for r in rs),
        }
        if kind == "measurement":
            entry["lists_measurement"] = sum(r["lists_measurement"] for r in rs)
            entry["no_cause"] = sum(r["no_cause"] for r in rs)
            entry["physical_alone"] = sum(bool(r["physical_alone"]) for r in rs)
        else:
            entry["named_first"] = sum(r["named_first"] for r in rs)
            entry["alone"] = sum(r["alone"] for r in rs)
            errs = [r["magnitude_error"] for r in rs if r["magnitude_error"] is not None]
            entry["worst_error"] = max(errs) if errs else None
        table.append(entry)
    kinds = {
        k: {
            "cases": sum(1 for r in rows if r["kind"] == k),
            "ok": sum(r["ok"] for r in rows if r["kind"] == k),
        }
        for k in ("measurement", "physical")
    }
    lines = [
        "| kind | scene | distortion or force | cases | claim holds | details |",
        "|---|---|---|---|---|---|",
    ]
    for e in table:
        if e["kind"] == "measurement":
            details = (
                f"lists a measurement cause {e['lists_measurement']}/{e['cases']}; "
                f"no cause (within the noise) {e['no_cause']}/{e['cases']}; "
                f"a physical cause alone {e['physical_alone']}/{e['cases']}"
            )
        else:
            worst = "-" if e["worst_error"] is None else f"{e['worst_error']:.1%}"
            details = (
                f"named first {e['named_first']}/{e['cases']}; named alone "
                f"{e['alone']}/{e['cases']}; worst magnitude error {worst}"
            )
        lines.append(
            f"| {e['kind']} | {e['scene']} | {e['label']} | {e['cases']} | "
            f"{e['ok']}/{e['cases']} | {details} |"
        )
    lines += [
        "",
        *(f"{k}: the claim holds in {v['ok']}/{v['cases']} cases" for k, v in kinds.items()),
    ]
    return {"kinds": kinds, "groups": table}, lines


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=(__doc__ or "").splitlines()[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    ap.add_argument("--engines", nargs="+", default=list(ENGINES), choices=list(ENGINES))
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument("--summarise", action="store_true", help="only re-summarise <out>/cases.jsonl")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.summarise:
        lines = (args.out / "cases.jsonl").read_text().splitlines()
        write_summary(args.out, [json.loads(line) for line in lines if line.strip()])
        return 0
    rows = []
    with (args.out / "cases.jsonl").open("w") as log:
        for engine in args.engines:
            for kind, scene, label, seed in cases(args.seeds):
                row = run_case(kind, scene, label, seed, engine)
                rows.append(row)
                log.write(json.dumps(row) + "\n")
                log.flush()
                print(
                    f"{kind:<11} {scene:<12} {label:<15} seed {seed:<3} {engine:<6} "
                    f"ok={row['ok']} causes={row['causes']} "
                    f"sets={row['indistinguishable']} ({row['cpu_seconds']:.1f} s)",
                    flush=True,
                )
    write_summary(args.out, rows)
    return 0


def write_summary(out: Path, rows: list[dict[str, Any]]) -> None:
    summary, lines = summarise(rows)
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    sys.exit(main())
