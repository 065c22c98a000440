"""Some cases of the field-camera grid rerun with a later tracker, beside the grid's own rows.

``benchmarks/video_discover.py --camera field --only SCENE/ ... --out DIR`` reruns part of the grid
(same cases, same camera domains); this script puts each rerun's rows beside the same cases of
the grid (``--grid``, default ``results/video_discover_field/results.json``) and of earlier
reruns, and writes one JSON (every stage's rows) and a Markdown table (per stage: right, wrong,
refused, false alarms, effects named with other causes, the median of the cases' median centre
errors; per case: what each stage named and its centre error).

    python benchmarks/field_rerun.py --grid results/video_discover_field/earlier/results.json \\
        --stage "gamma decoded=git 65a02a1:OLD.json" \\
        --stage "+ faint end=git HEAD:DIR1/results.json,DIR2/results.json" \\
        --out results/video_discover_field/earlier/pendulum_rerun

A stage is ``NAME=CODE:FILE[,FILE...]``; a FILE may be an earlier output of this script (its
last stage's rows are read).
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

TOLERANCE = 0.10


def key(row: dict) -> str:
    return f"{row['effect'] or 'control'}/{row['scene']}/{row['engine']}/{row['seed']}"


def right(row: dict) -> bool:
    got = row["filmed"]
    if not row["effect"]:
        return got["causes"] == []
    return (got["causes"] or [])[:1] == [row["effect"]] and got["error"] <= TOLERANCE


def centre(row: dict) -> float | None:
    px = row["field"].get("centre_px") or {}
    values = [v["median"] for v in px.values()]
    return max(values) if values else None


def summary(rows: list[dict]) -> dict:
    refused = [r for r in rows if r["field"].get("failure")]
    done = [r for r in rows if not r["field"].get("failure")]
    centres = [c for r in done if (c := centre(r)) is not None]
    return {
        "cases": len(rows),
        "right": sum(right(r) for r in done),
        "wrong": sum(not right(r) for r in done),
        "refused": len(refused),
        "false_alarms": sum(1 for r in done if not r["effect"] and r["filmed"]["causes"]),
        "named_with_others": sum(
            1
            for r in done
            if r["effect"] in r["filmed"]["causes"] and len(r["filmed"]["causes"]) > 1
        ),
        "centre_px_median": round(statistics.median(centres), 2) if centres else None,
    }


def read_rows(path: Path) -> list[dict]:
    data = json.loads(path.read_text())
    if "stages" in data:
        return data["stages"][-1]["rows"]
    return data["rows"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=Path, default=Path("results/video_discover_field/results.json"))
    ap.add_argument("--stage", action="append", required=True, help="NAME=CODE:FILE[,FILE...]")
    ap.add_argument("--out", type=Path, required=True, help="path without suffix")
    a = ap.parse_args()
    stages = []
    for spec in a.stage:
        name, rest = spec.split("=", 1)
        code, files = rest.split(":", 1)
        rows = [r for f in files.split(",") for r in read_rows(Path(f))]
        stages.append({"name": name, "code": code, "rows": sorted(rows, key=key)})
    cases = {key(r) for r in stages[-1]["rows"]}
    grid = sorted((r for r in read_rows(a.grid) if key(r) in cases), key=key)
    stages.insert(0, {"name": "before (results.json)", "code": "the grid", "rows": grid})
    for s in stages:
        if {key(r) for r in s["rows"]} != cases:
            raise SystemExit(f"stage {s['name']!r} holds other cases than the last stage")
        s["summary"] = summary(s["rows"])
    a.out.with_suffix(".json").write_text(json.dumps({"stages": stages}, indent=1) + "\n")
    cols = [
        "cases",
        "right",
        "wrong",
        "refused",
        "false_alarms",
        "named_with_others",
        "centre_px_median",
    ]
    lines = [
        "# Field-camera cases rerun with later trackers",
        "",
        f"Written by `benchmarks/field_rerun.py`; right: the hidden effect named first within "
        f"{TOLERANCE:.0%}, or no cause for a control. x264 is not bit-exact across runs, so a "
        "rerun moves single cases. Centre: the body's median centre error (px), median over cases.",
        "",
        "| stage | code | " + " | ".join(cols) + " |",
        "|---|---|" + "---|" * len(cols),
    ]
    for s in stages:
        lines.append(
            f"| {s['name']} | {s['code']} | "
            + " | ".join(str(s["summary"][c]) for c in cols)
            + " |"
        )
    lines += [
        "",
        "| case | " + " | ".join(s["name"] for s in stages) + " |",
        "|---|" + "---|" * len(stages),
    ]
    by = [{key(r): r for r in s["rows"]} for s in stages]
    for k in sorted(cases):
        cells = []
        for rows in by:
            r = rows[k]
            if r["field"].get("failure"):
                cells.append("refused")
                continue
            c = centre(r)
            mark = "" if right(r) else " (wrong)"
            cells.append(
                f"{r['filmed']['causes']}{mark}, {c:.2f} px"
                if c is not None
                else str(r["filmed"]["causes"])
            )
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    a.out.with_suffix(".md").write_text("\n".join(lines) + "\n")
    for s in stages:
        print(s["name"], s["summary"])


if __name__ == "__main__":
    main()
