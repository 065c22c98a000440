"""Camera footage of real simulations, shared by the tracking tests."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from physbench.components import create
from physbench.render.camera import CameraRenderer
from physbench.scene import Scene
from physbench.trajectory import Trajectory
from physbench.video.accuracy import pixel_errors
from physbench.video.writer import write_clip

#: A realistic camera: motion blur, sensor noise, uneven flickering light, lossy H.264.
REAL = {"shutter": 0.5, "subframes": 8, "noise": 0.02, "bitrate": 1_500_000}


@dataclass
class Clip:
    path: Path
    scene: Scene
    traj: Trajectory
    camera: CameraRenderer

    def errors(self, pixels: dict[str, np.ndarray]) -> tuple[np.ndarray, int]:
        """Centre errors (px) and identity swaps of tracked ``pixels`` against this clip's truth."""
        return pixel_errors(self.scene, self.traj, self.camera, pixels)


@pytest.fixture
def film(tmp_path: Path) -> Callable[..., Clip]:
    """``film(scene, engine="pymunk", name="clip.mp4", **camera options)``: simulate ``scene`` and
    film it at 640x480 with :data:`REAL` (options override) into ``tmp_path / name``."""

    def make(scene: Scene, engine: str = "pymunk", name: str = "clip.mp4", **opts: object) -> Clip:
        traj = create("simulator", engine).simulate(scene)
        camera = CameraRenderer(640, **{**REAL, **opts})  # type: ignore[arg-type]
        path = tmp_path / name
        write_clip(camera, path, scene, traj)
        return Clip(path, scene, traj, camera)

    return make
