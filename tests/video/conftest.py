"""Camera footage of real simulations, shared by the tracking tests."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from physbench.plugins import create
from physbench.render.camera import CameraRenderer
from physbench.scene import Scene
from physbench.trajectory import Trajectory

#: A realistic camera: motion blur, sensor noise, uneven flickering light, lossy H.264.
REAL = {"shutter": 0.5, "subframes": 8, "noise": 0.02, "bitrate": 1_500_000}


@dataclass
class Clip:
    path: Path
    scene: Scene
    traj: Trajectory
    camera: CameraRenderer

    def truth(self, body: str, times: np.ndarray) -> np.ndarray:
        """True image positions (px) of ``body`` at frame ``times`` (s)."""
        i = self.scene.body_index(body)
        k = np.searchsorted(np.asarray(self.traj.times), np.asarray(times) - 1e-6)
        return self.camera.image_points(self.scene, self.traj.states[k, i, :2])


def pixel_errors(clip: Clip, pixels: dict[str, np.ndarray]) -> tuple[np.ndarray, int]:
    """Centre errors (px) over all bodies and frames, and the identity swaps: frames where a
    tracked body lies nearer another body's true position than its own."""
    errors, swaps = [], 0
    names = clip.scene.body_names
    all_truth = {b: clip.truth(b, pixels[b][:, 0]) for b in names}
    for b in names:
        rows = pixels[b]
        errors.append(np.hypot(*(rows[:, 1:] - all_truth[b]).T))
        for k, (t, u, v) in enumerate(rows):
            mine = np.hypot(u - all_truth[b][k, 0], v - all_truth[b][k, 1])
            for other in names:
                if other != b:
                    o = clip.truth(other, np.array([t]))[0]
                    swaps += bool(np.hypot(u - o[0], v - o[1]) < mine)
    return np.concatenate(errors), swaps


@pytest.fixture
def film(tmp_path: Path) -> Callable[..., Clip]:
    """``film(scene, engine="pymunk", name="clip.mp4", **camera options)``: simulate ``scene`` and
    film it at 640x480 with :data:`REAL` (options override) into ``tmp_path / name``."""

    def make(scene: Scene, engine: str = "pymunk", name: str = "clip.mp4", **opts: object) -> Clip:
        traj = create("simulator", engine).simulate(scene)
        camera = CameraRenderer(640, **{**REAL, **opts})  # type: ignore[arg-type]
        path = tmp_path / name
        camera.write(path, scene, traj)
        return Clip(path, scene, traj, camera)

    return make
