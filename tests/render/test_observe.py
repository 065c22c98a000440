"""The image filters of the observation model: Gaussian blur and pixel noise."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.render.observe import add_noise, gaussian_blur


def test_blur_acts_on_image_axes_only() -> None:
    frames = np.zeros((3, 2, 16, 16), np.float32)
    frames[1, 0, 8, 8] = 1.0
    out = gaussian_blur(frames, 1.0)
    assert not out[0].any() and not out[2].any() and not out[1, 1].any()
    assert out[1, 0].sum() == pytest.approx(1.0, rel=1e-5)


def test_noise_is_clipped_float32_and_seeded() -> None:
    clean = np.full((2, 1, 8, 8), 0.5, np.float32)
    a = add_noise(clean, 0.1, np.random.default_rng(3))
    b = add_noise(clean, 0.1, np.random.default_rng(3))
    assert a.dtype == np.float32 and a.shape == clean.shape and 0 <= a.min() <= a.max() <= 1
    np.testing.assert_array_equal(a, b)
    assert 0.005 < float(((a - clean) ** 2).mean()) < 0.02
    assert np.array_equal(add_noise(clean, 0.0, np.random.default_rng(3)), clean)


@pytest.mark.parametrize(
    "fn", [lambda f: gaussian_blur(f, -1.0), lambda f: add_noise(f, -1.0, None)]
)
def test_negative_sigma_is_refused(fn) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match="expected a number >= 0"):
        fn(np.zeros((1, 1, 4, 4), np.float32))
