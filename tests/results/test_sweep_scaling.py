"""The committed sweep-scaling benchmark (``results/sweep_scaling``,
``benchmarks/sweep_scaling.py``): its numbers agree with each other and with the table
docs/results.md quotes. Not a timing test: nothing here depends on this machine's speed."""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "sweep_scaling"
ROWS = ("sweep", "cell_loop", "raw")


def _data() -> dict:
    return json.loads((RESULTS / "sweep_scaling.json").read_text())


def test_medians_and_ratios_follow_from_the_runs() -> None:
    data = _data()
    assert data["machine"] == "2 cores" and data["repeats"] >= 3
    for row in ROWS:
        one, two = data[row]["1"], data[row]["2"]
        for w in (one, two):
            assert len(w["runs_s"]) == data["repeats"]
            assert abs(w["median_s"] - statistics.median(w["runs_s"])) <= 1e-3
        assert abs(data[row]["ratio"] - one["median_s"] / two["median_s"]) <= 1e-3


def test_the_breakdown_fits_inside_the_end_to_end_time() -> None:
    data = _data()
    for w in ("1", "2"):
        b = data["sweep"][w]["breakdown"]
        assert abs(b["wall"] - data["sweep"][w]["median_s"]) <= 1e-3
        assert abs(b["cells_loop"] - data["cell_loop"][w]["median_s"]) <= 1e-3
        serial = [
            "interpreter_start",
            "cli_import",
            "before_cells",
            "cells_loop",
            "pool_shutdown",
            "assemble",
            "write_table",
            "write_summary",
            "after_summary",
        ]
        assert sum(b[k] for k in serial) <= b["wall"]
        assert 0 < b["worker_busy"] <= 1
        assert b["parent_cell_dumps"] + b["parent_cell_write"] <= b["parent_cell_save"] + 1e-3
    # one worker does every cell in the loop, so its run time cannot exceed the loop's
    assert data["sweep"]["1"]["breakdown"]["cell_run_sum"] <= data["cell_loop"]["1"]["median_s"]


def test_the_markdown_table_shows_the_json() -> None:
    data = _data()
    text = (RESULTS / "sweep_scaling.md").read_text()
    rows = re.findall(r"^\| ([^|]+) \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|$", text, re.M)
    assert len(rows) == len(ROWS)
    for row, (_, t1, t2, ratio) in zip(ROWS, rows, strict=True):
        assert float(t1) == round(data[row]["1"]["median_s"], 2)
        assert float(t2) == round(data[row]["2"]["median_s"], 2)
        assert float(ratio) == round(data[row]["ratio"], 2)
    assert "2 cores" in text


def test_docs_quote_the_committed_figures() -> None:
    docs = (ROOT / "docs" / "results.md").read_text()
    sweep = _data()["sweep"]
    quoted = (
        f"{sweep['1']['median_s']:.2f} s with one worker and {sweep['2']['median_s']:.2f} s "
        f"with two ({sweep['ratio']:.2f}×"
    )
    assert quoted in docs
