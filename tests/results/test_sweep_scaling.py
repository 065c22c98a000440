"""The committed sweep-scaling benchmark (``results/sweep_scaling``,
``benchmarks/sweep_scaling.py``): its numbers agree with each other and with the tables of its
summary. Not a timing test: nothing here depends on this machine's speed."""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "sweep_scaling"
#: The same benchmark on a 16-core machine (``benchmarks/sweep_scaling_device.sh``).
CORES16 = RESULTS / "cores16"
FOLDERS = [RESULTS, CORES16]


def _all(folder: Path = RESULTS) -> dict:
    return json.loads((folder / "results.json").read_text())


def _specs() -> list[tuple[str, dict]]:
    return [
        (name, s)
        for folder in FOLDERS
        for name, s in _all(folder)["specs"].items()
        if "prediction" in s
    ]


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
    for folder in FOLDERS:
        _summary_shows(folder)


def _summary_shows(folder: Path) -> None:
    text = (folder / "summary.md").read_text()
    for name, s in _all(folder)["specs"].items():
        if "prediction" not in s:
            continue
        assert f"## {name} " in text
        for key, m in s["median"].items():
            if key.startswith("raw"):
                continue
            ex, w = key.rsplit("_", 1)
            row = rf"^\| {ex} \| {w} \| {m['wall']:.2f} \| {s['ratios'][key]:.2f} \|"
            assert re.search(row, text, re.M), row
    docs = (ROOT / "docs" / "results.md").read_text()
    assert "../results/sweep_scaling/summary.md" in docs


@pytest.mark.xfail(strict=True, reason="16 cores: smoke48 5.14x at 16 workers, not 8x")
def test_on_16_cores_smoke48_scales_8x() -> None:
    # Issue 29's target, measured on a 16-core machine (results/sweep_scaling/cores16): local
    # processes reached 5.14x at 16 workers (56.9 s -> 11.1 s). Each worker imports its
    # estimators' libraries (there: hyperopt 2.1 s, nevergrad 2.9 s, cma 2.1 s) and starts up:
    # 5.5-6.7 s of CPU for the busiest, against 3.1 s of cells per worker.
    data = _all(CORES16)
    assert data["machine"] == "16 cores"
    assert data["specs"]["smoke48"]["ratios"]["processes_16"] >= 8.0


def test_on_16_cores_dask_is_within_1_2x_of_local_processes() -> None:
    # Measured there: a LocalCluster took 1.16x the local processes' wall time at 8 workers and
    # 1.17x at 16 (1.28x and 1.53x before the machine's install compiled its byte code once).
    data = _all(CORES16)
    ratios = data["specs"]["smoke48"]["dask_vs_processes"]
    assert set(ratios) == {"8", "16"}
    assert max(ratios.values()) <= 1.2
