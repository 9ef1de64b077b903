"""AssignmentProblem: construction, conventions and validation errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assocopt import AssignmentProblem, InvalidProblemError, solve

from conftest import sd_problems


def test_dense_square_has_all_tuples_one_based():
    p = AssignmentProblem.dense(np.arange(4.0).reshape(2, 2))
    assert p.sizes == (2, 2)
    assert p.tuples.tolist() == [[1, 1], [1, 2], [2, 1], [2, 2]]
    assert p.costs.tolist() == [0, 1, 2, 3]
    assert not p.slack.any()


def test_dense_rectangular_adds_zero_cost_slack_on_larger_axes_only():
    p = AssignmentProblem.dense(np.ones((2, 3, 4)))
    slack = p.tuples[p.slack]
    # axis 1 (size 3) and axis 2 (size 4) are larger than the smallest (2)
    assert sorted(map(tuple, slack)) == sorted(
        [(0, j, 0) for j in (1, 2, 3)] + [(0, 0, k) for k in (1, 2, 3, 4)])
    assert (p.costs[p.slack] == 0).all()


def test_rectangular_solution_reports_no_slack_and_matches_scipy():
    from scipy.optimize import linear_sum_assignment
    C = np.random.default_rng(3).random((3, 6))
    sol = solve(AssignmentProblem.dense(C), "highs")
    r, c = linear_sum_assignment(C)
    assert sol.objective == pytest.approx(C[r, c].sum())
    assert (sol.tuples > 0).all()
    rows, cols = sol.assignment()
    assert rows.tolist() == r.tolist() and cols.tolist() == c.tolist()


def test_inf_means_forbidden_and_is_dropped():
    C = np.array([[1.0, np.inf], [np.inf, 1.0]])
    p = AssignmentProblem.dense(C)
    assert p.n_candidates == 2 and np.isfinite(p.costs).all()
    sp = AssignmentProblem.sparse((2, 2), [[1, 1], [2, 2], [1, 2]], [1.0, 2.0, np.inf])
    assert sp.n_candidates == 2


def test_two_d_miss_costs_make_dummy_tuples():
    p = AssignmentProblem.two_d([[1.0, 2.0]], row_miss=[5.0], col_miss=[0.5, 0.25])
    got = {tuple(t): c for t, c in zip(p.tuples.tolist(), p.costs)}
    assert got == {(1, 1): 1.0, (1, 2): 2.0, (1, 0): 5.0, (0, 1): 0.5, (0, 2): 0.25}
    rm, cm = p.miss_costs()
    assert rm.tolist() == [5.0] and cm.tolist() == [0.5, 0.25]


def test_two_d_without_misses_is_dense():
    assert AssignmentProblem.two_d(np.ones((2, 3))).kind == "dense"


def test_input_arrays_are_copied_and_frozen():
    C = np.ones((2, 2))
    p = AssignmentProblem.dense(C)
    C[0, 0] = 99
    assert p.costs.max() == 1
    with pytest.raises(ValueError):
        p.costs[0] = 5


def test_coverage_matrix_rows_are_axis_offsets():
    p = AssignmentProblem.sparse((2, 3), [[1, 0], [0, 3], [2, 1]], [1, 2, 3])
    A = p.coverage_matrix().toarray()
    assert A.shape == (5, 3)
    assert A[:, 0].tolist() == [1, 0, 0, 0, 0]
    assert A[:, 1].tolist() == [0, 0, 0, 0, 1]
    assert A[:, 2].tolist() == [0, 1, 1, 0, 0]


def test_uncovered_names_axis_and_index():
    p = AssignmentProblem.sparse((2, 2), [[1, 1], [2, 1]], [1, 2])
    assert p.uncovered() == [(1, 2)]


def test_n_uncovered_of_full_grids_and_of_grids_with_a_hole():
    """A full grid of real tuples covers everything; one with as many tuples but a
    dummy among them, or with a forbidden entry, is counted."""
    assert AssignmentProblem.dense(np.ones((3, 3, 3))).n_uncovered == 0
    C = np.ones((2, 2, 2))
    C[1, :, :] = np.inf                         # real index 2 of axis 0: no candidate
    assert AssignmentProblem.dense(C).n_uncovered == 1
    T = [[1, 1], [1, 0], [0, 1], [0, 2]]         # 4 tuples = 2 x 2, index 2 of axis 0 missing
    p = AssignmentProblem.sparse((2, 2), T, [1.0, 1.0, 1.0, 1.0])
    assert p.n_uncovered == 1 and p.uncovered() == [(0, 2)]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(1, 6), min_size=2, max_size=5), st.integers(0, 10 ** 6),
       st.floats(0.05, 1.0))
def test_n_uncovered_counts_the_indices_no_candidate_covers(sizes, seed, keep):
    """The one-count route of ``n_uncovered`` agrees with the per-axis sets of
    ``uncovered()`` (asked first and second: the cached route too)."""
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij"),
                    -1).reshape(-1, len(sizes))[1:]
    T = grid[rng.random(len(grid)) < keep]
    if not len(T):
        T = grid[:1]
    p = AssignmentProblem.sparse(sizes, T, rng.normal(size=len(T)))
    want = sum(n - len(np.unique(T[:, s][T[:, s] > 0])) for s, n in enumerate(sizes))
    assert p.n_uncovered == want
    assert len(p.uncovered()) == want and p.n_uncovered == want


@pytest.mark.parametrize("cached", [False, True])
def test_window_rows_agree_with_the_cached_rows(cached):
    """uncovered_rows, coverage_matrix and violations of a subset of the candidates
    give the same answer whether or not the rows of all candidates are cached."""
    rng = np.random.default_rng(3)
    T = np.unique(rng.integers(0, 4, (40, 3)), axis=0)
    T = T[(T > 0).any(axis=1)]
    p = AssignmentProblem.sparse((3, 3, 3), T, rng.random(len(T)))
    if cached:
        p.entry_rows
    for pos in (np.arange(p.n_candidates), rng.choice(p.n_candidates, 12, replace=False),
                np.zeros(0, np.int64)):
        R = p.rows_of(p.tuples[pos])
        want = np.setdiff1d(np.arange(p.n_rows), R[R >= 0])
        assert p.uncovered_rows(pos).tolist() == want.tolist()
        A = p.coverage_matrix(pos).toarray()
        assert (A.sum(axis=0) == (R >= 0).sum(axis=1)).all()
    assert ("entry_rows" in p.__dict__) is cached   # windows need not build the cache
    sel = np.flatnonzero((p.tuples > 0).sum(axis=1) == 1)
    assert p.violations(sel[:1]) is not None


@pytest.mark.parametrize("bad, match", [
    (np.array([[1.0, np.nan]]), "NaN"),
    (np.array([[1.0, -np.inf]]), "-inf"),
    (np.array([1.0, 2.0]), "at least 2 dimensions"),
    ([["a", "b"]], "numeric"),
])
def test_dense_rejects_bad_costs(bad, match):
    with pytest.raises(InvalidProblemError, match=match):
        AssignmentProblem.dense(bad)


@pytest.mark.parametrize("sizes, tuples, costs, match", [
    ((2, 2), [[1, 1]], [1.0, 2.0], r"costs must have shape \(1,\)"),
    ((2, 2), [[1, 1, 1]], [1.0], r"shape \(K, 2\)"),
    ((2, 2), [[1, 3]], [1.0], "out of range"),
    ((2, 2), [[1, -1]], [1.0], "out of range"),
    ((2, 2), [[1.5, 1]], [1.0], "non-integer"),
    ((2, 2), [[0, 0]], [1.0], "all-dummy"),
    ((2, 2), [[0, 0], [0, 1], [1, 0]], [1.0, 1.0, 1.0], "all-dummy"),   # sorted, distinct
    ((2, 2), [[0, 0], [0, 0]], [1.0, 1.0], "all-dummy"),      # before the duplicate
    ((2, 2), [[1, 1], [1, 1]], [1.0, 2.0], "duplicate candidate tuple"),
    ((2, -1), [[1, 0]], [1.0], "non-negative"),
    ((2,), [[1]], [1.0], "at least 2 axes"),
    ((2, 2.5), [[1, 1]], [1.0], "integers"),
    ((2, 2), [[1, 1]], [np.nan], "NaN"),
])
def test_sparse_validation(sizes, tuples, costs, match):
    with pytest.raises(InvalidProblemError, match=match):
        AssignmentProblem.sparse(sizes, tuples, costs)


@pytest.mark.parametrize("sizes", [(5, 5, 5), (2 ** 40, 2 ** 40, 5)])
def test_duplicate_reported_as_the_first_in_sorted_order(sizes):
    # small sizes: found by mixed-radix keys; 2**80 keys overflow: by row-wise unique
    T = [[3, 1, 2], [1, 4, 4], [3, 1, 2], [1, 4, 4], [2, 0, 1]]
    with pytest.raises(InvalidProblemError, match=r"duplicate candidate tuple \[1, 4, 4\]"):
        AssignmentProblem.sparse(sizes, T, np.zeros(5))
    AssignmentProblem.sparse(sizes, T[1:3] + T[4:], np.zeros(3))     # no duplicate


def test_miss_cost_shape_is_checked():
    with pytest.raises(InvalidProblemError, match=r"row_miss must be a scalar or have shape \(2,\)"):
        AssignmentProblem.two_d(np.ones((2, 2)), row_miss=[1.0, 2.0, 3.0])


def test_violations_reports_double_cover():
    p = AssignmentProblem.sparse((2, 2), [[1, 1], [2, 1], [2, 2]], [1, 1, 1])
    assert "covered 2 times" in p.violations([0, 1])
    assert p.violations([0, 2]) is None


@settings(max_examples=60, deadline=None)
@given(sd_problems(), st.integers(0, 2 ** 32 - 1), st.booleans())
def test_violations_agrees_with_counting_each_row(p, seed, shuffle):
    """``violations`` (whose quick yes takes sorted selections) is None exactly when
    the selected candidates are distinct and cover every row once, counted here
    directly; subsets of a solution, a solution plus one, one of it swapped for a
    candidate with as many real indices (as many entries as rows), random picks."""
    rng = np.random.default_rng(seed)
    ref = solve(p, "bruteforce")
    picks = [rng.choice(p.n_candidates, size=rng.integers(0, p.n_candidates + 1),
                        replace=bool(rng.integers(2))) for _ in range(5)]
    if ref.selected is not None:
        s = ref.selected
        picks += [s, s[:-1], np.append(s, rng.integers(p.n_candidates)), np.append(s, s[:1])]
        width = (p.tuples > 0).sum(axis=1)      # swaps that keep the count of indices
        for j in range(len(s)):
            for k in np.flatnonzero(width == width[s[j]]):
                picks.append(np.append(np.delete(s, j), k))
    for sel in picks:
        sel = np.asarray(sel, np.int64)
        sel = rng.permutation(sel) if shuffle else np.sort(sel)
        count = np.zeros(p.n_rows, np.int64)
        for k in sel:
            for axis, i in enumerate(p.tuples[k]):
                if i > 0:
                    count[p.row_offsets[axis] + i - 1] += 1
        exact = len(np.unique(sel)) == len(sel) and bool((count == 1).all())
        assert (p.violations(sel) is None) == exact
