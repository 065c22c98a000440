"""Calibration and cost of the npe amortized posterior on Table 1 rows.

For each row with shipped npe weights: 200 held-out seeds (0..199; training used seeds from
2**24, validation from 2**30), each the Table 1 problem of that seed (the scene instance, the
truth of ``draw_problem``, a noise-free pymunk observation rendered by the 64-pixel raster
renderer in mark mode). Per unknown: how often the truth falls in the posterior's central
50/80/90/95 % intervals, the SBC rank's KS p-value against uniform (rank = share of posterior
samples below the truth), the mean 90 % width over the range, and the normalized MSE of the
posterior median (no simulation at all) next to the paper's NN after 11 iterations. Cost: one
observation's posterior (the estimator's start: loading the weights, summarizing the marked
views, 1,000 draws) on one torch thread, median of 20.

    python benchmarks/npe_calibration.py [--seeds 200] [--out results/posterior/npe]
"""

from __future__ import annotations

import argparse
import csv
import json
import statistics
import time
from pathlib import Path

import numpy as np

ROWS = (("three_circles", "mass"), ("three_circles", "elasticity"), ("second_order", "mass"))
LEVELS = (0.5, 0.8, 0.9, 0.95)


def problem(scene_name: str, params: str, seed: int):  # type: ignore[no-untyped-def]
    """The Table 1 task of ``seed`` for an estimator that marks bodies, and its truth."""
    from physbench.components import create, make_renderer
    from physbench.estimators.base import Task
    from physbench.loop import draw_problem
    from physbench.observation import simulate_observation
    from physbench.scenes.generator import resolve_scene
    from physbench.unknowns import ParamSpace, split_params

    scene = resolve_scene(scene_name, seed)
    space = ParamSpace.from_scene(scene, split_params(params))
    truth, initial = draw_problem(space, seed)
    renderer = make_renderer("raster", {}, resolution=64, mode="mark")
    obs = simulate_observation(
        scene, truth, create("simulator", "pymunk"), renderer, marked=space.bodies
    )
    task = Task(scene, space, obs.frames, initial, renderer, 11, obs.marked, noise=0.0)
    return task, truth


def evaluate_row(scene_name: str, params: str, seeds: range) -> tuple[list[dict], dict]:
    from scipy.stats import kstest

    from physbench.bench.tables import paper_value
    from physbench.estimators.npe.estimator import NPEEstimator

    cases = []
    for seed in seeds:
        task, truth = problem(scene_name, params, seed)
        est = NPEEstimator(refine=False)
        est.start(task, seed=seed)
        post = est.posterior()
        assert post is not None
        med = post.median()
        nmse = task.space.normalized_mse(med, truth)
        for j, k in enumerate(post.keys):
            lo, hi = post.low[j], post.high[j]
            row = {"scene": scene_name, "params": params, "seed": seed, "key": k}
            row["truth"], row["median"], row["nmse"] = truth[k], med[k], nmse
            row["rank"] = float(np.mean(post.samples[:, j] < truth[k]))
            for level in LEVELS:
                a, b = post.interval(level)[k]
                row[f"in{round(level * 100)}"] = int(a <= truth[k] <= b)
            a, b = post.interval(0.9)[k]
            row["width90"] = (b - a) / (hi - lo)
            cases.append(row)
    keys = sorted({c["key"] for c in cases})
    per_key = {}
    for k in keys:
        rows = [c for c in cases if c["key"] == k]
        per_key[k] = {
            **{
                f"coverage{round(lv * 100)}": float(
                    np.mean([r[f"in{round(lv * 100)}"] for r in rows])
                )
                for lv in LEVELS
            },
            "sbc_ks_p": float(kstest([r["rank"] for r in rows], "uniform").pvalue),
            "width90": float(np.mean([r["width90"] for r in rows])),
        }
    nmses = [c["nmse"] for c in cases if c["key"] == keys[0]]
    paper = paper_value(scene_name, params, "NN")
    summary = {
        "seeds": len(nmses),
        "per_key": per_key,
        "median_nmse_mean": float(np.mean(nmses)),
        "median_nmse_std": float(np.std(nmses)),
        "paper_nn_11": list(paper) if paper else None,
    }
    return cases, summary


def cost(scene_name: str, params: str, repeats: int = 20) -> float:
    """Median seconds of one observation's posterior (start + posterior) on one torch thread."""
    import torch

    from physbench.estimators.npe.estimator import NPEEstimator

    torch.set_num_threads(1)
    task, _ = problem(scene_name, params, 0)
    times = []
    for r in range(repeats):
        t = time.perf_counter()
        est = NPEEstimator(samples=1000, threads=1, refine=False)
        est.start(task, seed=r)
        est.posterior()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def write(out: Path, cases: list[dict], summaries: dict) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "cases.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(cases[0]))
        w.writeheader()
        w.writerows(cases)
    (out / "summary.json").write_text(json.dumps(summaries, indent=1, sort_keys=True))
    lines = [
        "# npe: calibration of the amortized posterior (held-out seeds 0..N-1)",
        "",
        "Written by `python benchmarks/npe_calibration.py`. Coverage: share of seeds whose truth",
        "lies in the posterior's central interval (a calibrated posterior matches the level). SBC",
        "KS p: the truth's rank among the samples against uniform (small: miscalibrated). Width:",
        "mean 90 % interval over the range. nMSE: of the posterior median, no simulation, mean ±",
        "std over seeds; paper NN: after 11 iterations.",
        "",
        "| row | unknown | 50 % | 80 % | 90 % | 95 % | SBC KS p | 90 % width | median nMSE "
        "| paper NN (11 it.) | cost (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row, s in summaries.items():
        paper = s["paper_nn_11"]
        paper_s = f"{paper[0]:.2g} ± {paper[1]:.1g}" if paper else "-"
        for k, v in s["per_key"].items():
            lines.append(
                f"| {row} | {k} | {v['coverage50']:.2f} | {v['coverage80']:.2f} | "
                f"{v['coverage90']:.2f} | {v['coverage95']:.2f} | {v['sbc_ks_p']:.2g} | "
                f"{v['width90']:.3f} | {s['median_nmse_mean']:.2g} ± {s['median_nmse_std']:.1g} "
                f"| {paper_s} | {s['cost_s']:.3f} |"
            )
    lines += ["", f"Seeds per row: {next(iter(summaries.values()))['seeds']}."]
    (out / "summary.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", type=int, default=200)
    p.add_argument("--out", default="results/posterior/npe")
    args = p.parse_args()
    all_cases, summaries = [], {}
    for scene_name, params in ROWS:
        cases, summary = evaluate_row(scene_name, params, range(args.seeds))
        summary["cost_s"] = cost(scene_name, params)
        all_cases += cases
        summaries[f"{scene_name}[{params}]"] = summary
        print(scene_name, params, json.dumps(summary))
    write(Path(args.out), all_cases, summaries)


if __name__ == "__main__":
    main()
