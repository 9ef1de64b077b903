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
    m = marginals(p, k=10_000, temperature=T, method="kbest")
    assert m.exhaustive
    assert np.allclose(m.candidate, ref, atol=1e-12)
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0)
    assert np.allclose(m.pairs.sum(axis=0) + m.col_miss, 1.0)
    e = marginals(p, temperature=T, method="enumerate")
    assert np.allclose(e.candidate, ref, atol=1e-12) and e.exhaustive


def test_truncated_kbest_marginals_still_normalised():
    p = AssignmentProblem.two_d(np.random.default_rng(0).random((5, 5)), 0.4, 0.4)
    m = marginals(p, k=20, method="kbest")
    assert m.hypotheses == 20 and not m.exhaustive
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0)
    exact = marginals(p, method="enumerate")
    assert np.abs(m.candidate - exact.candidate).max() < 0.5


def test_sd_candidate_marginals_cover_each_index_once():
    p = random_problem(np.random.default_rng(4), "sd", sizes=(3, 2, 2))
    m = marginals(p, k=10_000, solver="highs", method="kbest")
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


# --------------------------------------------------------------- clusters and exact
from assocopt import ProblemTooLargeError  # noqa: E402
from assocopt.ranking.clusters import clusters  # noqa: E402


def _direct_logz(p: AssignmentProblem, T: float) -> float:
    costs = [math.fsum(p.costs[s].tolist()) for s in enumerate_solutions(p)]
    lo = min(costs)
    return math.log(sum(math.exp(-(c - lo) / T) for c in costs)) - lo / T


@st.composite
def any_problem(draw):
    """A small problem of any family (2-D with misses, dense, axial, gated S-D)."""
    kind = draw(st.sampled_from(["square", "rect", "miss", "axial3", "sd", "sd"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**31 - 1)))
    if kind == "sd":
        sizes = tuple(int(v) for v in rng.integers(1, 4, size=int(rng.integers(3, 5))))
        return random_problem(rng, kind, sizes=sizes, keep=float(rng.choice([0.3, 0.6])))
    return random_problem(rng, kind, forbid=0.3)


@settings(max_examples=60, deadline=None)
@given(any_problem())
def test_clusters_partition_indices_and_candidates(p):
    parts = clusters(p)
    rows = np.concatenate([c.rows for c in parts])
    cands = np.concatenate([c.candidates for c in parts])
    assert sorted(rows.tolist()) == list(range(p.n_rows))
    assert sorted(cands.tolist()) == list(range(p.n_candidates))
    R = p.entry_rows
    for c in parts:
        inside = np.isin(R[c.candidates], c.rows) | (R[c.candidates] < 0)
        assert inside.all()
        assert sum(c.sizes(p)) == len(c.rows)


@settings(max_examples=80, deadline=None)
@given(two_d_cases(), st.sampled_from([0.3, 1.0, 5.0]))
def test_exact_2d_equals_brute_force(case, T):
    p = AssignmentProblem.two_d(*case)
    if not any(True for _ in enumerate_solutions(p)):
        with pytest.raises(InvalidProblemError, match="no feasible"):
            marginals(p, temperature=T, method="exact")
        return
    m = marginals(p, temperature=T, method="exact")
    assert m.exhaustive and m.error_bound == 0.0
    assert np.abs(m.candidate - _direct(p, T)).max(initial=0) <= 1e-12
    assert m.log_partition == pytest.approx(_direct_logz(p, T), abs=1e-12, rel=1e-12)
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0, atol=1e-12)
    assert np.allclose(m.pairs.sum(axis=0) + m.col_miss, 1.0, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(any_problem())
def test_exact_any_family_equals_brute_force(p):
    m = marginals(p, method="exact", temperature=2.0)
    assert m.clusters == len(clusters(p))
    assert np.abs(m.candidate - _direct(p, 2.0)).max(initial=0) <= 1e-12
    assert m.log_partition == pytest.approx(_direct_logz(p, 2.0), abs=1e-12, rel=1e-12)
    assert np.allclose(p.coverage_matrix() @ m.candidate, 1.0, atol=1e-12)


def test_sd_false_alarm_probabilities_are_the_singletons():
    p = random_problem(np.random.default_rng(7), "sd", sizes=(3, 3, 2))
    m = marginals(p, method="exact")
    ref = _direct(p, 1.0)
    single = (p.tuples > 0).sum(axis=1) == 1
    for s in range(3):
        sel = single & (p.tuples[:, s] > 0)
        want = np.zeros(p.sizes[s])
        want[p.tuples[sel, s] - 1] = ref[sel]
        assert np.allclose(m.unassigned[s], want, atol=1e-12)
    assert m.pairs is None


def _chain(n: int, rng: np.random.Generator) -> AssignmentProblem:
    """``n`` tracks in a row, track i gating measurements i and i+1, apart in blocks
    of three tracks (independent clusters)."""
    C = np.full((n, n + 1), np.inf)
    for i in range(n):
        C[i, i:i + 2] = rng.normal(size=2)
    for b in range(3, n, 3):                 # cut the chain every 3 tracks
        C[b - 1, b] = np.inf
    return AssignmentProblem.two_d(C, rng.random(n) + 0.5, rng.random(n + 1) + 0.5)


def test_clusters_multiply_and_log_partitions_add():
    p = _chain(9, np.random.default_rng(3))
    m = marginals(p, method="exact")
    assert m.clusters == 3
    assert np.abs(m.candidate - _direct(p, 1.0)).max() <= 1e-12
    assert m.log_partition == pytest.approx(_direct_logz(p, 1.0), abs=1e-11)


def test_large_entangled_cluster_is_exact_and_budget_is_an_error():
    rng = np.random.default_rng(5)
    n = 40                                    # tracks gating 3 neighbouring measurements
    C = np.full((n, n + 2), np.inf)
    for i in range(n):
        C[i, i:i + 3] = rng.normal(size=3)
    p = AssignmentProblem.two_d(C, 1.0, 1.0)
    m = marginals(p, method="exact")
    assert m.clusters == 1 and m.exhaustive and m.nodes > 0
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0, atol=1e-12)
    with pytest.raises(ProblemTooLargeError, match=r"cluster of 40 x 42 indices.*max_nodes=50"):
        marginals(p, method="exact", max_nodes=50)


def test_bad_input_is_a_clear_error():
    with pytest.raises(InvalidProblemError, match="no feasible.*index 1 of axis 0"):
        marginals(AssignmentProblem.two_d([[np.inf]], np.inf, 0.0), method="exact")
    with pytest.raises(InvalidProblemError, match="NaN"):
        marginals(AssignmentProblem.two_d([[np.nan]], 0.0, 0.0))
    with pytest.raises(InvalidProblemError, match=r"\+inf"):
        marginals(AssignmentProblem.two_d([[np.inf]], 0.0, 0.0, maximize=True))
    p = AssignmentProblem.two_d([[0.0]], 0.0, 0.0)
    for T in (0, -1.0, math.inf, math.nan, True):
        with pytest.raises(InvalidProblemError, match="temperature"):
            marginals(p, temperature=T)
    with pytest.raises(InvalidProblemError, match="max_nodes"):
        marginals(p, max_nodes=0)


# ------------------------------------------------------- approximations and bounds
@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.sampled_from([1, 3, 10, 30]),
       st.sampled_from([0.5, 1.0, 3.0]))
def test_kbest_error_bound_holds_against_exact(seed, k, T):
    rng = np.random.default_rng(seed)
    kind = rng.choice(["miss", "sd", "square"])
    p = random_problem(rng, str(kind), forbid=0.2) if kind != "sd" else \
        random_problem(rng, "sd", sizes=(3, 3, 3))
    exact = marginals(p, temperature=T, method="exact")
    m = marginals(p, k=k, temperature=T, method="kbest")
    err = np.abs(m.candidate - exact.candidate).max(initial=0)
    assert err <= m.error_bound + 1e-12
    assert m.exhaustive == (m.error_bound == 0.0)
    if m.exhaustive:
        assert err <= 1e-12
    assert m.log_partition <= exact.log_partition + 1e-9


def _tree(rng: np.random.Generator) -> AssignmentProblem:
    """Tracks on a line, each gating its own measurement and the next one: a
    cycle-free association graph, on which belief propagation is exact."""
    n = 7
    C = np.full((n, n + 1), np.inf)
    for i in range(n):
        C[i, i:i + 2] = rng.normal(size=2)
    return AssignmentProblem.two_d(C, rng.random(n) + 0.2, rng.random(n + 1) + 0.2)


def test_lbp_is_exact_on_a_tree_and_reports_its_iterations():
    p = _tree(np.random.default_rng(11))
    exact = marginals(p, method="exact")
    m = marginals(p, method="lbp", tolerance=1e-13)
    assert np.abs(m.candidate - exact.candidate).max() < 1e-9
    assert m.iterations >= 2 and m.residual <= 1e-13 and not m.exhaustive
    assert math.isnan(m.error_bound)
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0)
    short = marginals(p, method="lbp", max_iterations=1)
    assert short.iterations == 1 and short.residual > 1e-13


def test_lbp_close_on_loopy_clusters_and_refuses_what_it_cannot_do():
    rng = np.random.default_rng(2)
    C = rng.normal(size=(4, 4)) + 2.0
    p = AssignmentProblem.two_d(C, 1.0, 1.0)
    err = np.abs(marginals(p, method="lbp").candidate
                 - marginals(p, method="exact").candidate).max()
    assert 0 < err < 0.1
    with pytest.raises(InvalidProblemError, match="column 1 is not"):
        marginals(AssignmentProblem.dense(C), method="lbp")
    with pytest.raises(InvalidProblemError, match="2-D"):
        marginals(random_problem(rng, "sd", sizes=(2, 2, 2)), method="lbp")


def test_auto_falls_back_to_kbest_with_a_bound_and_a_warning():
    rng = np.random.default_rng(5)
    n = 12
    C = np.full((n, n + 2), np.inf)
    for i in range(n):
        C[i, i:i + 3] = rng.normal(size=3)
    p = AssignmentProblem.two_d(C, 1.0, 1.0)
    exact = marginals(p)
    assert exact.method == "auto" and exact.exhaustive and exact.approximated == 0
    with pytest.warns(RuntimeWarning, match="within"):
        m = marginals(p, k=5, max_nodes=20)
    assert m.approximated == 1 and m.error_bound > 1e-3 and not m.exhaustive
    assert np.abs(m.candidate - exact.candidate).max() <= m.error_bound


def test_a_frontier_over_64_bits_is_an_error_naming_the_cluster():
    C = np.random.default_rng(1).random((70, 70))      # every pair allowed: one cluster
    p = AssignmentProblem.two_d(C, 1.0, 1.0)
    with pytest.raises(ProblemTooLargeError, match="cluster of 70 x 70 indices.*64"):
        marginals(p, method="exact")


def test_a_net_larger_than_its_first_work_arrays_is_the_same_either_way_round():
    """Every track gates every measurement: a net of over 65 536 nodes (the build
    restarts with larger work arrays); the transposed problem (measurements first) is
    another net over other states, and must give the same probabilities."""
    rng = np.random.default_rng(8)
    C = rng.normal(size=(13, 14))
    rm, cm = rng.random(13), rng.random(14)
    m = marginals(AssignmentProblem.two_d(C, rm, cm), method="exact")
    t = marginals(AssignmentProblem.two_d(C.T, cm, rm), method="exact")
    assert m.nodes > 65_536
    assert np.abs(m.pairs - t.pairs.T).max() < 1e-12
    assert np.abs(m.row_miss - t.col_miss).max() < 1e-12
    assert m.log_partition == pytest.approx(t.log_partition, rel=1e-13)
    assert np.allclose(m.pairs.sum(axis=1) + m.row_miss, 1.0, atol=1e-12)
