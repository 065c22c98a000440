"""Samples whose exposure spans a collision: left out of a free body's video track.

A frame exposed while a ball bounces averages two motions into one blurred V, whose centre is
neither pose; fitted as a position, it pulls the restitution and every extrapolation after it (a
filmed bouncing ball without any hidden effect was fitted 4x better on held-out frames with an
invented velocity-dependent restitution until its four contact frames were left out). Such a
sample is where the track's acceleration departs from what the scene explains (gravity, and the
forces the scene applies) by more than free flight and tracking noise allow: a collision changes
the velocity within one frame interval.
"""

from __future__ import annotations

import math

import numpy as np

#: A departure from gravity larger than this many g is a collision, whatever the noise.
COLLISION_G = 3.0
#: ... and larger than this many standard deviations of the second difference of the noise.
COLLISION_SIGMA = 6.0


def contact_samples(
    t: np.ndarray,
    xy: np.ndarray,
    gravity: np.ndarray,
    accuracy: float,
    expected: np.ndarray | None = None,
) -> np.ndarray:
    """Called by the tracker on each free body's track when it writes the recording: a mask of
    the samples ``(t, xy)`` (s, m) at a collision, given the scene's ``gravity`` (m/s², a
    vector), the sensor's ``accuracy`` (m) and the accelerations the scene explains at each
    inner sample (``expected``, ``(n - 2, 2)`` m/s²: gravity and the scene's forces; default
    gravity alone). One sample per collision, the one nearest it (the largest departure among its
    neighbours); the first and last samples are never marked. A collision moves the departures of
    the two samples around it, so a run of departures over the limit whose samples lie two or more
    apart holds more than one: a ball into a corner hits the floor and then the wall a frame or
    two later (on the field camera, a bounce at 0.475 s and one at 0.574 s made one run of four
    departures, 108, 67, 62 and 41 m/s² over a limit of 29, and the frame exposed across the
    second, 2.35 px off, was kept). In a run that holds a peak, each further sample over the
    limit and not next to one marked is marked too, the largest first."""
    n = len(t)
    mask = np.zeros(n, dtype=bool)
    if n < 3:
        return mask
    dt = np.diff(t)
    v = np.diff(xy, axis=0) / dt[:, None]
    a = 2 * np.diff(v, axis=0) / (dt[1:] + dt[:-1])[:, None]
    known = np.asarray(gravity, dtype=float) if expected is None else expected
    excess = np.hypot(*(a - known).T)
    noise = accuracy * math.sqrt(6.0) / (dt[1:] * dt[:-1])
    limit = np.maximum(COLLISION_G * float(np.hypot(*gravity)), COLLISION_SIGMA * noise)
    over = excess > limit
    padded = np.concatenate([[0.0], excess, [0.0]])
    peak = (padded[1:-1] >= padded[:-2]) & (padded[1:-1] >= padded[2:])
    marked = over & peak
    # Runs of departures over the limit, numbered; a further collision only in a run that holds
    # one (with gaps in a track the limits differ from sample to sample, and a sample over its
    # own limit beside a larger departure under a larger one is no collision of its own).
    run = np.cumsum(np.diff(np.concatenate([[False], over]).astype(int)) == 1)
    held = set(run[marked].tolist())
    for k in np.argsort(-excess, kind="stable"):
        if over[k] and run[k] in held and not marked[max(k - 1, 0) : k + 2].any():
            marked[k] = True
    mask[1:-1] = marked
    return mask
