"""Measuring a decaying oscillation, on synthetic signals with known centre, period and decay."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from physbench.datasets.oscillation import (
    LOSS_LAWS,
    fit_loss_laws,
    half_swing_amplitudes,
    oscillation_centre,
    oscillation_periods,
    swing_peaks,
)


def decaying(centre: float, period: float, a0: float, loss_per_period: float, periods: float = 10):
    """``centre + A(t) cos(2π t / period)`` with an amplitude that shrinks linearly."""
    t = np.arange(0.0, periods * period, period / 200)
    amp = a0 - loss_per_period * t / period
    return t, centre + amp * np.cos(2 * np.pi * t / period)


def from_extremes(extremes: list[float], samples: int = 100) -> np.ndarray:
    """A signal that swings through ``extremes`` in turn, half a cosine between each two."""
    s = np.arange(samples) / samples
    parts = [
        0.5 * (a + b) + 0.5 * (a - b) * np.cos(np.pi * s) for a, b in itertools.pairwise(extremes)
    ]
    return np.concatenate([*parts, [extremes[-1]]])


def test_centre_cancels_a_linear_decay_that_biases_the_mean():
    t, a = decaying(0.3, 1.0, 1.0, 0.08, periods=9.25)
    assert abs(np.mean(a) - 0.3) > 0.004  # the plain average is off by about the decay
    assert oscillation_centre(t, a) == pytest.approx(0.3, abs=1e-9)


def test_periods_and_peaks_of_a_known_swing():
    t, a = decaying(-0.2, 0.8, 1.0, 0.05)
    periods = oscillation_periods(t, a)
    assert len(periods) == 9
    np.testing.assert_allclose(periods, 0.8, atol=2e-3)
    times, amp = swing_peaks(t, a)
    np.testing.assert_allclose(np.diff(times), 0.4, atol=5e-3)  # one extreme per half swing
    np.testing.assert_allclose(amp, 1.0 - 0.05 * times / 0.8, atol=1e-3)


def test_half_swing_amplitudes_are_free_of_the_rest_value():
    amps = [1.0, 0.9, 0.8, 0.7, 0.6]
    extremes = [0.25 + (-1) ** k * a for k, a in enumerate(amps)]  # about 0.25, not 0
    x = from_extremes([0.25, *extremes, 0.25])  # from rest and back: the ends are no extremes
    expected = [0.5 * (a + b) for a, b in itertools.pairwise(amps)]
    np.testing.assert_allclose(half_swing_amplitudes(x, distance=50), expected, atol=1e-12)


def test_loss_law_fits_name_coulomb_and_viscous_decay():
    coulomb = fit_loss_laws(1.0 - 0.03 * np.arange(20))  # the same loss every half swing
    assert set(coulomb) == set(LOSS_LAWS)
    assert coulomb["coulomb"].coef == pytest.approx([0.03])
    assert coulomb["coulomb"].rms < 1e-12 and coulomb["viscous"].rms > 1e-3
    b, a = coulomb["viscous + coulomb"].coef
    assert b == pytest.approx(0.03) and a == pytest.approx(0.0, abs=1e-12)

    q = 0.9  # each amplitude 90 % of the last: the loss is 2 (1 - q) / (1 + q) of the mean one
    viscous = fit_loss_laws(1.5 * q ** np.arange(20))
    assert viscous["viscous"].coef == pytest.approx([2 * (1 - q) / (1 + q)])
    assert viscous["viscous"].rms < 1e-12 and viscous["coulomb"].rms > 1e-3
