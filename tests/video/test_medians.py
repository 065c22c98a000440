"""physbench.video.medians: the tracker's small-array median is numpy's, to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.video.medians import median


@pytest.mark.parametrize("shape", [(1,), (2,), (7,), (8,), (5, 3), (6, 4), (3, 101)])
@pytest.mark.parametrize("dtype", [np.uint8, np.int64, np.float32, np.float64])
def test_equals_numpys_median_to_the_bit(shape: tuple[int, ...], dtype: type) -> None:
    rng = np.random.default_rng(sum(shape))
    a = (rng.random(shape) * 200).astype(dtype)
    for axis in range(-1, -len(shape) - 1, -1):
        got, want = median(a, axis=axis), np.median(a, axis=axis)
        assert got.dtype == want.dtype
        assert np.array_equal(got, want)
