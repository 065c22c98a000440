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
    observed: np.ndarray,
    simulated: np.ndarray,
    frames: int,
    resolution: int,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """One sample ``(C, 2·frames, R, R')`` float32 from two ``(T, C, H, W)`` marked sequences,
    written into ``out`` where given (a batch's slot: no copy to stack it)."""
    total = observed.shape[0]
    idx = time_indices(total, frames)
    # Each half is resized on its own and written once into the output (frames are resized one
    # by one, so the values are those of resizing both halves together); every frame of a
    # sequence as long as the observation is taken as it is, without a copy.
    halves = [
        resize(seq if len(idx) == total == seq.shape[0] else seq[idx], resolution)
        for seq in (observed, simulated)
    ]
    f = len(idx)
    shape = (halves[0].shape[1], 2 * f, *halves[0].shape[2:])
    if out is None:
        out = np.empty(shape, np.float32)
    elif out.shape != shape or out.dtype != np.float32:
        raise ValueError(f"out is {out.shape} {out.dtype}, expected {shape} float32")
    out[:, :f] = halves[0].transpose(1, 0, 2, 3)
    out[:, f:] = halves[1].transpose(1, 0, 2, 3)
    return out
