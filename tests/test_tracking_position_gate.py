"""position_pair_gate against a brute-force chi-square test of every report pair."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.runtime.errors import InvalidProblemError
from assocopt.tracking.gating import chi2_threshold, gated_tuples, position_pair_gate


def _random_cov(rng, d, n=None):
    A = rng.normal(size=(d, d) if n is None else (n, d, d))
    return A @ np.swapaxes(A, -1, -2) * rng.uniform(0.05, 2.0) + 0.05 * np.eye(d)


def _brute(Z, R, probability):
    """Every pair of every sensor pair, tested one by one."""
    gamma = chi2_threshold(probability, Z[0].shape[1])
    out = {}
    for s, t in itertools.combinations(range(len(Z)), 2):
        M = np.zeros((len(Z[s]), len(Z[t])), bool)
        for i, j in itertools.product(range(len(Z[s])), range(len(Z[t]))):
            C = R[s][i] + R[t][j]
            v = Z[s][i] - Z[t][j]
            M[i, j] = v @ np.linalg.solve(C, v) <= gamma
        out[(s, t)] = M
    return out


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 4), st.integers(1, 3), st.booleans())
def test_position_gate_equals_brute_force(seed, N, d, per_report):
    rng = np.random.default_rng(seed)
    sizes = rng.integers(0, 7, size=N)
    centre = rng.normal(size=(6, d)) * 3.0               # targets, so that some pairs pass
    Z = [centre[rng.integers(0, 6, size=n)] + rng.normal(size=(n, d)) for n in sizes]
    if per_report:
        R = [_random_cov(rng, d, n) for n in sizes]
        full = R
    else:
        R = [_random_cov(rng, d) for _ in sizes]
        full = [np.broadcast_to(r, (n, d, d)) for r, n in zip(R, sizes)]
    p = float(rng.choice([0.9, 0.99, 0.999]))
    got = position_pair_gate(Z, R, probability=p)
    want = _brute(Z, full, p)
    assert set(got) == set(want)
    for k in want:
        assert got[k].shape == want[k].shape
        assert np.array_equal(got[k].toarray(), want[k]), k
    # the sparse result feeds gated_tuples as the dense one does
    assert np.array_equal(gated_tuples(sizes, got, 0.9, 1.0), gated_tuples(sizes, want, 0.9, 1.0))


def test_mixed_shared_and_per_report_covariances():
    rng = np.random.default_rng(4)
    Z = [rng.normal(size=(30, 2)) for _ in range(3)]
    R = [np.eye(2) * 0.3, _random_cov(rng, 2, 30), np.diag([0.1, 2.0])]
    full = [np.broadcast_to(R[0], (30, 2, 2)), R[1], np.broadcast_to(R[2], (30, 2, 2))]
    got = position_pair_gate(Z, R, probability=0.99)
    want = _brute(Z, full, 0.99)
    for k in want:
        assert np.array_equal(got[k].toarray(), want[k])
    assert any(M.any() for M in want.values()) and not all(M.all() for M in want.values())


def test_bad_reports_are_named():
    good = [np.zeros((2, 2)), np.ones((3, 2))]
    with pytest.raises(InvalidProblemError, match=r"report 1 \(0-based\) of sensor 0 .*NaN"):
        position_pair_gate([np.array([[0.0, 0.0], [np.nan, 1.0]]), good[1]], np.eye(2))
    with pytest.raises(InvalidProblemError, match="same dimension"):
        position_pair_gate([np.zeros((2, 2)), np.zeros((2, 3))], np.eye(2))
    with pytest.raises(InvalidProblemError, match="sensor 1 is not positive definite"):
        position_pair_gate(good, [np.eye(2), np.diag([1.0, -1.0])])
    bad = np.stack([np.eye(2)] * 3)
    bad[2] = [[1.0, 2.0], [2.0, 1.0]]
    with pytest.raises(InvalidProblemError, match=r"sensor 1 \(report 2\) is not positive"):
        position_pair_gate(good, [np.eye(2), bad])
    with pytest.raises(InvalidProblemError, match="not symmetric"):
        position_pair_gate(good, [np.eye(2), [[1.0, 0.5], [0.0, 1.0]]])
    with pytest.raises(InvalidProblemError, match=r"R of sensor 1 must have shape"):
        position_pair_gate(good, [np.eye(2), np.eye(3)])
    with pytest.raises(InvalidProblemError, match="probability"):
        position_pair_gate(good, np.eye(2), probability=1.5)
    with pytest.raises(InvalidProblemError, match="at least 2 sensors"):
        position_pair_gate([good[0]], np.eye(2))
