"""The mixture density network: its density is the stated Gaussian mixture, its draws stay in
the unit interval, and the logit map."""

from __future__ import annotations

import math

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from physbench.estimators.npe.network import (  # noqa: E402
    SPREAD,
    MDNConfig,
    build_mdn,
    ensemble_log_prob,
    sample_unit,
    to_logit,
)


def _fixed(cfg: MDNConfig, logits: list[float], means: list[list[float]], tri: list[list[float]]):  # type: ignore[no-untyped-def]
    """A member whose mixture ignores the features: the head's bias alone sets it (``tri``: each
    component's lower-triangular entries, row-major, with the log of the diagonal)."""
    net = build_mdn(cfg)
    with torch.no_grad():
        net.head.weight.zero_()
        net.head.bias.copy_(
            torch.tensor(logits + [v for m in means for v in m] + [v for t in tri for v in t])
        )
    return net.eval()


def test_log_density_is_the_full_covariance_gaussian() -> None:
    from scipy.stats import multivariate_normal

    cfg = MDNConfig(n_features=3, n_params=2, hidden=4, components=1, members=1)
    # L = [[2, 0], [0.5, 1.5]] -> covariance [[4, 1], [1, 2.5]]
    net = _fixed(cfg, [0.0], [[0.3, -1.0]], [[math.log(2.0), 0.5, math.log(1.5)]])
    z = np.array([[0.0, 0.0], [1.5, -2.0], [-3.0, 0.7]])
    got = net.log_prob(torch.zeros(3, 3), torch.tensor(z, dtype=torch.float32))
    want = multivariate_normal([0.3, -1.0], [[4.0, 1.0], [1.0, 2.5]]).logpdf(z)
    np.testing.assert_allclose(got.detach().numpy(), want, rtol=1e-5)


def test_mixture_and_ensemble_weights() -> None:
    from scipy.stats import norm

    cfg = MDNConfig(n_features=2, n_params=1, hidden=4, components=2, members=1)
    # weights 0.25 / 0.75 (logits 0, log 3); N(-1, 1) and N(2, 0.5^2)
    a = _fixed(cfg, [0.0, math.log(3.0)], [[-1.0], [2.0]], [[0.0], [math.log(0.5)]])
    b = _fixed(cfg, [0.0, 0.0], [[0.0], [0.0]], [[0.0], [0.0]])  # N(0, 1)
    z = np.array([[-1.0], [0.4], [2.2]])
    za, feats = torch.tensor(z, dtype=torch.float32), torch.zeros(3, 2)
    pa = 0.25 * norm(-1, 1).pdf(z[:, 0]) + 0.75 * norm(2, 0.5).pdf(z[:, 0])
    np.testing.assert_allclose(a.log_prob(feats, za).detach().numpy(), np.log(pa), rtol=1e-5)
    pe = 0.5 * pa + 0.5 * norm(0, 1).pdf(z[:, 0])
    got = ensemble_log_prob([a, b], feats, za).detach().numpy()
    np.testing.assert_allclose(got, np.log(pe), rtol=1e-5)


def test_draws_follow_the_mixture_and_stay_in_the_unit_interval() -> None:
    cfg = MDNConfig(n_features=2, n_params=2, hidden=4, components=2, members=1)
    # One component far below 0 and one far above 1 in logit space: sigmoid saturates there.
    net = _fixed(cfg, [0.0, 0.0], [[-40.0, 40.0], [1.0, -1.0]], [[3.0, 0.0, 3.0], [-1.0, 0.0, -1]])
    u = sample_unit([net], np.zeros(2, np.float32), 4000, np.random.default_rng(0))
    assert u.shape == (4000, 2) and (u >= 0).all() and (u <= 1).all()
    near = np.abs(to_logit(u) - [1.0, -1.0]).max(axis=1) < 2.0
    assert 0.45 < near.mean() < 0.55  # the second component's share
    # Standardized features: the buffers feed the network.
    assert torch.equal(net.feature_std, torch.ones(2))


def test_logit_is_finite_at_the_bounds() -> None:
    z = to_logit(np.array([0.0, 0.5, 1.0]))
    assert np.isfinite(z).all() and z[1] == 0
    np.testing.assert_allclose(z[[0, 2]], [-13.8155, 13.8155], atol=1e-4)


def test_spread_scales_each_components_width_around_its_mean() -> None:
    cfg = MDNConfig(n_features=2, n_params=1, hidden=4, components=1, members=1)
    net = _fixed(cfg, [0.0], [[0.5]], [[math.log(0.8)]])  # N(0.5, 0.8^2) in logit space
    rng = np.random.default_rng(0)
    for spread in (1.0, SPREAD, 0.5):
        z = to_logit(sample_unit([net], np.zeros(2, np.float32), 20_000, rng, spread=spread))
        assert z.mean() == pytest.approx(0.5, abs=0.02)
        assert z.std() == pytest.approx(0.8 * spread, rel=0.02)
