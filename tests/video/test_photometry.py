"""The light of a frame against the background: a gain and an offset per channel, measured
robustly away from the bodies, and the difference taken in that light."""

from __future__ import annotations

import numpy as np

from physbench.video.photometry import LightMeter
from physbench.video.spheres import expose, wall


def test_gain_and_offset_are_measured_through_foreground_the_meter_did_not_expect() -> None:
    rng = np.random.default_rng(1)
    plate = wall((240, 320), 4)
    background = expose(plate.astype(np.float64), rng, noise=0.0)
    light = plate * np.array([1.08, 1.05, 0.97]) + 0.02
    light[60:180, 100:220] = (0.9, 0.7, 0.6)  # a hand a sixth of the view, not a body
    frame = expose(light, rng, noise=0.01)
    got = LightMeter(background).measure(frame, [(40.0, 40.0, 20.0)])
    gain, offset = np.array([1.08, 1.05, 0.97]), 0.02 * 255
    np.testing.assert_allclose(got.gain, gain, atol=0.02)
    # The wall's levels in this frame's light, within 2 grey levels (the foreground threshold is
    # 12 at least).
    for level in (80.0, 120.0, 160.0):
        np.testing.assert_allclose(got.gain * level + got.offset, gain * level + offset, atol=2.0)
    assert abs(got.change - 0.073) < 0.01  # the mean gain less 1, and the offset of mid-grey
    # Noise of 2.5 grey levels per channel: 6 robust standard deviations of the largest channel
    # difference, as before the light was measured.
    assert 20 < got.threshold() < 40
    # In the frame's light the wall differs from the background by noise only, the hand by a lot.
    diff = got.difference(frame, background)
    assert np.median(diff[:40]) <= 4 and np.median(diff[80:160, 120:200]) > 60


def test_a_plain_wall_gives_a_gain_alone() -> None:
    # On a uniform wall an offset cannot be told from a gain: it stays 0.
    background = np.full((120, 160, 3), 100, np.uint8)
    frame = np.full((120, 160, 3), 110, np.uint8)
    got = LightMeter(background).measure(frame)
    np.testing.assert_allclose(got.gain, 1.1, atol=1e-6)
    np.testing.assert_allclose(got.offset, 0.0)
    assert got.difference(frame, background).max() == 0
