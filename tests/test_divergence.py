"""Gaussian divergences: exact forms against numerical integration, printed forms as printed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy import integrate
from scipy.stats import multivariate_normal, norm

from assocopt.tracking.costs.kld import (kld_exact, kld_gauss, kld_printed, skld_exact,
                                       skld_gauss, skld_printed)


def _kl_numeric(mu0, s0, mu1, s1):
    """KL(N(mu0, s0^2) || N(mu1, s1^2)) by quadrature of p log(p/q)."""
    f = lambda x: norm.pdf(x, mu0, s0) * (norm.logpdf(x, mu0, s0) - norm.logpdf(x, mu1, s1))
    lo, hi = mu0 - 40 * s0, mu0 + 40 * s0
    return integrate.quad(f, lo, hi, limit=400, epsabs=1e-13, epsrel=1e-11)[0]


@pytest.mark.parametrize("mu_t,s_t,mu,s", [
    (0.0, 1.0, 0.0, 1.0), (1.0, 1.0, 0.0, 2.0), (0.3, 0.5, -0.2, 1.5),
    (2e-3, 1.0e-3, 0.0, 1.5e-3),            # the paper's scale: s~ < s, mrad
    (-4.0, 3.0, 1.0, 0.7)])
def test_exact_kld_matches_numerical_integration(mu_t, s_t, mu, s):
    num = _kl_numeric(mu_t, s_t, mu, s)
    assert kld_exact(mu_t, s_t ** 2, mu, s ** 2) == pytest.approx(num, rel=1e-6, abs=1e-10)
    num_swap = _kl_numeric(mu, s, mu_t, s_t)
    assert skld_exact(mu_t, s_t ** 2, mu, s ** 2) == pytest.approx(num + num_swap, rel=1e-6,
                                                                   abs=1e-10)


pos = st.floats(1e-3, 1e3)
real = st.floats(-1e3, 1e3)


@given(real, pos, real, pos)
def test_exact_kld_is_nonnegative_and_zero_iff_equal(mu_t, v_t, mu, v):
    k = kld_exact(mu_t, v_t, mu, v)
    assert k >= -1e-12 * (1 + abs(k))
    assert kld_exact(mu, v, mu, v) == 0.0
    assert skld_exact(mu_t, v_t, mu, v) >= -1e-9
    assert skld_exact(mu_t, v_t, mu, v) == pytest.approx(
        kld_exact(mu_t, v_t, mu, v) + kld_exact(mu, v, mu_t, v_t), rel=1e-9, abs=1e-9)


@given(st.floats(0.1, 0.99), pos, st.floats(-1, 1))
def test_printed_27_is_negative_when_pseudo_variance_is_smaller(ratio, v, mu):
    """Printed (27), not a KL divergence: negative with s~ < s and equal means."""
    assert kld_printed(mu, ratio * v, mu, v) < 0


def test_printed_forms_as_printed():
    # (27): ((s~^2 - s^2) + (mu~-mu)^2) / (2 s^2 s~^2)
    assert kld_printed(1.0, 2.0, 0.0, 4.0) == pytest.approx((2 - 4 + 1) / (2 * 4 * 2))
    # (28) = (27) + its swap: variance terms cancel
    a = kld_printed(1.0, 2.0, 0.0, 4.0) + kld_printed(0.0, 4.0, 1.0, 2.0)
    assert skld_printed(1.0, 2.0, 0.0, 4.0) == pytest.approx(a)
    # neither equals the true divergence
    assert kld_printed(1.0, 2.0, 0.0, 4.0) != pytest.approx(kld_exact(1.0, 2.0, 0.0, 4.0))
    assert skld_printed(1.0, 2.0, 0.0, 4.0) != pytest.approx(skld_exact(1.0, 2.0, 0.0, 4.0))


def test_printed_27_over_the_reproductions_region():
    """(27) at the true association over the region the reproduction draws targets in:
    s~ recomputed independently (finite-difference Jacobian of the bearings at the LS
    position, sandwiching the LS covariance), (27) recomputed from its printed formula,
    and negative exactly where s~ < s and the mean difference is small."""
    from assocopt.reproduce.lu2013.divergence import printed_kld_over_region
    from assocopt.tracking.localisation import angles, wrap_angle
    from assocopt.tracking.scenarios.lu2013 import PAPER_SENSORS_KM
    s = 1.5e-3
    r = printed_kld_over_region(1.5, n=30, seed=3)
    S = np.asarray(PAPER_SENSORS_KM)
    h = 1e-6
    for k in range(30):
        x, P = r["x"][k], r["P"][k]
        J = np.stack([(angles(x + h * e, S) - angles(x - h * e, S)) / (2 * h)
                      for e in np.eye(3)], axis=-1)                      # (3, 2, 3)
        J[:, 1] = wrap_angle(J[:, 1] * 2 * h) / (2 * h)
        var_t = np.einsum("sai,ij,saj->sa", J, P, J)
        assert np.sqrt(var_t) / s == pytest.approx(r["ratio"][k], rel=1e-5)
        diff = angles(x, S) - r["meas"][k]
        diff[:, 1] = wrap_angle(diff[:, 1])
        want = ((var_t - s * s) + diff ** 2) / (2 * s * s * var_t)
        assert want == pytest.approx(r["kld27"][k], rel=1e-5, abs=1e-5 / s ** 2)
    neg = r["kld27"] < 0
    assert (r["ratio"][neg] < 1).all()          # (27) < 0 only where s~ < s
    assert neg.any() and (r["ratio"] < 1).mean() > 0.5


def test_committed_lu2013_summary_has_the_printed_27_range_the_code_gives():
    """The numbers the lu2013 page shows for (27) over the region are this code's."""
    import json
    from pathlib import Path
    from assocopt.reproduce.lu2013.divergence import printed_kld_summary
    path = Path(__file__).resolve().parents[1] / "docs/papers/lu2013/summary.json"
    committed = json.loads(path.read_text())["derived"]["printed_kld"]
    mine = printed_kld_summary((1.5, 5.0))
    assert len(mine) == len(committed)
    for row, want in zip(mine, committed):   # approx takes no nested containers
        assert row.keys() == want.keys()
        assert row == pytest.approx(want, rel=1e-12)


def test_multivariate_reduces_to_scalar_and_to_sum_for_diagonal():
    assert kld_gauss([0.3], [[0.5]], [-0.2], [[2.0]]) == pytest.approx(
        kld_exact(0.3, 0.5, -0.2, 2.0))
    mu0, mu1 = np.array([0.1, -0.4]), np.array([0.5, 0.2])
    S0, S1 = np.diag([0.3, 2.0]), np.diag([1.1, 0.7])
    assert kld_gauss(mu0, S0, mu1, S1) == pytest.approx(
        kld_exact(mu0[0], 0.3, mu1[0], 1.1) + kld_exact(mu0[1], 2.0, mu1[1], 0.7))
    assert skld_gauss(mu0, S0, mu1, S1) == pytest.approx(
        skld_exact(mu0[0], 0.3, mu1[0], 1.1) + skld_exact(mu0[1], 2.0, mu1[1], 0.7))


def test_multivariate_kld_matches_grid_integration_with_correlation():
    mu0, mu1 = np.array([0.2, -0.1]), np.array([-0.3, 0.4])
    S0 = np.array([[0.5, 0.3], [0.3, 0.8]])
    S1 = np.array([[1.2, -0.4], [-0.4, 0.9]])
    g = np.linspace(-7, 7, 1401)
    X, Y = np.meshgrid(g, g, indexing="ij")
    pts = np.stack([X, Y], axis=-1)
    lp = multivariate_normal(mu0, S0).logpdf(pts)
    lq = multivariate_normal(mu1, S1).logpdf(pts)
    num = np.sum(np.exp(lp) * (lp - lq)) * (g[1] - g[0]) ** 2
    assert kld_gauss(mu0, S0, mu1, S1) == pytest.approx(num, rel=1e-4)
    assert skld_gauss(mu0, S0, mu1, S1) == pytest.approx(
        kld_gauss(mu0, S0, mu1, S1) + kld_gauss(mu1, S1, mu0, S0), rel=1e-12)


def test_vectorised_over_batches():
    rng = np.random.default_rng(0)
    mu_t, mu = rng.normal(size=(5, 3)), rng.normal(size=(5, 3))
    v_t, v = rng.uniform(0.1, 2, (5, 3)), rng.uniform(0.1, 2, (5, 3))
    out = kld_exact(mu_t, v_t, mu, v)
    assert out.shape == (5, 3)
    assert out[2, 1] == pytest.approx(float(kld_exact(mu_t[2, 1], v_t[2, 1], mu[2, 1], v[2, 1])))
