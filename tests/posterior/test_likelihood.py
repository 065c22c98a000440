"""The clipped-Gaussian pixel likelihood and the noise estimate."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

from physbench.errors import PhysbenchError
from physbench.posterior.likelihood import NOISE_FLOOR, PixelLikelihood, estimate_noise
from physbench.render.sensor import add_noise


def test_matches_a_direct_censored_gaussian_sum() -> None:
    rng = np.random.default_rng(0)
    truth = np.zeros((3, 2, 8, 8), np.float32)
    truth[:, 0, 2:5, 2:5] = 1.0
    truth[:, 1, 4, 4] = 0.5
    obs = add_noise(truth, 0.2, rng)
    mu = np.clip(truth + 0.05, 0, 1)
    o, m = obs.astype(float).ravel(), mu.astype(float).ravel()
    direct = np.where(
        o <= 0,
        norm.logcdf(-m / 0.2),
        np.where(o >= 1, norm.logcdf((m - 1) / 0.2), norm.logpdf(o, m, 0.2)),
    ).sum()
    assert PixelLikelihood(obs, 0.2)(mu) == pytest.approx(direct, rel=1e-5)


def test_the_truth_is_more_likely_than_a_shifted_frame() -> None:
    rng = np.random.default_rng(1)
    truth = np.zeros((4, 1, 16, 16), np.float32)
    truth[:, 0, 5:9, 5:9] = 1.0
    obs = add_noise(truth, 0.1, rng)
    like = PixelLikelihood(obs, 0.1)
    assert like(truth) > like(np.roll(truth, 1, axis=-1)) + 10


def test_noise_estimate_recovers_the_clipped_noise_level() -> None:
    rng = np.random.default_rng(2)
    truth = np.zeros((10, 2, 32, 32), np.float32)
    truth[:, 0, 10:14, 10:14] = 1.0
    for sigma in (0.03, 0.1):
        assert estimate_noise(add_noise(truth, sigma, rng)) == pytest.approx(sigma, rel=0.1)
    assert estimate_noise(truth) == NOISE_FLOOR


@pytest.mark.parametrize("sigma", [0, -1, 2, float("nan"), True])
def test_bad_sigma_is_refused(sigma: object) -> None:
    with pytest.raises(PhysbenchError, match="pixel noise"):
        PixelLikelihood(np.zeros((1, 1, 2, 2), np.float32), sigma)  # type: ignore[arg-type]


def test_frames_of_another_shape_are_refused() -> None:
    like = PixelLikelihood(np.zeros((1, 1, 2, 2), np.float32), 0.1)
    with pytest.raises(PhysbenchError, match="expected the observation's"):
        like(np.zeros((1, 1, 3, 2), np.float32))
