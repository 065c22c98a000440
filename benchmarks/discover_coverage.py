"""Coverage of discovery's 90 % intervals on the hidden-effect cases: writes
results/discover_coverage/.

    python benchmarks/discover_coverage.py                  # seeds 0-2, both engines (~15 min)
    python benchmarks/discover_coverage.py --seeds 0 --engines pymunk --out out/cov
    python benchmarks/discover_coverage.py --summarise     # rewrite the summary of cases.jsonl

Every hidden-effect case of ``tests/discover/test_hidden_effects.py`` (each effect in its two
scenes, :data:`~physbench.discover.synthetic.EFFECT_SCENES`) is discovered; where the effect is
named first, each of its fitted parameters' 90 % interval is checked against the hidden value.
Writes ``cases.jsonl`` (one line per case and parameter) and ``summary.json`` / ``summary.md``:
the fraction of intervals that hold the truth with a Clopper-Pearson 95 % confidence interval,
overall, per effect and per engine, for the verdict's interval (profile likelihood), the AR(1)
sandwich it starts from, and the i.i.d. Jacobian interval (``stderr`` × the t quantile) that
they replaced. The two engines see the same noise draws, so their cases are not independent.
``tests/results/test_discover_coverage.py`` checks the committed summary.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "results" / "discover_coverage"
LEVEL = 0.90


def run_case(effect: str, scene: str, engine: str, seed: int) -> list[dict[str, Any]]:
    """Discover one hidden-effect case; one row per hidden parameter (one row with
    ``named`` False when the effect is not named first)."""
    from scipy import stats

    from physbench.discover import discover
    from physbench.discover.synthetic import make_case
    from physbench.simulators.box2d_sim import Box2DSimulator
    from physbench.simulators.pymunk_sim import PymunkSimulator

    sim = {"pymunk": PymunkSimulator, "box2d": Box2DSimulator}[engine]()
    case = make_case(effect, scene, seed, sim)
    t0 = time.perf_counter()
    disc = discover([case.run], sim, diagnose=False)
    seconds = time.perf_counter() - t0
    head = {"effect": effect, "scene": scene, "engine": engine, "seed": seed}
    if disc.causes[:1] != [effect]:
        return [{**head, "named": False, "causes": disc.causes, "seconds": seconds}]
    c = disc.cause_results[0]
    fit = c.scored.fit if c.scored is not None else None
    dof = max(fit.n - fit.k, 1) if fit is not None else 1
    zt = float(stats.t.ppf(0.5 + LEVEL / 2, dof))
    rows = []
    for k, truth in case.truth.items():
        value = c.params[k]
        low, high = getattr(c, "intervals", {}).get(k, (math.nan, math.nan))
        se = c.stderr.get(k, math.nan)
        s_low, s_high = (
            fit.intervals.get(f"{effect}.{k}", (math.nan, math.nan))
            if fit is not None
            else (math.nan, math.nan)
        )
        rows.append(
            {
                **head,
                "named": True,
                "param": k,
                "truth": truth,
                "value": value,
                "low": low,
                "high": high,
                "covered": bool(low <= truth <= high),
                "stderr": se,
                "jacobian_covered": bool(abs(value - truth) <= zt * se),
                "sandwich_low": s_low,
                "sandwich_high": s_high,
                "sandwich_covered": bool(s_low <= truth <= s_high),
                "method": getattr(c, "interval_method", ""),
                "seconds": seconds,
            }
        )
    return rows


def coverage(rows: list[dict[str, Any]], key: str = "covered") -> dict[str, Any]:
    """Fraction of ``rows`` whose interval holds the truth, with a Clopper-Pearson 95 % CI."""
    from scipy import stats

    n = len(rows)
    k = sum(bool(r[key]) for r in rows)
    if n == 0:
        return {"intervals": 0, "covered": 0, "fraction": None, "ci95": None}
    ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="exact")
    return {
        "intervals": n,
        "covered": k,
        "fraction": k / n,
        "ci95": [float(ci.low), float(ci.high)],
    }


def summarise(rows: list[dict[str, Any]], seeds: list[int], engines: list[str]) -> dict[str, Any]:
    named = [r for r in rows if r["named"]]
    cases = {(r["effect"], r["scene"], r["engine"], r["seed"]) for r in rows}
    by = lambda f: {  # noqa: E731
        v: {
            "new": coverage([r for r in named if r[f] == v]),
            "sandwich": coverage([r for r in named if r[f] == v], "sandwich_covered"),
            "jacobian": coverage([r for r in named if r[f] == v], "jacobian_covered"),
        }
        for v in sorted({r[f] for r in named})
    }
    return {
        "level": LEVEL,
        "seeds": seeds,
        "engines": engines,
        "cases": len(cases),
        "named_first": len({(r["effect"], r["scene"], r["engine"], r["seed"]) for r in named}),
        "method": sorted({r["method"] for r in named}),
        "coverage": coverage(named),
        "sandwich_coverage": coverage(named, "sandwich_covered"),
        "jacobian_coverage": coverage(named, "jacobian_covered"),
        "per_effect": by("effect"),
        "per_engine": by("engine"),
    }


def markdown(s: dict[str, Any]) -> str:
    def cell(c: dict[str, Any]) -> str:
        if not c["intervals"]:
            return "-"
        lo, hi = c["ci95"]
        return f"{c['covered']}/{c['intervals']} = {c['fraction']:.0%} [{lo:.0%}, {hi:.0%}]"

    lines = [
        f"Coverage of the {s['level'] * 100:g} % intervals of discovery on the hidden-effect cases "
        f"(seeds {', '.join(map(str, s['seeds']))}; engines {', '.join(s['engines'])}; "
        f"{s['cases']} cases, {s['named_first']} with the effect named first; "
        f"method {', '.join(s['method'])}). Each cell: intervals holding the truth, fraction, "
        "Clopper-Pearson 95 % CI.",
        "",
        "| | verdict's interval (profile) | AR(1) sandwich alone | i.i.d. Jacobian (replaced) |",
        "|---|---|---|---|",
        f"| **all** | {cell(s['coverage'])} | {cell(s['sandwich_coverage'])} | "
        f"{cell(s['jacobian_coverage'])} |",
    ]
    for group in ("per_engine", "per_effect"):
        for k, v in s[group].items():
            lines.append(
                f"| {k} | {cell(v['new'])} | {cell(v['sandwich'])} | {cell(v['jacobian'])} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    from physbench.discover.synthetic import EFFECT_SCENES

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--engines", default="pymunk,box2d")
    ap.add_argument("--effects", default="", help="comma-separated subset (default: all)")
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT)
    ap.add_argument(
        "--summarise", action="store_true", help="only rewrite the summary of OUT/cases.jsonl"
    )
    a = ap.parse_args()
    seeds = [int(x) for x in a.seeds.split(",")]
    engines = a.engines.split(",")
    effects = a.effects.split(",") if a.effects else list(EFFECT_SCENES)
    a.out.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    if a.summarise:
        rows = [json.loads(x) for x in (a.out / "cases.jsonl").read_text().splitlines()]
        seeds = sorted({r["seed"] for r in rows})
        engines = list(dict.fromkeys(r["engine"] for r in rows))
        effects = []
    with open(a.out / "cases.jsonl", "a" if a.summarise else "w") as f:
        for seed in seeds:
            for effect in effects:
                for scene in EFFECT_SCENES[effect]:
                    for engine in engines:
                        got = run_case(effect, scene, engine, seed)
                        for r in got:
                            f.write(json.dumps(r) + "\n")
                        f.flush()
                        rows += got
                        print(
                            f"{effect}/{scene}/{engine}/{seed}: "
                            + ", ".join(
                                f"{r['param']} {'ok' if r['covered'] else 'MISS'}"
                                if r["named"]
                                else "not named"
                                for r in got
                            ),
                            flush=True,
                        )
    s = summarise(rows, seeds, engines)
    (a.out / "summary.json").write_text(json.dumps(s, indent=1) + "\n")
    (a.out / "summary.md").write_text(markdown(s))
    print(markdown(s))


if __name__ == "__main__":
    main()
