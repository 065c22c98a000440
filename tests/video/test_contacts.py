"""Collision samples of a free body's track: found where they are, nowhere else."""

from __future__ import annotations

import numpy as np

from physbench.video.contacts import contact_samples

G = np.array([0.0, -9.81])


def _bouncing(fps: float, seconds: float, e: float = 0.8) -> tuple[np.ndarray, np.ndarray, list]:
    """A ball dropped from 1 m bouncing on y = 0, sampled at ``fps``, and its bounce times."""
    t = np.arange(0.0, seconds, 1 / fps)
    y, bounces = np.empty_like(t), []
    t0, v0, y0 = 0.0, 0.0, 1.0
    for k, tk in enumerate(t):
        while True:
            dt = tk - t0
            yk = y0 + v0 * dt - 4.905 * dt * dt
            if yk >= 0:
                break
            hit = t0 + (v0 + np.sqrt(v0 * v0 + 2 * 9.81 * y0)) / 9.81
            v_in = v0 - 9.81 * (hit - t0)
            t0, v0, y0 = hit, -e * v_in, 0.0
            bounces.append(hit)
        y[k] = yk
    return t, np.column_stack([0.3 * t, y]), bounces


def test_one_sample_per_bounce_the_nearest_and_none_in_flight() -> None:
    rng = np.random.default_rng(0)
    t, xy, bounces = _bouncing(30.0, 2.0)
    noisy = xy + rng.normal(0, 0.001, xy.shape)
    mask = contact_samples(t, noisy, G, 0.002)
    assert len(bounces) >= 3
    marked = t[mask]
    assert len(marked) == len(bounces)
    for hit, when in zip(bounces, marked, strict=True):
        assert abs(when - hit) <= 1 / 30 + 1e-9  # a neighbour of the collision
    assert not contact_samples(t[:10], noisy[:10], G, 0.002).any()  # before the first bounce


def test_free_flight_and_noise_at_a_high_frame_rate_mark_nothing() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 1.0, 1 / 240)
    xy = np.column_stack([2.0 * t, 3.0 * t - 4.905 * t * t])
    noisy = xy + rng.normal(0, 0.002, xy.shape)  # 2 mm at 240 fps: ~ 280 m/s² of noise
    assert not contact_samples(t, noisy, G, 0.002).any()
    assert not contact_samples(t[:2], xy[:2], G, 0.002).any()  # too short to tell


def test_without_gravity_a_puck_hitting_a_wall_is_marked() -> None:
    t = np.arange(0.0, 1.0, 1 / 30)
    x = np.where(t < 0.5, 1.0 * t, 0.5 - 0.9 * (t - 0.5))  # hits a wall at x = 0.5, t = 0.5
    mask = contact_samples(t, np.column_stack([x, 0.2 + 0 * t]), np.zeros(2), 0.001)
    assert np.flatnonzero(mask).tolist() == [15]


def _corner(t: np.ndarray, floor: float, wall: float) -> np.ndarray:
    """A ball falling at 3.6 m/s onto the floor at ``floor`` s (restitution 0.8) while moving at
    2.3 m/s into a wall it hits at ``wall`` s (restitution 0.9)."""
    x = np.where(t < wall, 1.8 + 2.3 * (t - wall), 1.8 - 0.9 * 2.3 * (t - wall))
    after = t >= floor
    vy = np.where(after, 0.8 * 3.6, -3.6)
    y = 0.1 + vy * (t - floor) - 4.905 * (t - floor) ** 2
    return np.column_stack([x, y])


def test_a_bounce_into_a_corner_marks_the_floor_and_the_wall() -> None:
    # The floor at 0.475 s and the wall 1.75 frame intervals later, at 25 fps: each frame is the
    # mean pose over an exposure of 0.55 of the interval, as a camera records it, so the frames
    # exposed across either bounce are off too. Their departures make one run, and each bounce
    # is a sample within an interval of it.
    fps, floor, wall = 25.0, 0.475, 0.545
    t = np.arange(0.0, 1.0, 1 / fps)
    exposure = np.linspace(0.0, 0.55 / fps, 12)
    xy = np.mean([_corner(t + s, floor, wall) for s in exposure], axis=0)
    for seed in range(5):
        noisy = xy + np.random.default_rng(seed).normal(0, 0.001, xy.shape)
        marked = t[contact_samples(t, noisy, G, 0.002)]
        assert len(marked) == 2
        assert abs(marked[0] - floor) <= 1 / fps and abs(marked[1] - wall) <= 1 / fps
