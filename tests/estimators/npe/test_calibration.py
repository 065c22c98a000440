"""The committed calibration measurement (benchmarks/npe_calibration.py) meets the issue's bands
on 200 held-out seeds per row: 90 % intervals cover 85-95 % of the truths, 50 % intervals 45-55 %
(per row, its unknowns pooled), and no unknown's SBC ranks are rejected as non-uniform at p = 0.01;
one posterior costs at most 2 s."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

SUMMARY = Path(__file__).parents[3] / "results" / "posterior" / "npe" / "summary.json"
ROWS = ("three_circles[mass]", "three_circles[elasticity]", "second_order[mass]")


def _summary() -> dict:
    return json.loads(SUMMARY.read_text())


def test_summary_covers_three_rows_on_200_held_out_seeds() -> None:
    summary = _summary()
    assert set(summary) >= set(ROWS)
    for row in summary.values():
        assert row["seeds"] == 200
        assert row["cost_s"] <= 2.0  # the cost target: one observation's posterior in 2 s


@pytest.mark.parametrize("row", ROWS)
def test_coverage_lies_in_the_bands_and_sbc_is_not_rejected(row: str) -> None:
    keys = _summary()[row]["per_key"]
    for level, (lo, hi) in (("coverage90", (0.85, 0.95)), ("coverage50", (0.45, 0.55))):
        pooled = sum(k[level] for k in keys.values()) / len(keys)
        assert lo <= pooled <= hi, f"{row}: {level} {pooled:.3f} outside [{lo}, {hi}]"
    for key, k in keys.items():
        assert k["sbc_ks_p"] > 0.01, f"{row} {key}: SBC ranks rejected (p = {k['sbc_ks_p']:.3g})"
