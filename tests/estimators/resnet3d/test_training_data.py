"""Training pairs: range-normalised targets and blur augmentation of the observed half only."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.estimators.resnet3d.network import NetConfig  # noqa: E402
from physbench.estimators.resnet3d.training_data import DataSpec, PairMaker  # noqa: E402

TINY = NetConfig(n_outputs=1, widths=(4, 8, 8, 8), resolution=16, frames=6)
TINY_DATA = DataSpec(
    "three_circles", ("mass",), render_resolution=32, resolution=16, frames=6, group=3
)


def test_pairs_targets_are_range_normalised_differences() -> None:
    maker = PairMaker(TINY_DATA)
    x, y = maker.group(12345)
    assert x.shape[1:] == (2, 12, 16, 16)
    assert y.shape == (x.shape[0], 1) and np.all(np.abs(y) <= 1)
    # Ordered pairs: (i, j) and (j, i) have opposite targets.
    assert np.isclose(y.sum(), 0.0, atol=1e-5)


def test_blur_augmentation_blurs_the_observed_half_only() -> None:
    sharp = PairMaker(TINY_DATA).group(4321)
    blurred = PairMaker(
        DataSpec(**{**TINY_DATA.__dict__, "blur_max": 3.0, "blur_prob": 1.0})
    ).group(4321)
    frames = TINY_DATA.frames
    assert np.array_equal(sharp[1], blurred[1])  # same simulations, same targets
    assert np.array_equal(
        sharp[0][:, :, frames:], blurred[0][:, :, frames:]
    )  # simulated half untouched
    assert not np.allclose(sharp[0][:, :, :frames], blurred[0][:, :, :frames])

    # Blur smooths: less total variation across the image.
    def tv(x: np.ndarray) -> float:
        return float(np.abs(np.diff(x, axis=-1)).sum() + np.abs(np.diff(x, axis=-2)).sum())

    assert tv(blurred[0][:, :, :frames]) < 0.95 * tv(sharp[0][:, :, :frames])


def test_near_pairs_are_as_close_as_a_second_correction() -> None:
    """``near``: simulations drawn near another's parameters give small targets; ``near = 0``
    leaves the samples of a spec exactly as before (no extra random draws)."""
    prior = PairMaker(TINY_DATA).group(777)
    assert np.array_equal(prior[1], PairMaker(DataSpec(**TINY_DATA.__dict__)).group(777)[1])
    near = DataSpec(**{**TINY_DATA.__dict__, "near": 1.0, "near_scale": 0.02})
    x, y = PairMaker(near).group(777)
    assert x.shape == prior[0].shape and np.all(np.abs(y) <= 1)
    # Every simulation after the first is within a few spreads of an earlier one: each body's
    # targets include pairs far smaller than prior pairs typically are.
    assert np.median(np.abs(y)) < 0.1 < np.median(np.abs(prior[1]))
    assert DataSpec.from_dict(near.to_dict()) == near
    assert (
        DataSpec.from_dict({k: v for k, v in TINY_DATA.to_dict().items() if k != "near"}).near == 0
    )
