"""The dense 2-D path and the sparse gated engine against brute force."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, Status, solve
from assocopt.solvers.twod.lap import lapx_available
from assocopt.solvers.twod.sparse import assign_sparse
from conftest import draw_misses

ENGINES = ["scipy-lsa"] + (["lapjv"] if lapx_available() else [])


@st.composite
def two_d_cases(draw):
    """A small 2-D matrix with forbidden entries and misses that may be forbidden."""
    n1 = draw(st.integers(0, 4))
    n2 = draw(st.integers(0, 4))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    C = rng.integers(-5, 10, size=(n1, n2)).astype(float)
    C[rng.random((n1, n2)) < draw(st.sampled_from([0.0, 0.3]))] = np.inf

    return C, draw_misses(draw, rng, n1, None), draw_misses(draw, rng, n2, None)


def _reference(p: AssignmentProblem):
    return solve(AssignmentProblem.sparse(p.sizes, p.tuples, p.costs), "bruteforce")


@settings(max_examples=150, deadline=None)
@given(two_d_cases())
def test_dense_path_matches_brute_force(case):
    C, rm, cm = case
    p = AssignmentProblem.two_d(C, rm, cm)
    ref = _reference(p)
    for name in ENGINES:
        sol = solve(p, name)
        if ref.status is Status.INFEASIBLE:
            assert sol.status is Status.INFEASIBLE, (name, sol)
            continue
        assert sol.status is Status.OPTIMAL, (name, sol.message)
        assert sol.objective == pytest.approx(ref.objective, abs=1e-9)
        assert p.violations(sol.selected) is None
        assert p.objective_of(sol.selected) == pytest.approx(sol.objective)
        assert np.array_equal(sol.tuples,
                              p.tuples[sol.selected[~p.slack[sol.selected]]])


@settings(max_examples=150, deadline=None)
@given(two_d_cases())
def test_sparse_engine_matches_brute_force(case):
    from assocopt.solvers.twod.lap import LapInfeasibleError

    C, rm, cm = case
    p = AssignmentProblem.two_d(C, rm, cm)
    ref = _reference(p)
    n1, n2 = C.shape
    rm_, cm_ = p.miss_costs()
    rows, cols = np.nonzero(np.isfinite(C))
    try:
        cor, _ = assign_sparse(n1, n2, rows, cols, C[rows, cols], rm_, cm_)
    except LapInfeasibleError:
        assert ref.status is Status.INFEASIBLE
        return
    assert ref.status is Status.OPTIMAL
    checked = p.dense_view.check(cor)
    assert not isinstance(checked, str), checked
    assert checked.objective == pytest.approx(ref.objective, abs=1e-9)


def test_lazy_candidate_list_matches_the_eager_construction():
    C = np.array([[1.0, np.inf, 3.0], [4.0, 5.0, 6.0]])
    p = AssignmentProblem.two_d(C, row_miss=[1.0, np.inf], col_miss=2.0)
    assert p.__dict__.get("_tuples") is None          # not built by the constructor
    assert p.n_candidates == 5 + 1 + 3
    assert p.tuples.tolist() == [[1, 1], [1, 3], [2, 1], [2, 2], [2, 3], [1, 0],
                                 [0, 1], [0, 2], [0, 3]]
    assert p.costs.tolist() == [1, 3, 4, 5, 6, 1, 2, 2, 2]
    q = AssignmentProblem.dense(np.arange(6.0).reshape(3, 2))
    assert q.tuples[q.slack].tolist() == [[1, 0], [2, 0], [3, 0]]


def test_dense_solve_does_not_build_the_candidate_list():
    p = AssignmentProblem.two_d(np.random.default_rng(1).random((30, 40)), 0.5, 0.5)
    sol = solve(p)
    assert sol.status is Status.OPTIMAL and p.__dict__["_tuples"] is None
    assert sol.info["lsa_mode"] == "reduced"


def test_gated_candidate_list_is_solved_sparse():
    from assocopt.workflow.generate import gated_2d

    p = gated_2d(3000, 5, seed=0)
    sol = solve(p)
    assert sol.status is Status.OPTIMAL and sol.info["lsa_mode"] == "sparse-reduced"


@settings(max_examples=200, deadline=None)
@given(two_d_cases(), st.integers(0, 2**31 - 1))
def test_small_and_bulk_checks_agree(case, seed):
    """The list-based check of small answers and the numpy one give the same verdict,
    positions, objective and tuples, also on answers that are not feasible."""
    C, rm, cm = case
    p = AssignmentProblem.two_d(C, rm if rm is not None else 0.0, cm)
    d = p.dense_view
    n1, n2 = C.shape
    cor = np.random.default_rng(seed).integers(-1, max(n2, 1), size=n1)
    a, b = d._check_small(cor), d._check_bulk(cor)
    if isinstance(b, str):
        assert isinstance(a, str)
        return
    assert not isinstance(a, str)
    assert np.array_equal(a.selected, b.selected) and np.array_equal(a.tuples, b.tuples)
    assert a.objective == b.objective
