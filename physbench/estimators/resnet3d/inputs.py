"""Network inputs: observed ‖ simulated marked sequences, concatenated along time.

Both sequences arrive as the loop renders them for a marked object (``focus=body``):
``(T, 2, H, W)`` with channel 0 = the other bodies and channel 1 = the marked body (the paper's
colour marking). The same function prepares training pairs and inference inputs, so both see
identical pixels.
"""

from __future__ import annotations

import numpy as np


def time_indices(total: int, frames: int) -> np.ndarray:
    """``frames`` evenly spaced frame indices out of ``total`` (all of them if fewer)."""
    if frames >= total:
        return np.arange(total)
    return np.round(np.linspace(0, total - 1, frames)).astype(int)


def resize(frames: np.ndarray, size: int) -> np.ndarray:
    """Area-average ``(..., H, W)`` so that H becomes ``size`` (integer factors take a fast
    path)."""
    h, w = frames.shape[-2:]
    if h == size:
        return frames
    if h % size == 0 and w % (h // size) == 0:
        # Sum the f x f blocks from strided views, each row of a block first, then divide: the
        # order of ``reshape(..., size, f, w // f, f).mean(axis=(-3, -1))``, so the same float32
        # values at f = 2, and about 15x faster (numpy's mean over two non-adjacent axes was most
        # of the time a training sample took to make at 64 -> 32 pixels).
        f = h // size
        rows = [frames[..., i::f, :] for i in range(f)]
        sums = [sum((r[..., j::f] for j in range(1, f)), r[..., 0::f]) for r in rows]
        return sum(sums[1:], sums[0]) / (f * f)
    from scipy.ndimage import zoom

    z = [1.0] * (frames.ndim - 2) + [size / h, size / h]
    return zoom(frames, z, order=1)


def make_input(
    observed: np.ndarray, simulated: np.ndarray, frames: int, resolution: int
) -> np.ndarray:
    """One sample ``(C, 2·frames, R, R')`` float32 from two ``(T, C, H, W)`` marked sequences."""
    idx = time_indices(observed.shape[0], frames)
    both = np.concatenate([observed[idx], simulated[idx]], axis=0)  # (2F, C, H, W)
    return np.ascontiguousarray(resize(both, resolution).transpose(1, 0, 2, 3), dtype=np.float32)
