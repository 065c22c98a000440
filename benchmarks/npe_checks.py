"""Does npe notice when its answer cannot be trusted? Its two checks, measured as a user meets them.

``physbench run --estimator npe`` on three_circles mass (model pymunk, 64-pixel raster, mark
mode; the Table 1 setting npe was trained in) for held-out seeds 0..N-1, each observation made
three ways:

- ``in``: the training setting (pymunk, sharp, noise-free): the checks should stay quiet, and the
  posterior's coverage is npe's calibration (benchmarks/npe_calibration.py measured it before the
  checks existed; the checks do not change the posterior);
- ``box2d``: Box2D makes the observation (``--observe-engine box2d``): npe's intervals miss the
  truth on most seeds, and the posterior predictive check (:mod:`physbench.posterior.predictive`)
  should say that the model does not reproduce the observation;
- ``blur``: a 3 px blur of the observation (``--blur 3``): npe's summary features leave its
  training data, and npe should say so instead of "the data do not determine".

Each case goes through :func:`physbench.experiment.run_config`, the path ``physbench run`` takes
(npe's posterior, then resnet3d's 11-iteration refinement, then the predictive check with its
default draws; ``--draws 0`` leaves the check out, as this script does for ``blur``). One JSON
line per case to ``OUT/cases.jsonl`` (resumable); ``--summarize`` writes ``OUT/summary.md`` and
``OUT/summary.json``.

    python benchmarks/npe_checks.py --conditions in box2d blur --seeds 0-199
    python benchmarks/npe_checks.py --summarize
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

CONDITIONS = {
    "in": {},
    "box2d": {"observe_engine": "box2d"},
    "blur": {"blur": 3.0},
}
LEVELS = (0.5, 0.8, 0.9, 0.95)


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def run_case(condition: str, seed: int, draws: int) -> dict:
    from physbench.experiment import RunConfig, run_config

    config = RunConfig(
        scene="three_circles",
        params=("mass",),
        estimator="npe",
        seed=seed,
        predictive_draws=draws,
        **CONDITIONS[condition],
    )
    t = time.process_time()
    h = run_config(config, probe=False)
    post, truth = h.posterior, h.truth
    assert post is not None and truth is not None and post.domain is not None
    row: dict = {
        "condition": condition,
        "seed": seed,
        "cpu_s": round(time.process_time() - t, 3),
        "domain_distance": post.domain.distance,
        "domain_threshold": post.domain.threshold,
        "outside": post.outside,
        "undetermined": list(post.undetermined()),
        "says_not_determined": "not determined" in "\n".join(post.describe(truth)),
        "says_outside": "outside npe's training data" in "\n".join(post.describe(truth)),
        "predictive_p": None if h.predictive is None else h.predictive.p,
        "reproduced": None if h.predictive is None else h.predictive.reproduced,
        "predictive_s": None if h.predictive is None else round(h.predictive.seconds, 3),
        "best_nmse": h.best_nmse,
        "keys": {},
    }
    for j, k in enumerate(post.keys):
        s = post.samples[:, j]
        inside = {}
        for lv in LEVELS:
            a, b = post.interval(lv)[k]
            inside[f"in{round(100 * lv)}"] = bool(a <= truth[k] <= b)
        lo, hi = post.interval(0.9)[k]
        row["keys"][k] = {
            **inside,
            "rank": float(np.mean(s < truth[k])),
            "width90": (hi - lo) / (post.high[j] - post.low[j]),
        }
    row["miss90"] = not all(v["in90"] for v in row["keys"].values())
    return row


def _share(flags: list[bool]) -> str:
    return f"{np.mean(flags):.3f} ({sum(flags)} of {len(flags)})" if flags else "-"


def summarize(out: Path) -> None:
    from scipy.stats import kstest

    cases = [json.loads(line) for line in (out / "cases.jsonl").read_text().splitlines() if line]
    summary: dict = {}
    for cond in CONDITIONS:
        cs = [c for c in cases if c["condition"] == cond]
        if not cs:
            continue
        miss = [c for c in cs if c["miss90"]]
        checked = [c for c in cs if c["reproduced"] is not None]
        warned = [c["outside"] or c["reproduced"] is False for c in cs]
        keys = sorted(cs[0]["keys"])
        summary[cond] = {
            "seeds": len(cs),
            "miss90_runs": len(miss),
            "predictive_fails": _share([not c["reproduced"] for c in checked]),
            "predictive_fails_on_miss90": _share(
                [not c["reproduced"] for c in miss if c["reproduced"] is not None]
            ),
            "outside": _share([c["outside"] for c in cs]),
            "warned": _share(warned),
            "warned_on_miss90": _share([c["outside"] or c["reproduced"] is False for c in miss]),
            "says_not_determined": _share([c["says_not_determined"] for c in cs]),
            "coverage": {
                k: {
                    f"in{round(100 * lv)}": float(
                        np.mean([c["keys"][k][f"in{round(100 * lv)}"] for c in cs])
                    )
                    for lv in LEVELS
                }
                | {"sbc_ks_p": float(kstest([c["keys"][k]["rank"] for c in cs], "uniform").pvalue)}
                for k in keys
            },
            "median_cpu_s": float(np.median([c["cpu_s"] for c in cs])),
            "median_predictive_s": (
                float(np.median([c["predictive_s"] for c in checked])) if checked else None
            ),
            "domain_threshold": float(cs[0]["domain_threshold"]),
            "domain_distance_range": [
                float(min(c["domain_distance"] for c in cs)),
                float(max(c["domain_distance"] for c in cs)),
            ],
        }
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    (out / "summary.md").write_text(_markdown(summary))
    print(_markdown(summary))


def _markdown(summary: dict) -> str:
    lines = [
        "# npe's checks: three_circles mass, model pymunk, held-out seeds",
        "",
        "Written by `python benchmarks/npe_checks.py --summarize`. `in`: the training setting;",
        "`box2d`: Box2D makes the observation; `blur`: a 3 px blur of it. miss90: runs whose 90 %",
        "interval misses the truth of at least one unknown. Predictive check: the model does not",
        "reproduce the observation (p <= 0.05, 59 posterior draws; not run on `blur`). Outside:",
        "npe says the observation lies outside its training data. Warned: either. 'Not",
        "determined': runs where npe would say the data do not determine an unknown.",
        "",
        "| condition | seeds | miss90 | predictive check fails | ... on miss90 runs | outside "
        "| warned on miss90 runs | warned | says 'not determined' |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for cond, s in summary.items():
        lines.append(
            f"| {cond} | {s['seeds']} | {s['miss90_runs']} | {s['predictive_fails']} | "
            f"{s['predictive_fails_on_miss90']} | {s['outside']} | {s['warned_on_miss90']} | "
            f"{s['warned']} | {s['says_not_determined']} |"
        )
    lines += [
        "",
        "Coverage of the central intervals (share of seeds whose truth they hold) and the SBC",
        "rank KS p-value:",
        "",
        "| condition | unknown | 50 % | 80 % | 90 % | 95 % | SBC KS p |",
        "|---|---|---|---|---|---|---|",
    ]
    for cond, s in summary.items():
        for k, v in s["coverage"].items():
            lines.append(
                f"| {cond} | {k} | {v['in50']:.3f} | {v['in80']:.3f} | {v['in90']:.3f} | "
                f"{v['in95']:.3f} | {v['sbc_ks_p']:.2g} |"
            )
    lines += [
        "",
        "Cost, medians: CPU seconds of the whole run (npe, resnet3d's 11 iterations, the check);",
        "wall seconds of the predictive check alone, on the shared 2-core machine under heavy load",
        "(so far above its CPU share). npe's distance from its training data (threshold "
        f"{next(iter(summary.values()))['domain_threshold']:.3g}):",
        "",
    ]
    for cond, s in summary.items():
        pred = s["median_predictive_s"]
        lines.append(
            f"- {cond}: {s['median_cpu_s']:.2f} s CPU per run"
            + ("" if pred is None else f"; predictive check {pred:.2f} s wall")
            + f"; distance {s['domain_distance_range'][0]:.3g} to "
            f"{s['domain_distance_range'][1]:.3g}"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--conditions", nargs="+", default=list(CONDITIONS), choices=list(CONDITIONS))
    ap.add_argument("--seeds", default="0-199")
    ap.add_argument("--draws", type=int, default=None, help="predictive draws (default: run's)")
    ap.add_argument("--out", type=Path, default=Path("results/posterior/npe_checks"))
    ap.add_argument("--summarize", action="store_true")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.summarize:
        summarize(args.out)
        return
    from physbench.posterior.predictive import DRAWS

    path = args.out / "cases.jsonl"
    done = set()
    if path.exists():
        done = {(c["condition"], c["seed"]) for c in map(json.loads, path.read_text().splitlines())}
    for seed in _seeds(args.seeds):
        for cond in args.conditions:
            if (cond, seed) in done:
                continue
            draws = args.draws if args.draws is not None else (0 if cond == "blur" else DRAWS)
            row = run_case(cond, seed, draws)
            with path.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(cond, seed, row["miss90"], row["reproduced"], row["outside"], flush=True)


if __name__ == "__main__":
    main()
