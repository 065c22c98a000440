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


SPECS = ("smoke", "smoke48")


def _all() -> dict:
    return json.loads((RESULTS / "sweep_scaling.json").read_text())


def _specs() -> list[tuple[str, dict]]:
    data = _all()
    assert set(data["specs"]) == set(SPECS)
    return [(name, {**data["specs"][name], "repeats": data["repeats"]}) for name in SPECS]


def test_medians_and_ratios_follow_from_the_runs() -> None:
    data = _all()
    assert data["machine"] == "2 cores" and data["repeats"] >= 3
    for _, data in _specs():
        _check_medians(data)


def test_the_amdahl_bound_follows_from_the_one_worker_run() -> None:
    for _, data in _specs():
        a = data["amdahl"]
        assert abs(a["parallel_s"] + a["serial_s"] - data["sweep"]["1"]["median_s"]) <= 0.02
        assert abs(a["best_2_workers_s"] - (a["serial_s"] + a["parallel_s"] / 2)) <= 0.01
        assert abs(a["best_ratio"] - data["sweep"]["1"]["median_s"] / a["best_2_workers_s"]) < 0.01
        # no run can beat the bound by more than the noise of the medians
        assert data["sweep"]["ratio"] <= a["best_ratio"] + 0.05


def test_the_cpu_bound_follows_from_the_two_worker_run() -> None:
    for _, data in _specs():
        a, two = data["amdahl"], data["sweep"]["2"]
        assert abs(a["cpu_2_workers_s"] - two["breakdown"]["cpu"]) <= 1e-3
        assert (
            abs(a["cpu_bound_ratio"] - data["sweep"]["1"]["median_s"] * 2 / a["cpu_2_workers_s"])
            < 0.01
        )
        # 2 cores: a run's wall time is at least half its CPU time (medians: a little noise)
        assert two["median_s"] >= a["cpu_2_workers_s"] / 2 - 0.05
        assert data["sweep"]["ratio"] <= a["cpu_bound_ratio"] + 0.05


def _check_medians(data: dict) -> None:
    for row in ROWS:
        one, two = data[row]["1"], data[row]["2"]
        for w in (one, two):
            assert len(w["runs_s"]) == data["repeats"]
            assert abs(w["median_s"] - statistics.median(w["runs_s"])) <= 1e-3
        assert abs(data[row]["ratio"] - one["median_s"] / two["median_s"]) <= 1e-3


def test_the_breakdown_fits_inside_the_end_to_end_time() -> None:
    for _, data in _specs():
        _check_breakdown(data)


def _check_breakdown(data: dict) -> None:
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
        assert b["exit"] < 0.1  # the phase the teardown skip shortened (0.30-0.37 s before)
        # medians over the repeats, each taken alone: their sum may pass the total's median a bit
        assert b["parent_cell_dumps"] + b["parent_cell_write"] <= 1.05 * b["parent_cell_save"]
    # one worker does every cell in the loop, so its run time cannot exceed the loop's
    assert data["sweep"]["1"]["breakdown"]["cell_run_sum"] <= data["cell_loop"]["1"]["median_s"]


def test_the_markdown_table_shows_the_json() -> None:
    text = (RESULTS / "sweep_scaling.md").read_text()
    rows = re.findall(
        r"^\| ([^|]+) \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \| [\d. ]+ \| [\d. ]+ \|$", text, re.M
    )
    rows = [r for r in rows if "," in r[0] or ":" in r[0]]  # not the Amdahl table's rows
    specs = _specs()
    assert len(rows) == len(ROWS) * len(specs)
    expected = [(d, row) for _, d in specs for row in ROWS]
    for (data, row), (_, t1, t2, ratio) in zip(expected, rows, strict=True):
        assert float(t1) == round(data[row]["1"]["median_s"], 2)
        assert float(t2) == round(data[row]["2"]["median_s"], 2)
        assert float(ratio) == round(data[row]["ratio"], 2)
    assert "2 cores" in text


def test_docs_quote_the_committed_figures() -> None:
    docs = (ROOT / "docs" / "results.md").read_text()
    for name, data in _specs():
        sweep = data["sweep"]
        quoted = (
            f"| {name}, end to end | {sweep['1']['median_s']:.2f} s | "
            f"{sweep['2']['median_s']:.2f} s | **{sweep['ratio']:.2f}×** |"
        )
        assert quoted in docs, quoted
        assert f"{data['amdahl']['best_ratio']:.2f}×" in docs
        assert f"{data['amdahl']['cpu_bound_ratio']:.2f}×" in docs
