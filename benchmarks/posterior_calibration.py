"""Calibration of the posterior of an estimator that returns one (``smc``), measured on held-out
seeds per Table 1 row: does the 90 % interval cover the truth in 90 % of cases?

Every case draws the truth uniformly from the row's ranges (the prior), simulates and renders the
observation (pymunk, a 32-pixel raster) with Gaussian pixel noise ``--noise`` (clipped to [0, 1],
the observation model the likelihood states), and runs ``smc`` for ``--iterations`` (6,000: on
the three rows no case needed more than 5,455 to reach the posterior). One JSON line per
case and unknown goes to ``OUT/cases.jsonl`` (appended; a case already there is skipped, so runs
resume and split across processes with ``--seeds``). ``--summarize`` writes
``OUT/summary.json`` and ``OUT/summary.md``: per row and unknown, the coverage of the
50/80/90/95 % intervals with 95 % binomial intervals, the SBC rank-uniformity p-value, the mean
90 % width over the range, and how many posteriors were complete.

    python benchmarks/posterior_calibration.py --rows three_circles:mass --seeds 0-199 \
        --out results/posterior/smc
    python benchmarks/posterior_calibration.py --summarize --out results/posterior/smc
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from physbench.components import create
from physbench.estimators.smc import SMCEstimator
from physbench.loop import draw_problem, refine
from physbench.observation import simulate_observation
from physbench.render.sensor import SensorModel
from physbench.scenes import resolve_scene
from physbench.unknowns import ParamSpace

LEVELS = (0.5, 0.8, 0.9, 0.95)
#: Seeds are held out from nothing here (smc is not trained), but start far from the training
#: seeds of the learned estimators all the same, so both can share a table.
SEED_OFFSET = 100_000


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def run_case(scene_name: str, params: list[str], seed: int, args: argparse.Namespace) -> list[dict]:
    scene = resolve_scene(scene_name, SEED_OFFSET + seed)
    space = ParamSpace.from_scene(scene, params)
    truth, _ = draw_problem(space, SEED_OFFSET + seed)
    sim = create("simulator", "pymunk")
    ren = create("renderer", "raster", resolution=args.resolution)
    camera = SensorModel(noise=args.noise, seed=SEED_OFFSET + seed)
    obs = simulate_observation(scene, truth, sim, ren, sensor=camera)
    t = time.perf_counter()
    est = SMCEstimator(particles=args.particles)
    h = refine(obs, scene, space, sim, ren, est, iterations=args.iterations, seed=seed)
    wall = time.perf_counter() - t
    post = h.posterior
    rows = []
    for j, k in enumerate(space.keys):
        u = space.unknowns[j]
        row = {
            "row": f"{scene_name}:{'+'.join(params)}",
            "seed": seed,
            "key": k,
            "truth": truth[k],
            "low": u.low,
            "high": u.high,
            "complete": bool(post is not None and post.complete),
            "wall_s": wall,
            "noise": args.noise,
            "iterations": args.iterations,
            "particles": args.particles,
            "resolution": args.resolution,
        }
        if post is not None:
            x = post.samples[:, j]
            row.update(
                median=float(np.median(x)),
                rank=float(np.mean(x < truth[k])),
                simulations_to_posterior=post.extra.get("simulations_to_posterior"),
                **{
                    f"in{round(100 * lv)}": bool(
                        post.interval(lv)[k][0] <= truth[k] <= post.interval(lv)[k][1]
                    )
                    for lv in LEVELS
                },
                width90=(post.interval(0.9)[k][1] - post.interval(0.9)[k][0]) / (u.high - u.low),
            )
        rows.append(row)
    return rows


def summarize(out: Path) -> None:
    from scipy.stats import binomtest, kstest

    cases = [json.loads(line) for line in (out / "cases.jsonl").read_text().splitlines() if line]
    groups: dict[tuple[str, str], list[dict]] = {}
    for c in cases:
        groups.setdefault((c["row"], c["key"]), []).append(c)
    summary = []
    for (row, key), cs in sorted(groups.items()):
        ok = [c for c in cs if "rank" in c]
        entry = {
            "row": row,
            "key": key,
            "cases": len(cs),
            "complete": sum(c["complete"] for c in cs),
        }
        for lv in LEVELS:
            name = f"in{round(100 * lv)}"
            hits = sum(c[name] for c in ok)
            ci = binomtest(hits, len(ok)).proportion_ci(0.95)
            entry[f"coverage{round(100 * lv)}"] = hits / len(ok)
            entry[f"coverage{round(100 * lv)}_ci"] = [ci.low, ci.high]
        # Ranks of a calibrated posterior are uniform on [0, 1] (SBC); with 64 particles they
        # take 65 values, fine for a KS test at these case counts.
        entry["sbc_ks_p"] = float(kstest([c["rank"] for c in ok], "uniform").pvalue)
        entry["width90"] = float(np.mean([c["width90"] for c in ok]))
        entry["median_wall_s"] = float(np.median([c["wall_s"] for c in cs]))
        entry["median_simulations_to_posterior"] = float(
            np.median([c["simulations_to_posterior"] for c in ok if c["complete"]])
        )
        summary.append(entry)
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    lines = [
        "| row | unknown | cases (complete) | 50 % | 80 % | 90 % | 95 % | SBC KS p "
        "| 90 % width / range | simulations | s per case |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for e in summary:
        cov = " | ".join(
            "{:.3f} [{:.2f}, {:.2f}]".format(e[f"coverage{p}"], *e[f"coverage{p}_ci"])
            for p in (50, 80, 90, 95)
        )
        lines.append(
            f"| {e['row']} | {e['key']} | {e['cases']} ({e['complete']}) | {cov} | "
            f"{e['sbc_ks_p']:.3f} | {e['width90']:.4f} | "
            f"{e['median_simulations_to_posterior']:.0f} | {e['median_wall_s']:.1f} |"
        )
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--rows", nargs="+", default=["three_circles:mass"], help="SCENE:PARAM[+PARAM]")
    ap.add_argument("--seeds", default="0-199", help="e.g. 0-199 or 0-99,150-199")
    ap.add_argument("--iterations", type=int, default=6000)
    ap.add_argument("--particles", type=int, default=64)
    ap.add_argument("--noise", type=float, default=0.1)
    ap.add_argument("--resolution", type=int, default=32)
    ap.add_argument("--out", type=Path, default=Path("results/posterior/smc"))
    ap.add_argument("--summarize", action="store_true")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.summarize:
        summarize(args.out)
        return
    path = args.out / "cases.jsonl"
    done = set()
    if path.exists():
        done = {(c["row"], c["seed"]) for c in map(json.loads, path.read_text().splitlines()) if c}
    for spec in args.rows:
        scene, _, params = spec.partition(":")
        for seed in _seeds(args.seeds):
            if (spec, seed) in done:
                continue
            rows = run_case(scene, params.split("+"), seed, args)
            with path.open("a") as f:  # one write per case: a killed run loses at most one case
                f.write("".join(json.dumps(r) + "\n" for r in rows))
            print(spec, seed, f"{rows[0]['wall_s']:.1f}s", rows[0].get("in90"), flush=True)


if __name__ == "__main__":
    main()
