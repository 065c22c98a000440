"""The committed visual-gap sweep (``results/video_gap``, ``benchmarks/video_gap.toml``): every
Table 1 row observed as sharp masks and as a filmed, H.264-encoded, tracked and segmented camera
video, every estimator. The sweep is a benchmark (about 10 minutes on 2 cores); these tests check
that the committed table is the whole sweep and hold the issue's claims against it: ``resnet3d``
after 11 iterations within 3x of its own sharp-mask error on every row, and below TPE, CMA-ES and
Optuna on each."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results" / "video_gap"
SPEC = ROOT / "benchmarks" / "video_gap.toml"


@pytest.fixture(scope="module")
def final() -> pd.DataFrame:
    """One row per cell: its best normalized MSE after the last iteration."""
    results = pd.read_parquet(RESULTS / "results.parquet")
    assert (results.status == "ok").all()
    iterations = tomllib.loads(SPEC.read_text())["iterations"]
    return results[results.iteration == iterations - 1]


def test_every_row_estimator_observer_and_seed_ran(final) -> None:
    spec = tomllib.loads(SPEC.read_text())
    names = {e if isinstance(e, str) else e["name"] for e in spec["estimators"]}
    assert names == {"tpe", "cmaes", "optuna", "random", "resnet3d"}
    counts = final.groupby(["scene", "unknowns", "observer", "estimator_name"]).seed.nunique()
    rows = sum(len(s["unknowns"]) for s in spec["scenes"])
    assert rows == 8  # the paper's Table 1 cells
    assert len(counts) == rows * 2 * len(names)  # sharp and camera
    assert (counts == spec["seeds"]).all()
    assert (RESULTS / "spec.toml").read_text() == SPEC.read_text()


ROWS = [
    ("three_circles", "mass"),
    ("three_circles", "elasticity"),
    ("three_circles", "mass+elasticity"),
    ("second_order", "mass"),
    ("second_order", "elasticity"),
    ("stacked_boxes", "mass"),
    ("stacked_boxes", "friction"),
    ("bouncing_balls", "mass"),
]


@pytest.mark.parametrize(("scene", "unknowns"), ROWS)
def test_resnet3d_on_camera_video_stays_within_3x_of_sharp_masks(final, scene, unknowns) -> None:
    cells = final[
        (final.estimator_name == "resnet3d") & (final.scene == scene) & (final.unknowns == unknowns)
    ]
    means = cells.groupby("observer").best_nmse.mean()
    assert means["camera"] <= 3.0 * means["sharp"], means.to_dict()


def test_resnet3d_on_camera_video_beats_the_black_box_estimators(final) -> None:
    camera = final[final.observer == "camera"]
    means = camera.groupby(["scene", "unknowns", "estimator_name"]).best_nmse.mean().unstack()
    for other in ("tpe", "cmaes", "optuna"):
        assert (means["resnet3d"] < means[other]).all(), (other, means.to_dict())


def test_the_camera_column_really_saw_different_frames(final) -> None:
    # Black-box estimators rank their candidates by image MSE and mostly pick the same iterate on
    # both observations; the losses themselves must differ (segmentation is not the identity).
    key = ["scene", "unknowns", "estimator_name", "seed"]
    loss = final.pivot_table(index=key, columns="observer", values="best_image_mse")
    assert (loss["camera"] != loss["sharp"]).mean() > 0.99
