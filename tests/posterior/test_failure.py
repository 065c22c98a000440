"""Failed fits: the noise floor of clipped pixel noise, the two ratios and when they flag, the
shipped references and their lookup, and a run that carries them."""

from __future__ import annotations

import numpy as np
import pytest

from physbench.posterior import failure
from physbench.posterior.failure import FitCheck, noise_floor

TABLE1 = {
    "engine": "pymunk",
    "observe_engine": "pymunk",
    "renderer": "raster",
    "renderer_options": {},
    "resolution": 64,
    "render_mode": "mark",
    "blur": 0.0,
    "noise": 0.0,
}


def test_the_noise_floor_is_the_clipped_noises_own_mse() -> None:
    rng = np.random.default_rng(0)
    mu = rng.choice([0.0, 0.0, 0.0, 0.3, 0.97, 1.0], size=(4, 2, 32, 32))
    sigma = 0.1
    draws = [
        np.mean((np.clip(mu + sigma * rng.standard_normal(mu.shape), 0, 1) - mu) ** 2)
        for _ in range(50)
    ]
    assert noise_floor(mu, sigma) == pytest.approx(np.mean(draws), rel=0.01)
    # An empty frame keeps only the upper half of the noise: sigma^2 / 2.
    assert noise_floor(np.zeros((2, 8, 8)), sigma) == pytest.approx(sigma**2 / 2, rel=1e-6)


def test_each_ratio_flags_above_its_factor_and_says_why() -> None:
    ok = FitCheck(1e-4, noise_floor=5e-5, reference=1e-4, reference_seeds=200)
    assert not ok.failed and ok.describe() is None
    assert ok.noise_ratio == pytest.approx(2) and ok.scene_ratio == pytest.approx(1)
    noisy = FitCheck(1e-3, noise_floor=5e-5)
    assert noisy.failed and "20 times the pixel noise's own" in (noisy.describe() or "")
    far = FitCheck(5e-3, reference=1e-4, reference_seeds=200)
    text = far.describe() or ""
    assert far.failed and text.startswith("the fit looks failed: its best image MSE 0.005 is 50")
    assert "on 200 other seeds of the scene" in text
    assert FitCheck.from_dict(far.to_dict()) == far
    assert not FitCheck(1.0).failed  # neither measure known: no claim


def test_the_shipped_references_are_found_for_their_row_budget_and_setting_only() -> None:
    ref = failure.reference("resnet3d", "three_circles", ("mass",), 11, TABLE1)
    assert ref is not None and ref.seeds >= 200 and ref.median > 0
    both = failure.reference("resnet3d", "three_circles", ("elasticity", "mass"), 11, TABLE1)
    assert both is not None and both.unknowns == ("mass", "elasticity")
    assert failure.reference("resnet3d", "three_circles", ("mass",), 2, TABLE1) is None
    assert (
        failure.reference("resnet3d", "three_circles", ("mass",), 11, TABLE1 | {"blur": 3.0})
        is None
    )
    assert failure.reference("tpe", "three_circles", ("mass",), 11, TABLE1) is None


def test_a_resnet3d_run_is_judged_against_its_rows_reference() -> None:
    pytest.importorskip("torch")
    from physbench.experiment import RunConfig, run_config

    h = run_config(RunConfig(estimator="resnet3d", seed=0), probe=False)
    assert h.fit is not None and h.fit.reference_seeds >= 200
    assert h.fit.scene_ratio == pytest.approx(h.min_loss / h.fit.reference)
    assert not h.fit.failed and h.fit.noise_floor is None  # a noise-free observation
    other = run_config(RunConfig(estimator="resnet3d", seed=0, blur=3.0), probe=False)
    assert other.fit is not None and other.fit.reference is None
