"""``physbench/codec.py``: H.264 coding is the same on every machine (its encoder threads are
fixed, :data:`~physbench.codec.ENCODER_THREADS`) and on every call (x264's macroblock tree is
off, :data:`~physbench.codec.X264_PARAMS`), so a clip filmed for a test or a committed result
depends neither on the cores of the machine that filmed it nor on what it filmed before."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys

import pytest

pytest.importorskip("av")

#: Codes frames with both encoders and prints their digests; run here and in a child on one core.
CODE = """
import hashlib, os, sys
import numpy as np
from physbench.codec import h264_round_trip
from physbench.video.writer import write_video

if len(sys.argv) > 2:
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
rng = np.random.default_rng(7)
frames = np.clip(rng.normal(128, 40, (12, 240, 320, 3)), 0, 255).astype(np.uint8)
frames[:, 80:160, 100:200] = 230  # a bright patch: coded edges, where threads made a difference
coded = h264_round_trip(frames, 30.0, 0, 23)
path = sys.argv[1]
write_video(path, list(frames), fps=30.0, crf=23)
print(hashlib.md5(coded.tobytes()).hexdigest(), hashlib.md5(open(path, "rb").read()).hexdigest())
"""


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="needs CPU affinity (Linux)")
def test_a_clip_is_coded_the_same_on_one_core_as_on_all(tmp_path) -> None:  # type: ignore[no-untyped-def]
    def digests(*extra: str) -> list[str]:
        out = subprocess.run(
            [sys.executable, "-c", CODE, str(tmp_path / f"clip{len(extra)}.mp4"), *extra],
            check=True,
            capture_output=True,
            text=True,
        )
        return out.stdout.split()

    all_cores, one_core = digests(), digests("one core")
    assert len(all_cores) == 2
    assert one_core == all_cores
    # Both files hold the same bytes, not just the same frames.
    one, two = (hashlib.md5((tmp_path / f"clip{k}.mp4").read_bytes()).hexdigest() for k in (0, 1))
    assert one == two


def test_a_clip_written_again_in_the_same_process_is_the_same_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # A lit bob on a textured wall, from the second camera: with x264's macroblock tree on, five
    # writes of these frames in one process gave five different files.
    from dataclasses import replace

    import numpy as np

    from physbench.codec import even
    from physbench.components import create
    from physbench.discover.synthetic import pendulum
    from physbench.testing.field_camera import FieldCamera
    from physbench.video.footage import motion_view
    from physbench.video.writer import write_video

    scene = replace(pendulum(np.random.default_rng(2), (0.9, 1.3)), frames=12)
    traj = create("simulator", "pymunk").simulate(scene)
    still = {"drift": 0.0, "oblique": 0.0, "k1": 0.0, "k2": 0.0}
    camera = FieldCamera(320, seed=2, view=motion_view(scene, traj), shutter=0.7, **still)
    frames = list(even(camera.exposure(scene, traj)))
    files = set()
    for k in range(5):
        path = write_video(tmp_path / f"bob{k}.mp4", frames, fps=scene.fps, crf=camera.crf)
        files.add(hashlib.md5(path.read_bytes()).hexdigest())
    assert len(files) == 1
