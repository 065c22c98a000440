"""The painted spheres' sensor (physbench/video/spheres.py): what ``expose`` records."""

from __future__ import annotations

import numpy as np

from physbench.video.spheres import expose


def test_expose_encodes_light_by_a_camera_transfer_or_keeps_it_linear() -> None:
    light = np.array([0.0, 0.1, 0.5, 1.0, 1.4]).reshape(1, 5, 1) * np.ones((1, 1, 3))
    rng = np.random.default_rng(0)
    linear = expose(light, rng, noise=0.0)
    encoded = expose(light, rng, noise=0.0, gamma=2.2)
    assert linear[0, :, 0].tolist() == [0, 26, 128, 255, 255]  # clipped at full scale
    # 0.1 ** (1 / 2.2) = 0.351, 0.5 ** (1 / 2.2) = 0.730: a camera lifts the dark levels.
    assert encoded[0, :, 0].tolist() == [0, 90, 186, 255, 255]
    assert linear.dtype == encoded.dtype == np.uint8
