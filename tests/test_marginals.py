"""Marginal association probabilities: normalised, and exact when k covers everything."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, InvalidProblemError, marginals
from assocopt.solvers.baseline.bruteforce import enumerate_solutions
from assocopt.testing import random_problem

from test_twod import two_d_cases


def _direct(p: AssignmentProblem, T: float) -> np.ndarray:
    """Candidate marginals by a plain loop over every hypothesis (the reference)."""
    hyps = [(s, sum(p.costs[s])) for s in enumerate_solutions(p)]
    lo = min(c for _, c in hyps)
    out = np.zeros(p.n_candidates)
    z = 0.0
    for s, c in hyps:
        w = math.exp(-(c - lo) / T)
        z += w
        out[s] += w
    return out / z


@settings(max_examples=60, deadline=None)
@given(two_d_cases(), st.sampled_from([0.3, 1.0, 5.0]))
def test_2d_marginals_sum_to_one_and_equal_enumeration(case, T):
    C, rm, cm = case
    p = AssignmentProblem.two_d(C, rm, cm)
    ref = _direct(p, T) if any(True for _ in enumerate_solutions(p)) else None
    if ref is None:
        with pytest.raises(InvalidProblemError, match="no feasible"):
            marginals(p, k=5, temperature=T)
        return
    m = marginals(p, k=10_000, temperature=T)
    assert m.exhaustive
    assert np.allclose(m.candidate, ref, atol=1e-12)
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0)
    assert np.allclose(m.pairs.sum(axis=0) + m.col_miss, 1.0)
    e = marginals(p, temperature=T, method="enumerate")
    assert np.allclose(e.candidate, ref, atol=1e-12) and e.exhaustive


def test_truncated_kbest_marginals_still_normalised():
    p = AssignmentProblem.two_d(np.random.default_rng(0).random((5, 5)), 0.4, 0.4)
    m = marginals(p, k=20)
    assert m.hypotheses == 20 and not m.exhaustive
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0)
    exact = marginals(p, method="enumerate")
    assert np.abs(m.candidate - exact.candidate).max() < 0.5


def test_sd_candidate_marginals_cover_each_index_once():
    p = random_problem(np.random.default_rng(4), "sd", sizes=(3, 2, 2))
    m = marginals(p, k=10_000, solver="highs")
    assert m.exhaustive and np.allclose(m.candidate, _direct(p, 1.0), atol=1e-12)
    A = p.coverage_matrix()
    assert np.allclose(A @ m.candidate, 1.0)


def test_maximize_marginals_weight_high_scores():
    S = np.array([[5.0, 0.0], [0.0, 5.0]])
    m = marginals(AssignmentProblem.dense(S, maximize=True), k=5)
    assert m.pairs[0, 0] == pytest.approx(1 / (1 + math.exp(-10)))


def test_bad_arguments():
    p = AssignmentProblem.dense(np.eye(2))
    with pytest.raises(InvalidProblemError, match="temperature"):
        marginals(p, temperature=0)
    with pytest.raises(InvalidProblemError, match="method"):
        marginals(p, method="sample")
