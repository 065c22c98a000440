"""The accuracy a track states: its floor, or twice the noise its fifth differences measure."""

from __future__ import annotations

import numpy as np

from physbench.video.accuracy import (
    ACCURACY_PX,
    ANGLE_ACCURACY_PX,
    DISC_ACCURACY_PX,
    stated_accuracy,
    stated_angle_accuracy,
    track_noise,
)


def test_a_tracks_noise_is_measured_and_its_smooth_motion_is_not() -> None:
    rng = np.random.default_rng(0)
    t = np.arange(80) / 20.0  # a swing at 20 frames/s: its third differences are most of a pixel
    swing = np.column_stack([t, 320 + 90 * np.sin(2 * np.pi * t / 1.5), 240 + 30 * np.cos(t)])
    assert track_noise(swing) < 0.02
    noisy = swing.copy()
    noisy[:, 1:] += rng.normal(0.0, 0.3, (80, 2))
    assert abs(track_noise(noisy) / 0.3 - 1) < 0.25
    # A gap breaks the runs of evenly spaced samples, not the estimate.
    assert abs(track_noise(np.delete(noisy, [30, 31, 50], axis=0)) / 0.3 - 1) < 0.25
    assert np.isnan(track_noise(noisy[:6]))
    assert stated_accuracy(swing, disc=True) == DISC_ACCURACY_PX
    assert stated_accuracy(swing, disc=False) == ACCURACY_PX
    assert abs(stated_accuracy(noisy, disc=True) / 0.6 - 1) < 0.25  # twice the noise


def test_an_angle_states_its_floor_at_the_far_end_or_twice_its_noise() -> None:
    rng = np.random.default_rng(1)
    t = np.arange(80) / 20.0
    swing = 0.8 * np.sin(2 * np.pi * t / 1.5)
    # an arm reaching 100 px from its centre: a quarter pixel there is 2.5 mrad
    assert stated_angle_accuracy(t, swing, 100.0) == ANGLE_ACCURACY_PX / 100.0
    noisy = swing + rng.normal(0.0, 0.01, 80)
    assert abs(stated_angle_accuracy(t, noisy, 100.0) / 0.02 - 1) < 0.25
    assert stated_angle_accuracy(t[:6], swing[:6], 50.0) == ANGLE_ACCURACY_PX / 50.0
