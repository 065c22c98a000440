"""Does a resnet3d run say when its fit failed? And does restarting from a global design pay?

Every Table 1 row, resnet3d with its shipped weights in the Table 1 setting (pymunk, 64-pixel
raster, mark mode, sharp noise-free observation, 11 iterations: what ``physbench run --estimator
resnet3d`` does), held-out seeds 0..N-1 (training instances start at 2**24, validation at
2**30). Per case the image MSE and normalized parameter MSE of every iteration go to
``OUT/cases.jsonl`` (resumable).

The failure measure (:mod:`physbench.posterior.failure`) compares a run's best image MSE with the
median best image MSE of the row's other seeds. ``--reference`` writes those medians into
``physbench/posterior/failure_reference.json`` from the cases (all seeds; the summary scores each
seed against the median of the *other half* of the seeds, so no seed is judged by a reference it
helped make). ``--restart`` reruns the seeds with ``RunConfig(restart=True)``: from iteration 3
on, while the best image MSE is above the failure threshold, the loop simulates a Latin
hypercube point instead of resnet3d's proposal. A run whose best image MSE never exceeds the
threshold from iteration 3 on is identical with and without the restart (the loop and resnet3d
are deterministic), so only the seeds whose base run crosses it are rerun; the others are
recorded as not triggered. ``--summarize`` writes ``OUT/summary.md`` and ``OUT/summary.json``.

    python benchmarks/resnet3d_failures.py --seeds 0-199            # the base runs
    python benchmarks/resnet3d_failures.py --reference              # the shipped reference
    python benchmarks/resnet3d_failures.py --restart --seeds 0-199  # the restarts
    python benchmarks/resnet3d_failures.py --summarize
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

ROWS = (
    ("three_circles", "mass"),
    ("three_circles", "elasticity"),
    ("three_circles", "mass+elasticity"),
    ("second_order", "mass"),
    ("second_order", "elasticity"),
    ("stacked_boxes", "mass"),
    ("stacked_boxes", "friction"),
    ("bouncing_balls", "mass"),
)
ITERATIONS = 11
SETTING = {
    "engine": "pymunk",
    "observe_engine": "pymunk",
    "renderer": "raster",
    "renderer_options": {},
    "resolution": 64,
    "render_mode": "mark",
    "blur": 0.0,
    "noise": 0.0,
}
#: Failures: runs whose normalized min MSE is above this many times the row's median.
FAILURE = 100.0


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def run_case(scene: str, params: str, seed: int, restart: bool) -> dict:
    from physbench.experiment import RunConfig, run_config

    config = RunConfig(
        scene=scene,
        params=tuple(params.split("+")),
        estimator="resnet3d",
        options={"threads": 1},
        seed=seed,
        iterations=ITERATIONS,
        restart=restart,
    )
    t = time.process_time()
    h = run_config(config, probe=False)
    return {
        "row": f"{scene}:{params}",
        "seed": seed,
        "cpu": _g(time.process_time() - t),
        "loss": [_g(i.loss) for i in h.iterations],
        "nmse": [_g(i.nmse) for i in h.iterations],
        "best_nmse": _g(h.best_nmse),
        "min_loss": _g(h.min_loss),
        "restarts": list(h.restarts),
    }


def _g(x: float | None) -> float | None:
    """Five significant digits: what the tables use, at a third of the file size."""
    return None if x is None else float(f"{x:.5g}")


def _load(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line]


def _by_row(cases: list[dict]) -> dict[str, list[dict]]:
    rows: dict[str, list[dict]] = {}
    for c in cases:
        rows.setdefault(c["row"], []).append(c)
    return {k: sorted(v, key=lambda c: c["seed"]) for k, v in rows.items()}


def write_reference(out: Path) -> None:
    """The medians (and 99th percentiles) of the rows' best image MSE into the package."""
    from physbench.estimators.resnet3d import weights
    from physbench.posterior import failure

    refs = []
    for row, cs in _by_row(_load(out / "cases.jsonl")).items():
        scene, _, params = row.partition(":")
        losses = [c["min_loss"] for c in cs]
        info = weights.find(scene, tuple(params.split("+")))
        _, meta = weights.load(info.path)
        refs.append(
            {
                "estimator": "resnet3d",
                "scene": scene,
                "unknowns": params.split("+"),
                "iterations": ITERATIONS,
                "setting": SETTING,
                "median": float(statistics.median(losses)),
                "q99": float(np.quantile(losses, 0.99)),
                "seeds": len(losses),
                "weights_sha256": meta["sha256"],
            }
        )
    doc = {
        "about": (
            "Best image MSE of resnet3d after 11 iterations on held-out seeds, per Table 1 row; "
            "written by benchmarks/resnet3d_failures.py --reference from "
            "results/resnet3d/failures/cases.jsonl"
        ),
        "references": refs,
    }
    failure.REFERENCES.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {failure.REFERENCES}")


def _threshold_crossed(case: dict, threshold: float, after: int) -> bool:
    """Whether the base run's best image MSE is above ``threshold`` at an iteration where the
    restart rule looks (from iteration ``after - 1`` on, before the last)."""
    best = np.minimum.accumulate(case["loss"])
    return bool(np.any(best[after - 1 : -1] > threshold))


def restart_cases(out: Path, seeds: list[int]) -> None:
    from physbench.loop import Restart
    from physbench.posterior import failure

    base = {(c["row"], c["seed"]): c for c in _load(out / "cases.jsonl")}
    path = out / "restart.jsonl"
    done = {(c["row"], c["seed"]) for c in _load(path)} if path.exists() else set()
    after = Restart(threshold=1.0).after
    for scene, params in ROWS:
        row = f"{scene}:{params}"
        ref = failure.reference("resnet3d", scene, tuple(params.split("+")), ITERATIONS, SETTING)
        if ref is None:
            raise SystemExit(f"no reference for {row}: run --reference first")
        for seed in seeds:
            if (row, seed) in done or (row, seed) not in base:
                continue
            b = base[(row, seed)]
            if _threshold_crossed(b, failure.SCENE_FACTOR * ref.median, after):
                rec = run_case(scene, params, seed, restart=True)
            else:  # the same run as the base one
                rec = {"row": row, "seed": seed, "restarts": [], "not_triggered": True}
            with path.open("a") as f:
                f.write(json.dumps(rec) + "\n")
            print(row, seed, rec["restarts"], f"{rec['best_nmse']:.2e}", flush=True)


def _row_summary(row: str, cs: list[dict], restarted: list[dict] | None) -> dict:
    """A row's failures, flags (each seed against the median of the other half's best image
    MSE) and restart outcome."""
    from physbench.bench.tables import paper_value
    from physbench.posterior.failure import SCENE_FACTOR

    scene, _, params = row.partition(":")
    nmse = np.array([c["best_nmse"] for c in cs])
    loss = np.array([c["min_loss"] for c in cs])
    half = np.array([c["seed"] % 2 for c in cs])
    ref = np.where(half == 0, np.median(loss[half == 1]), np.median(loss[half == 0]))
    flagged = loss > SCENE_FACTOR * ref
    failed = nmse > FAILURE * np.median(nmse)
    # Every iterate (any iteration of any seed) as if the run had stopped there: how often the
    # flag sees one whose normalized MSE is a failure's.
    it_loss = np.concatenate([np.asarray(c["loss"]) / r for c, r in zip(cs, ref, strict=True)])
    it_nmse = np.concatenate([c["nmse"] for c in cs]) / np.median(nmse)
    it_failed = it_nmse > FAILURE
    paper = paper_value(scene, params, "NN")
    out = {
        "seeds": len(cs),
        "median_nmse": float(np.median(nmse)),
        "mean_nmse": float(nmse.mean()),
        "max_nmse": float(nmse.max()),
        "paper_nn": None if paper is None else paper[0],
        "failures": int(failed.sum()),
        "failures_flagged": int((failed & flagged).sum()),
        "flagged": int(flagged.sum()),
        "flagged_not_failed_nmse_over_median": sorted(
            float(round(v, 1)) for v in (nmse / np.median(nmse))[flagged & ~failed]
        ),
        "largest_loss_ratio_unflagged": float((loss / ref)[~flagged].max()),
        "failure_iterates": int(it_failed.sum()),
        "failure_iterates_flagged": int((it_failed & (it_loss > SCENE_FACTOR)).sum()),
    }
    if restarted:
        base_of = {c["seed"]: c for c in cs}
        by_seed = {
            c["seed"]: base_of[c["seed"]] if c.get("not_triggered") else c for c in restarted
        }
        r = np.array([by_seed[c["seed"]]["best_nmse"] for c in cs if c["seed"] in by_seed])
        base = np.array([c["best_nmse"] for c in cs if c["seed"] in by_seed])
        out.update(
            restart_seeds=len(r),
            restart_triggered=sum(1 for c in restarted if not c.get("not_triggered")),
            restart_mean_nmse=float(r.mean()),
            base_mean_nmse_same_seeds=float(base.mean()),
            restart_median_nmse=float(np.median(r)),
            restart_failures=int((r > FAILURE * np.median(base)).sum()),
        )
    return out


def summarize(out: Path) -> None:
    cases = _by_row(_load(out / "cases.jsonl"))
    restart = _by_row(_load(out / "restart.jsonl")) if (out / "restart.jsonl").exists() else {}
    summary = {row: _row_summary(row, cs, restart.get(row)) for row, cs in cases.items()}
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    md = _markdown(summary)
    (out / "summary.md").write_text(md)
    print(md)


def _markdown(summary: dict) -> str:
    from physbench.posterior.failure import SCENE_FACTOR

    lines = [
        "# resnet3d: failed fits, flagged and restarted (Table 1 setting, 11 iterations)",
        "",
        "Written by `python benchmarks/resnet3d_failures.py --summarize`. Failure: normalized min",
        f"MSE above {FAILURE:g} x the row's median. Flagged: best image MSE above {SCENE_FACTOR:g}",
        "x the median of the other half of the seeds (even seeds against odd ones and back).",
        "Restart: `RunConfig(restart=True)`, a Latin hypercube point instead of resnet3d's",
        "proposal from iteration 3 on while the best image MSE is above the flag's threshold;",
        "means over the same seeds. Failure iterates: every iteration of every seed whose",
        f"normalized MSE is above {FAILURE:g} x the row's median, as if the run had stopped there.",
        "",
        "| row | seeds | median nMSE | mean nMSE | paper NN | failures | flagged failures | "
        "flagged | largest unflagged image-MSE ratio | failure iterates flagged | restarted "
        "| mean nMSE with restart |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row, s in summary.items():
        paper = "-" if s["paper_nn"] is None else f"{s['paper_nn']:.2g}"
        restart = (
            f"{s['restart_triggered']} | {s['restart_mean_nmse']:.3g} "
            f"(without: {s['base_mean_nmse_same_seeds']:.3g})"
            if "restart_seeds" in s
            else "- | -"
        )
        lines.append(
            f"| {row} | {s['seeds']} | {s['median_nmse']:.3g} | {s['mean_nmse']:.3g} | {paper} | "
            f"{s['failures']} | {s['failures_flagged']} | {s['flagged']} | "
            f"{s['largest_loss_ratio_unflagged']:.1f} | "
            f"{s['failure_iterates_flagged']} of {s['failure_iterates']} | {restart} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--rows", default=",".join(str(i) for i in range(len(ROWS))))
    ap.add_argument("--seeds", default="0-199")
    ap.add_argument("--out", type=Path, default=Path("results/resnet3d/failures"))
    ap.add_argument("--reference", action="store_true")
    ap.add_argument("--restart", action="store_true")
    ap.add_argument("--summarize", action="store_true")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.summarize:
        summarize(args.out)
        return
    if args.reference:
        write_reference(args.out)
        return
    if args.restart:
        restart_cases(args.out, _seeds(args.seeds))
        return
    path = args.out / "cases.jsonl"
    done = {(c["row"], c["seed"]) for c in _load(path)} if path.exists() else set()
    for i in map(int, args.rows.split(",")):
        scene, params = ROWS[i]
        for seed in _seeds(args.seeds):
            if (f"{scene}:{params}", seed) in done:
                continue
            rec = run_case(scene, params, seed, restart=False)
            with path.open("a") as f:
                f.write(json.dumps(rec) + "\n")


if __name__ == "__main__":
    main()
