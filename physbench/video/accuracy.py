"""How well a tracker followed a known motion: centre errors in pixels and identity swaps, against
a camera renderer's projection of the simulated positions. Used by the tracking tests and
``benchmarks/track_accuracy.py``."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from physbench.render.base import Camera
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory


def true_pixels(
    scene: Scene, traj: Trajectory, camera: Camera, body: str, times: np.ndarray
) -> np.ndarray:
    """``(len(times), 2)`` image positions (px) of ``body`` at the trajectory frames of ``times``
    (s), as ``camera`` films ``scene``."""
    i = scene.body_index(body)
    k = np.searchsorted(np.asarray(traj.times), np.asarray(times) - 1e-6)
    return camera.image_points(scene, traj.states[k, i, :2])


def pixel_errors(
    scene: Scene, traj: Trajectory, camera: Camera, pixels: dict[str, np.ndarray]
) -> tuple[np.ndarray, int]:
    """Centre errors (px) over all bodies and tracked frames of ``pixels`` (body -> rows ``(t, u,
    v)``, as in :attr:`~physbench.video.track.TrackResult.pixels`), and the identity swaps: tracked
    samples that lie nearer another body's true position than their own."""
    names = scene.body_names
    truth = {b: true_pixels(scene, traj, camera, b, pixels[b][:, 0]) for b in names}
    errors, swaps = [], 0
    for b in names:
        rows = pixels[b]
        mine = np.hypot(*(rows[:, 1:] - truth[b]).T)
        errors.append(mine)
        for other in names:
            if other != b:
                theirs = true_pixels(scene, traj, camera, other, rows[:, 0])
                swaps += int(np.count_nonzero(np.hypot(*(rows[:, 1:] - theirs).T) < mine))
    return np.concatenate(errors), swaps
