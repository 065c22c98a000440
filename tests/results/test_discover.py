"""The committed real-data discovery results (``results/discover/``, written by
``python benchmarks/discover_real.py``): their layout and the claims docs/results.md and
docs/discover.md make about them. These tests read the committed files; they do not recompute
anything."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

RESULTS = Path(__file__).resolve().parents[2] / "results" / "discover"
DATASETS = ["billiards", "billiards_slow", "pendulum_kaheman", "pendulum_benard"]
WHIFFLE = ["whiffle_ball_1", "whiffle_ball_2", "yellow_whiffle_ball", "orange_whiffle_ball"]
DENSE = ["golf_ball", "baseball", "bowling_ball"]
G = 9.81


def verdict(name: str) -> dict:
    return json.loads((RESULTS / name / "verdict.json").read_text())


def chosen(d: dict, effect: str) -> dict:
    return next(c for c in d["candidates"] if c["chosen"] and c["effect"] == effect)


@pytest.mark.parametrize("name", DATASETS + [f"ball_drops/{b}" for b in WHIFFLE + DENSE])
def test_verdict_json_has_the_documented_layout(name):
    d = verdict(name)
    assert {"base", "candidates", "causes", "gain"} <= set(d)
    assert d["base"]["heldout_error"] > 0 and 0.0 <= d["gain"] < 1.0
    for c in d["candidates"]:
        assert {"effect", "params", "heldout_error", "gain", "criterion"} <= set(c)
    assert [c["effect"] for c in d["candidates"] if c["chosen"]] == d["causes"]
    if d["causes"]:  # the reported gain is the final model's against the base
        assert d["gain"] == pytest.approx(
            1 - d["final"]["heldout_error"] / d["base"]["heldout_error"], rel=1e-6
        )
    assert (RESULTS / name / "verdict.txt").is_file()


def test_billiards_rolling_resistance_matches_the_measured_deceleration():
    d = verdict("billiards")
    assert d["causes"][0] == "rolling_resistance" and d["gain"] > 0.3
    decel = chosen(d, "rolling_resistance")["params"]["mu"] * G
    assert 0.035 < decel < 0.06  # PROVENANCE: 0.047 m/s² (IQR 0.042-0.051)
    # the cushions: restitution fitted in the base model, and measured directly at about 0.6
    e = d["final"]["params"]["ball.elasticity"]
    cushions = json.loads((RESULTS / "billiards" / "cushions.json").read_text())
    e_direct = sorted(b["e_n"] for b in cushions["bounces"])[len(cushions["bounces"]) // 2]
    assert 0.45 < e < 0.75 and abs(e - e_direct) < 0.1


def test_ball_drops_name_drag_for_whiffle_balls_far_above_dense_balls():
    rows = {r["ball"]: r for r in json.loads((RESULTS / "ball_drops" / "summary.json").read_text())}
    for b in WHIFFLE:
        assert "linear_drag" in rows[b]["causes"] and rows[b]["gain"] > 0.8
        # the data decide linear: the quadratic law predicts the held-out drop ends worse
        assert rows[b]["heldout"]["linear_drag"] < rows[b]["heldout"]["quadratic_drag"]
    for b in DENSE:
        assert not {"linear_drag", "quadratic_drag"} & set(rows[b]["causes"])
    k_whiffle = min(rows[b]["quadratic_k"][0] for b in WHIFFLE)
    k_dense = max(rows[b]["quadratic_k"][0] for b in DENSE)
    assert k_whiffle > 4 * k_dense
    c_whiffle = min(rows[b]["linear_c_per_m"][0] for b in WHIFFLE)
    assert c_whiffle > 4 * max(rows[b]["linear_c_per_m"][0] for b in DENSE)


@pytest.mark.parametrize("name", ["pendulum_kaheman", "pendulum_benard"])
def test_pendulums_name_joint_damping(name):
    d = verdict(name)
    assert d["causes"][0] in ("joint_viscous_damping", "joint_coulomb_friction") and d["gain"] > 0.5
    assert all(c.startswith("joint_") for c in d["causes"])
