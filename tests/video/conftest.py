"""Camera footage of real simulations, shared by the tracking tests."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from physbench.calibration import Calibration
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


@dataclass
class StillDisc:
    """A still dark disc on a lighter wall, 128x96 px at 10 fps for 2 s: its scene, calibration
    and plate, and :meth:`clip` to write it as a video."""

    scene: Scene
    calibration: Calibration
    plate: np.ndarray

    def clip(self, path: Path, *, trc: int | None = None, interlaced: bool = False) -> Path:
        """The clip, H.264 written with PyAV: its stream tagged with transfer characteristics
        ``trc`` (physbench's writer tags only the curves it reads), or coded ``interlaced`` (top
        field first)."""
        import av

        frame = self.plate.copy()
        vv, uu = np.mgrid[0:96, 0:128]
        frame[(uu - 64) ** 2 + (vv - 48) ** 2 <= 8**2] = 60
        with av.open(str(path), "w") as container:
            stream = container.add_stream("libx264", rate=10)
            stream.width, stream.height, stream.pix_fmt = 128, 96, "yuv420p"
            if trc is not None:
                stream.codec_context.color_trc = trc
            if interlaced:
                stream.options = {"x264-params": "tff=1"}
            for i in range(20):
                f = av.VideoFrame.from_ndarray(frame, format="rgb24")
                f.pts = i
                container.mux(stream.encode(f))
            container.mux(stream.encode(None))
        return path


@pytest.fixture
def still_disc() -> StillDisc:
    """:class:`StillDisc`."""
    from physbench.scene import Body, Circle

    cal = Calibration.from_scale(0.01, (0.0, 95.0))
    ball = Body("ball", Circle(0.08), tuple(cal.to_scene((64.0, 48.0))))
    scene = Scene("s", (ball,), bounds=(0.0, 0.0, 1.28, 0.96), gravity=(0.0, 0.0), fps=10.0)
    return StillDisc(scene.validate(), cal, np.full((96, 128, 3), 180, np.uint8))
