"""How accurate a track is: what the tracker states from its own measurements
(:func:`stated_accuracy`, from a track's noise), and, where the motion is known, its centre
errors in pixels and identity swaps against a camera renderer's projection of the simulated
positions (used by the tracking tests and ``benchmarks/track_accuracy.py``)."""

from __future__ import annotations

import math
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


#: The systematic accuracy (px) of a disc's centre fitted to its outline: what shading, a
#: highlight, lossy coding and motion blur leave in it (``benchmarks/track_shading.py``,
#: ``results/track/shading.json``: the 95th percentile over three walls is 0.17-0.18 px at 13-22
#: px radius, 0.14 px in raw frames and 0.22 px in H.264-coded ones; with the light encoded as
#: a camera encodes it, ``shading_gamma22.json``, 0.19-0.22 px: raw 0.10, coded 0.24).
DISC_ACCURACY_PX = 0.25
#: ... of other bodies' centroids: the arc a turning body sweeps in one exposure (a swinging arm
#: 0.4-0.5 px RMS along its length; ``tests/video/test_track.py``).
ACCURACY_PX = 0.5
#: A track's stated accuracy is at least this many times its measured noise.
NOISE_K = 2.0
#: The floor of a turning body's stated angle accuracy: this many pixels across at its far end
#: (its extent from the centre). On five single field-camera arms the angle's 95th-percentile
#: error was 0.8-4.2 mrad, under this floor (2.6-5.7 mrad) on each; part of it is systematic (on
#: a large swing, 0.1 % of the angle), which the noise alone does not show. Not on a double
#: pendulum's upper arm, joined to the lower at the elbow: 22.6 mrad, above both its floor and
#: twice its noise (14 mrad).
ANGLE_ACCURACY_PX = 0.25


def stated_accuracy(tuv: np.ndarray, *, disc: bool) -> float:
    """The accuracy (px) the tracker states for an image track ``(t, u, v)``: its floor
    (:data:`DISC_ACCURACY_PX` for a disc, :data:`ACCURACY_PX` otherwise), or :data:`NOISE_K`
    times its measured noise (:func:`track_noise`) where that is larger."""
    floor = DISC_ACCURACY_PX if disc else ACCURACY_PX
    noise = track_noise(tuv)
    return max(floor, NOISE_K * noise) if math.isfinite(noise) else floor


def stated_angle_accuracy(t: np.ndarray, angle: np.ndarray, extent_px: float) -> float:
    """The accuracy (rad) the tracker states for a body's angles ``angle`` at times ``t``:
    :data:`ANGLE_ACCURACY_PX` over the body's extent ``extent_px`` (px from its centre to its
    far end), or :data:`NOISE_K` times the angles' measured noise where that is larger."""
    floor = ANGLE_ACCURACY_PX / max(extent_px, 1.0)
    noise = track_noise(np.column_stack([t, angle]))
    return max(floor, NOISE_K * noise) if math.isfinite(noise) else floor


def track_noise(tuv: np.ndarray) -> float:
    """The noise (px, a robust standard deviation per coordinate) of an image track ``(t, u,
    v)``, or of any coordinates after ``t`` (an angle's: rad), from the fifth differences of runs
    of six evenly spaced samples: a smooth motion's are near zero (a swinging arm's at 20
    frames/s: a few hundredths of a pixel, where its third differences are most of one),
    noise's have a variance 252 times its own. NaN with fewer than three such runs."""
    order = 5
    if len(tuv) < order + 3:
        return math.nan
    t, uv = tuv[:, 0], tuv[:, 1:]
    dt = np.diff(t)
    step = float(np.median(dt))
    even = np.abs(dt - step) <= 0.25 * step
    run = np.ones(len(dt) - order + 1, dtype=bool)
    for k in range(order):
        run &= even[k : len(even) - order + 1 + k]
    d5 = np.diff(uv, n=order, axis=0)[run]
    if len(d5) < 3:
        return math.nan
    return 1.4826 * float(np.median(np.abs(d5))) / math.sqrt(252.0)
