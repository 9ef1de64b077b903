"""Gating and kinematic costs: against direct numpy loops, scipy.stats.chi2, and the
ungated optimum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy.stats import chi2

from assocopt import solve
from assocopt.runtime.errors import InvalidProblemError
from assocopt.tracking.costs import kinematic as kin
from assocopt.tracking.gating import gate, pair_statistics, predict_measurements
from conftest import fresh_python


def _random_scan(rng, n, M, m, spread=10.0):
    zp = rng.uniform(0, spread, size=(n, m))
    A = rng.normal(size=(n, m, m))
    S = A @ np.swapaxes(A, 1, 2) * 0.3 + np.eye(m) * 0.2
    z = rng.uniform(0, spread, size=(M, m))
    return zp, S, z


def _loop_d2(zp, S, z):
    """Squared Mahalanobis distance and log det of every pair, one pair at a time."""
    n, M = len(zp), len(z)
    d2 = np.empty((n, M))
    ld = np.empty((n, M))
    for i in range(n):
        Si = np.linalg.inv(S[i])
        for j in range(M):
            v = z[j] - zp[i]
            d2[i, j] = float(v @ Si @ v)
            ld[i, j] = math.log(np.linalg.det(S[i]))
    return d2, ld


@pytest.mark.parametrize("m", [1, 2, 3])
def test_gate_keeps_exactly_the_pairs_below_the_chi2_quantile(m):
    rng = np.random.default_rng(m)
    zp, S, z = _random_scan(rng, 30, 40, m, spread=6.0)
    g = gate(zp, S, z, probability=0.9)
    d2, ld = _loop_d2(zp, S, z)
    gamma = chi2.ppf(0.9, m)
    want = {(i, j) for i in range(30) for j in range(40) if d2[i, j] <= gamma}
    assert set(zip(g.rows.tolist(), g.cols.tolist())) == want
    assert 0 < len(want) < 30 * 40              # the gate really drops pairs here
    np.testing.assert_allclose(g.d2, d2[g.rows, g.cols], rtol=1e-10)
    np.testing.assert_allclose(g.logdet, ld[g.rows, g.cols], rtol=1e-10, atol=1e-12)
    assert g.threshold == pytest.approx(gamma) and g.probability == pytest.approx(0.9)


def test_gate_with_per_measurement_noise_matches_a_loop():
    rng = np.random.default_rng(5)
    zp, HPH, z = _random_scan(rng, 12, 15, 2, spread=5.0)
    B = rng.normal(size=(15, 2, 2))
    R = B @ np.swapaxes(B, 1, 2) * 0.5 + np.eye(2) * 0.1
    g = gate(zp, HPH, z, R=R, probability=0.95)
    gamma = chi2.ppf(0.95, 2)
    want = set()
    for i in range(12):
        for j in range(15):
            v = z[j] - zp[i]
            if v @ np.linalg.inv(HPH[i] + R[j]) @ v <= gamma:
                want.add((i, j))
    assert set(zip(g.rows.tolist(), g.cols.tolist())) == want and want


def test_ungated_keeps_every_pair_and_pair_statistics_agree():
    rng = np.random.default_rng(2)
    zp, S, z = _random_scan(rng, 5, 7, 2)
    g = gate(zp, S, z, threshold=np.inf)
    assert g.n_pairs == 35 and g.probability == 1.0
    d2, _ = pair_statistics(zp, S, z, g.rows, g.cols)
    np.testing.assert_allclose(d2, g.d2)


def test_nllr_and_mahalanobis_costs_against_a_direct_computation():
    rng = np.random.default_rng(3)
    zp, S, z = _random_scan(rng, 8, 9, 2, spread=4.0)
    pd = rng.uniform(0.5, 0.99, size=8)
    lam = rng.uniform(1e-3, 1e-1, size=9)
    g = gate(zp, S, z, probability=0.99)
    got = kin.nllr_costs(g, pd, lam)
    for k, (i, j) in enumerate(zip(g.rows, g.cols)):
        v = z[j] - zp[i]
        lik = math.exp(-0.5 * v @ np.linalg.inv(S[i]) @ v) / math.sqrt(
            np.linalg.det(2 * math.pi * S[i]))
        assert got[k] == pytest.approx(-math.log(pd[i] * lik / lam[j]), rel=1e-10)
        assert kin.mahalanobis_costs(g)[k] == pytest.approx(v @ np.linalg.inv(S[i]) @ v)
    miss = kin.nllr_miss_cost(pd, g.probability)
    np.testing.assert_allclose(miss, -np.log(1 - pd * 0.99))


def test_build_problem_layout_and_miss_costs():
    rng = np.random.default_rng(4)
    zp, S, z = _random_scan(rng, 6, 5, 2, spread=3.0)
    p = kin.build_problem(zp, S, z, pd=0.8, clutter_density=0.01, name="my-scan")
    assert p.name == "my-scan" and p.sizes == (6, 5)
    rm, cm = p.miss_costs()
    np.testing.assert_allclose(rm, -np.log(1 - 0.8 * 0.99))
    np.testing.assert_array_equal(cm, 0.0)
    g = gate(zp, S, z, probability=0.99)
    real = (p.tuples > 0).all(axis=1)
    assert real.sum() == g.n_pairs
    pm = kin.build_problem(zp, S, z, cost="mahalanobis")
    assert pm.name == "gated-mahalanobis"
    np.testing.assert_allclose(pm.miss_costs()[0], chi2.ppf(0.99, 2))


def test_predict_measurements_is_h_p_ht_plus_r():
    rng = np.random.default_rng(6)
    x = rng.normal(size=(4, 4))
    A = rng.normal(size=(4, 4, 4))
    P = A @ np.swapaxes(A, 1, 2)
    H = np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]])
    R = np.diag([0.5, 0.7])
    z, S = predict_measurements(x, P, H, R)
    for i in range(4):
        np.testing.assert_allclose(z[i], H @ x[i])
        np.testing.assert_allclose(S[i], H @ P[i] @ H.T + R)


def test_large_scan_gates_without_all_pairs():
    """10^4 tracks and measurements (an all-pairs pass would be 10^8 pairs)."""
    rng = np.random.default_rng(7)
    n = 10_000
    truth = rng.uniform(0, 1000, size=(n, 2))
    z = truth + rng.normal(scale=0.5, size=(n, 2))
    g = gate(truth, np.eye(2) * 0.25, z, probability=0.99)
    assert n <= g.n_pairs < 5 * n
    # every measurement of a sample of tracks, checked exactly
    sample = rng.choice(n, 50, replace=False)
    d2 = (((z[None, :, :] - truth[sample, None, :]) ** 2).sum(-1) / 0.25)
    gamma = chi2.ppf(0.99, 2)
    for k, i in enumerate(sample):
        assert set(g.cols[g.rows == i].tolist()) == set(np.flatnonzero(d2[k] <= gamma).tolist())
    p = kin.build_problem(truth, np.eye(2) * 0.25, z, pd=0.9, clutter_density=1e-4)
    assert p.n_candidates == g.n_pairs + 2 * n


@given(st.integers(0, 10_000), st.integers(1, 5), st.integers(0, 5),
       st.sampled_from(["nllr", "mahalanobis"]))
def test_gated_optimum_equals_ungated_when_it_uses_only_gated_pairs(seed, n, M, cost):
    rng = np.random.default_rng(seed)
    zp, S, z = _random_scan(rng, n, M, 2, spread=3.0)
    opts = dict(cost=cost, pd=0.9, clutter_density=0.02, miss_cost=4.0)
    full = kin.build_problem(zp, S, z, threshold=np.inf, **opts)
    gated = kin.build_problem(zp, S, z, probability=0.9, **opts)
    s_full = solve(full, "highs")
    g = gate(zp, S, z, probability=0.9)
    inside = set(zip((g.rows + 1).tolist(), (g.cols + 1).tolist()))
    used = {tuple(t) for t in s_full.tuples.tolist() if min(t) > 0}
    if used <= inside:
        assert solve(gated, "highs").objective == pytest.approx(s_full.objective, abs=1e-9)
    else:                                        # the gate removed an optimal pair
        assert solve(gated, "highs").objective >= s_full.objective - 1e-9


def test_bad_input_is_named():
    with pytest.raises(InvalidProblemError, match="not positive definite"):
        gate([[0.0, 0.0]], -np.eye(2), [[0.0, 0.0]])
    with pytest.raises(InvalidProblemError, match=r"z must have shape \(M, 2\)"):
        gate([[0.0, 0.0]], np.eye(2), [[0.0, 0.0, 1.0]])
    with pytest.raises(InvalidProblemError, match=r"S must have shape \(1, 2, 2\) or \(2, 2\)"):
        gate([[0.0, 0.0]], np.eye(3), [[0.0, 0.0]])
    with pytest.raises(InvalidProblemError, match=r"P must have shape \(1, 2, 2\) or \(2, 2\)"):
        predict_measurements([[1.0, 0.5]], np.eye(3), [[1.0, 0.0]])
    with pytest.raises(InvalidProblemError, match="P is not positive semi-definite .*negative"):
        predict_measurements([[1.0, 0.5]], -np.eye(2), [[1.0, 0.0]])
    with pytest.raises(InvalidProblemError, match=r"P\[1\] is not positive semi-definite "
                                                  r"\(it is indefinite"):
        predict_measurements([[1.0, 0.5]] * 2, [np.eye(2), np.diag([1.0, -1.0])],
                             [[1.0, 0.0]])
    with pytest.raises(InvalidProblemError, match="P is not symmetric"):
        predict_measurements([[1.0, 0.5]], [[1.0, 0.5], [0.0, 1.0]], [[1.0, 0.0]])
    with pytest.raises(InvalidProblemError, match="R is not positive semi-definite"):
        predict_measurements([[1.0, 0.5]], np.eye(2), [[1.0, 0.0]], [[-0.1]])
    z, S = predict_measurements([[1.0, 0.5]], np.zeros((2, 2)), [[1.0, 0.0]], [[0.1]])
    assert S.tolist() == [[[0.1]]]          # a singular (known) state is a covariance
    with pytest.raises(InvalidProblemError, match="gate probability"):
        gate([[0.0, 0.0]], np.eye(2), [[0.0, 0.0]], probability=1.0)
    with pytest.raises(InvalidProblemError, match="clutter_density must be > 0"):
        kin.build_problem([[0.0]], [[1.0]], [[0.0]], clutter_density=0.0)
    with pytest.raises(InvalidProblemError, match="unknown cost"):
        kin.build_problem([[0.0]], [[1.0]], [[0.0]], cost="euclid")
    with pytest.raises(InvalidProblemError, match="pd must lie"):
        kin.build_problem([[0.0]], [[1.0]], [[0.0]], pd=1.5)


def test_empty_scans():
    g = gate(np.zeros((0, 2)), np.eye(2), [[1.0, 1.0]])
    assert g.n_pairs == 0 and g.n_tracks == 0
    p = kin.build_problem(np.zeros((2, 2)), np.eye(2), np.zeros((0, 2)))
    assert p.sizes == (2, 0) and solve(p).objective == pytest.approx(
        2 * -math.log(1 - 0.9 * 0.99))


def test_the_core_never_imports_tracking():
    code = ("import sys, assocopt, assocopt.solving.api, assocopt.problems.problem, assocopt.solvers, "
            "assocopt.io, assocopt.cli; "
            "print(any(m.startswith('assocopt.tracking') for m in sys.modules))")
    assert fresh_python(code).strip() == "False"


def test_the_gating_package_loads_neither_stonesoup_nor_numba():
    """``assocopt.tracking.gating`` is a package of plain numpy modules: its public
    names are there without Stone Soup or the compiled kernels."""
    code = ("import sys\nfrom assocopt.tracking.gating import gate, gated_tuples, "
            "build_gated_problem\n"
            "print(sorted(m for m in ('stonesoup', 'numba') if m in sys.modules))")
    assert fresh_python(code).strip() == "[]"
