"""Pixel summaries: mass, centroid and spread of each channel per frame."""

from __future__ import annotations

import numpy as np

from physbench.estimators.npe.features import PER_FRAME, summarize


def test_summaries_of_known_blobs() -> None:
    frames = np.zeros((4, 2, 8, 10), np.float32)
    frames[:, 1, 2, 3] = 1.0  # marked body: one pixel at row 2, column 3
    frames[:, 1, 2, 5] = 1.0  # ...and column 5: centroid column 4, spread one column
    frames[:2, 0, 6, 8] = 0.5  # the others: two frames, then out of view
    f = summarize(frames, 4).reshape(4, PER_FRAME)
    np.testing.assert_allclose(f[:, 0], 2 / 80)
    np.testing.assert_allclose(f[:, 1], 4.5 / 10)
    np.testing.assert_allclose(f[:, 2], 2.5 / 8)
    np.testing.assert_allclose(f[:, 3], 1 / 10, rtol=1e-6)
    np.testing.assert_allclose(f[:, 4], 0, atol=1e-6)
    np.testing.assert_allclose(f[:, 5], [0.5 / 80] * 2 + [0, 0])
    np.testing.assert_allclose(f[:, 6], [8.5 / 10] * 2 + [0.5, 0.5])
    np.testing.assert_allclose(f[:, 7], [6.5 / 8] * 2 + [0.5, 0.5])


def test_time_subsampling() -> None:
    frames = np.zeros((30, 2, 8, 8), np.float32)
    for t in range(30):
        frames[t, 1, 0, t % 8] = 1.0
    f = summarize(frames, 3).reshape(3, PER_FRAME)
    np.testing.assert_allclose(f[:, 1], [(t % 8 + 0.5) / 8 for t in (0, 14, 29)])
