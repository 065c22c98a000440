"""The pixel-summary embedding: per frame, where each channel's intensity is and how much.

The paper embeds the video with a 3D-ResNet. Trained end to end on this project's CPU that costs
about 20-200 ms per sample, while simulating and rendering a sample costs 3-11 ms (three_circles:
11 ms, second_order: 3 ms, measured), so the network would take hours where the simulations take
minutes. These summaries cost 2.5 ms per 30-frame 64-pixel view and keep what the dynamics show:
the marked body's path and size (channel 1) and the other bodies' joint path (channel 0).
"""

from __future__ import annotations

import numpy as np

from physbench.estimators.resnet3d.inputs import time_indices

#: Features per frame: channel 1's mass, centroid (x, y) and spread (x, y); channel 0's mass and
#: centroid (x, y).
PER_FRAME = 8
#: What :func:`distance` measures, as the posterior's training-domain record states it.
DISTANCE = "the mean squared z-score of its summary features against the training set"
#: An input is outside the training data beyond this many times the largest distance of a
#: validation case (the weights' sidecar records both; see :func:`domain_record`).
DOMAIN_FACTOR = 2.0
#: The threshold for weights whose sidecar predates the record. The shipped rows' validation
#: sets reach 4.0 at most (three_circles mass; see the sidecars' ``domain``).
DEFAULT_THRESHOLD = 10.0


def summarize(marked: np.ndarray, frames: int) -> np.ndarray:
    """``(frames · PER_FRAME,)`` float32 features of one marked view ``(T, 2, H, W)`` (channel 1 the
    marked body), ``frames`` of them evenly spaced in time. Coordinates are shares of the frame
    (0..1); a channel with no intensity in a frame (a body out of view) gets mass 0 and centroid
    0.5, the frame's centre."""
    view = np.asarray(marked, dtype=np.float64)[time_indices(marked.shape[0], frames)]
    _, _, h, w = view.shape
    y = (np.arange(h) + 0.5) / h
    x = (np.arange(w) + 0.5) / w
    out = []
    for c, spread in ((1, True), (0, False)):
        img = view[:, c]
        mass = img.sum(axis=(1, 2))
        safe = np.where(mass > 0, mass, 1.0)
        px, py = img.sum(axis=1), img.sum(axis=2)  # (T, W), (T, H) marginals
        cx = np.where(mass > 0, px @ x / safe, 0.5)
        cy = np.where(mass > 0, py @ y / safe, 0.5)
        out += [mass / (h * w), cx, cy]
        if spread:
            sx = np.sqrt(np.maximum(px @ x**2 / safe - cx**2, 0.0))
            sy = np.sqrt(np.maximum(py @ y**2 / safe - cy**2, 0.0))
            out += [np.where(mass > 0, sx, 0.0), np.where(mass > 0, sy, 0.0)]
    return np.stack(out, axis=1).reshape(-1).astype(np.float32)


def distance(feats: np.ndarray, mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    """How far feature rows ``(..., F)`` lie from the training set whose per-feature mean and
    standard deviation are ``mean`` and ``std`` (what the network standardizes with): the mean
    over features of the squared z-score. 1 on average over the training set by construction.
    A 3 px blur widens the marked body's spread, which hardly varies in training (its standard
    deviation is 1e-5 of the frame on three_circles), and takes it to about 8e4."""
    z = (np.asarray(feats, dtype=np.float64) - mean) / std
    return np.mean(np.square(z), axis=-1)


def domain_record(validation: np.ndarray, mean: np.ndarray, std: np.ndarray) -> dict[str, object]:
    """The training-domain record of a weights' sidecar, from the validation set's features:
    the largest and 99th-percentile :func:`distance` there and the threshold
    (:data:`DOMAIN_FACTOR` times the largest). Written by training."""
    d = distance(validation, mean, std)
    top = float(d.max())
    return {
        "statistic": DISTANCE,
        "validation_rows": int(d.size),
        "validation_max": round(top, 4),
        "validation_q99": round(float(np.quantile(d, 0.99)), 4),
        "threshold": round(DOMAIN_FACTOR * top, 4),
    }
