"""Medians of the small arrays the tracker takes every frame (a blob's colours), equal to
:func:`numpy.median`'s to the bit but without its generic handling, which costs ~50 µs a call:
several times what partitioning a few hundred values does."""

from __future__ import annotations

import numpy as np


def median(a: np.ndarray, axis: int = -1) -> np.ndarray:
    """The median of ``a`` (finite values, at least one along ``axis``) along ``axis``, as
    :func:`numpy.median` gives it: the mean of the two middle values of an even count, in float64
    for integers."""
    a = np.asarray(a)
    n = a.shape[axis]
    h = n // 2
    part = np.partition(a, [h - 1, h] if n % 2 == 0 else h, axis=axis)
    dtype = np.float64 if a.dtype.kind in "biu" else a.dtype
    mid = np.take(part, h, axis=axis).astype(dtype, copy=False)
    if n % 2:
        return mid
    below = np.take(part, h - 1, axis=axis).astype(dtype, copy=False)
    return (below + mid) / 2
