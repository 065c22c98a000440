"""The committed sweep-scaling benchmark (``results/sweep_scaling``,
``benchmarks/sweep_scaling.py``): its numbers agree with each other and with the tables of its
summary. Not a timing test: nothing here depends on this machine's speed."""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "sweep_scaling"


def _all() -> dict:
    return json.loads((RESULTS / "results.json").read_text())


def _specs() -> list[tuple[str, dict]]:
    return [(name, s) for name, s in _all()["specs"].items() if "prediction" in s]


def test_medians_and_ratios_follow_from_the_runs() -> None:
    assert _specs()
    for _, s in _specs():
        one = s["median"]["processes_1"]["wall"]
        for key, runs in s["runs"].items():
            assert abs(s["median"][key]["wall"] - statistics.median(r["wall"] for r in runs)) < 1e-3
            assert abs(s["ratios"][key] - one / s["median"][key]["wall"]) < 1e-2


def test_every_cell_ran_once_and_gave_the_same_table() -> None:
    for _, s in _specs():
        cells = s["median"]["processes_1"]["cells"]
        assert cells == sum(s["median"]["processes_1"]["estimators_cells"].values())
        for key, m in s["median"].items():
            if key.startswith("raw"):
                continue
            assert sum(m["cells_per_worker"]) == cells == m["cells"], key
            assert s["identical_tables"][key], f"{key}: another table than processes_1's"


def test_the_projections_follow_from_the_measured_parts() -> None:
    for _, s in _specs():
        for n, p in s["prediction"].items():
            work_n = p["work_cpu"] / int(n)
            assert abs(p["amdahl_s"] - (p["serial_cpu"] + p["overhead_n_cpu"] + work_n)) < 0.01
            t1 = p["serial_cpu"] + p["overhead_1_cpu"] + p["work_cpu"]
            assert abs(p["t1_cpu"] - t1) < 0.01
            assert abs(p["replay_s"] - (p["serial_cpu"] + p["replay"]["span_s"])) < 0.01
        for n, r in s["replays"].items():
            assert len(r["cells_per_worker"]) == int(n)
            assert sum(r["cells_per_worker"]) == s["median"]["processes_1"]["cells"]


def test_the_summary_shows_the_json() -> None:
    text = (RESULTS / "summary.md").read_text()
    for name, s in _specs():
        assert f"## {name} " in text
        for key, m in s["median"].items():
            if key.startswith("raw"):
                continue
            ex, w = key.rsplit("_", 1)
            row = rf"^\| {ex} \| {w} \| {m['wall']:.2f} \| {s['ratios'][key]:.2f} \|"
            assert re.search(row, text, re.M), row
    docs = (ROOT / "docs" / "results.md").read_text()
    assert "../results/sweep_scaling/summary.md" in docs
