"""The committed visual-gap sweep (``results/video_gap``, ``benchmarks/video_gap.toml``): every
Table 1 row observed as sharp masks and as a filmed, H.264-encoded, tracked and segmented camera
video, every estimator. The sweep is a benchmark (about 10 minutes on 2 cores); these tests check
that the committed table is the whole sweep and hold the issue's claims against it: ``resnet3d``
after 11 iterations within 3x of its own sharp-mask error on every row but the box scene's masses
(an expected failure, measured again over 100 seeds), and below TPE, CMA-ES and Optuna on each."""

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
BOXES = pytest.mark.xfail(
    strict=True,
    reason="the box scene's masses on camera video: 3.5x over these 20 seeds, 3.3x (95 % interval "
    "1.8-4.9x) over 100 (results/video_gap_boxes); the 2.3x of the earlier run was a draw of 20 "
    "seeds: the tracker of that run gave 11.8x over 100 (one seed 1,270x the median)",
)
WITHIN_3X = [
    pytest.param(*row, marks=BOXES) if row == ("stacked_boxes", "mass") else row for row in ROWS
]


@pytest.mark.parametrize(("scene", "unknowns"), WITHIN_3X)
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


def test_the_box_scenes_masses_over_100_seeds(final) -> None:
    """``results/video_gap_boxes`` (``benchmarks/video_gap_boxes.toml``): the row whose 20 seeds
    cannot tell whether it is within 3x, with 100; its first 20 seeds are the sweep's cells."""
    boxes = pd.read_parquet(ROOT / "results" / "video_gap_boxes" / "results.parquet")
    assert (boxes.status == "ok").all()
    boxes = boxes[boxes.iteration == boxes.iteration.max()]
    means, seeds = {}, {}
    for observer in ("sharp", "camera"):
        mine = boxes[boxes.observer == observer].set_index("seed").best_nmse.sort_index()
        assert list(mine.index) == list(range(100))
        means[observer], seeds[observer] = mine.mean(), mine
        sweep = final[
            (final.estimator_name == "resnet3d")
            & (final.scene == "stacked_boxes")
            & (final.unknowns == "mass")
            & (final.observer == observer)
        ]
        assert sweep.set_index("seed").best_nmse.sort_index().tolist() == mine.iloc[:20].tolist()
    ratio = means["camera"] / means["sharp"]
    assert 3.0 < ratio < 3.5  # docs/results.md: 3.3x
    # No run on camera video fails outright (the tracker before gave one at 1,270x the median).
    assert seeds["camera"].max() < 50 * seeds["camera"].median()
