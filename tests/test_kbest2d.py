"""The compiled 2-D ranking (assocopt.ranking.kbest2d, kernels sap / murty2d) against brute force
and scipy: the k best objectives are the k smallest of the full enumeration, every
solution once, in a fixed order; the warm-started LAP kernel agrees with scipy."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import linear_sum_assignment

from assocopt import AssignmentProblem, kbest
from assocopt.ranking import kbest2d
from assocopt.solvers.baseline.bruteforce import enumerate_solutions
from assocopt.solvers.kernels.sap import augment, lap, lap_warm

INF = np.inf
#: entries: small integers (many ties) or forbidden
ENTRY = st.one_of(st.integers(-2, 3).map(float), st.just(INF))


@st.composite
def matrices(draw, max_n: int = 5, finite: bool = False):
    n1 = draw(st.integers(1, max_n))
    n2 = draw(st.integers(1, max_n))
    entry = st.integers(-2, 3).map(float) if finite else ENTRY
    rows = draw(st.lists(st.lists(entry, min_size=n2, max_size=n2),
                         min_size=n1, max_size=n1))
    return np.array(rows, dtype=float)


@st.composite
def two_d_problems(draw):
    """Rectangular, with or without misses (finite, partly or wholly forbidden)."""
    C = draw(matrices())
    kind = draw(st.sampled_from(["dense", "misses"]))
    if kind == "dense":
        return AssignmentProblem.dense(C) if np.isfinite(C).any() else \
            AssignmentProblem.two_d(C, 0.0, 0.0)

    def miss(n):
        how = draw(st.sampled_from(["finite", "some-inf", "all-inf", "zero"]))
        if how == "zero":
            return np.zeros(n)
        if how == "all-inf":
            return np.full(n, INF)
        vals = draw(st.lists(st.integers(-1, 3).map(float), min_size=n, max_size=n))
        m = np.array(vals)
        if how == "some-inf":
            m[draw(st.lists(st.booleans(), min_size=n, max_size=n))] = INF
        return m
    rm, cm = miss(C.shape[0]), miss(C.shape[1])
    if draw(st.booleans()):       # scores: the same problem, -inf forbids
        return AssignmentProblem.two_d(-C, -rm, -cm, maximize=True)
    return AssignmentProblem.two_d(C, rm, cm)


def _check_ranked(p: AssignmentProblem, k: int) -> None:
    ref = sorted(p.objective_of(s) for s in enumerate_solutions(p))
    r = kbest(p, k)
    assert r.solver == kbest2d.NAME
    sign = -1.0 if p.maximize else 1.0
    assert [sign * s.objective for s in r] == ref[:k]        # integers: exact
    assert len(r) == min(k, len(ref)) and r.exhausted == (len(ref) <= k)
    keys = [(sign * s.objective, s.selected.tolist()) for s in r]
    assert keys == sorted(keys)                 # ties: by candidate positions
    assert len({tuple(sel) for _, sel in keys}) == len(keys)
    for rank, s in enumerate(r, 1):
        assert p.violations(s.selected) is None
        assert p.value_of(s.selected) == s.objective
        want = p.tuples[s.selected[~p.slack[s.selected]]]
        assert s.tuples.tolist() == want.tolist()
        assert s.info["rank"] == rank and s.maximize == p.maximize
    again = kbest(p, k)
    assert [s.selected.tolist() for s in again] == [s.selected.tolist() for s in r]


@settings(max_examples=300, deadline=None)
@given(two_d_problems(), st.integers(1, 60))
def test_compiled_kbest_equals_enumeration(p, k):
    _check_ranked(p, k)


@settings(max_examples=60, deadline=None)
@given(two_d_problems(), st.integers(1, 40))
def test_compiled_kbest_on_a_candidate_list(p, k):
    q = AssignmentProblem.sparse(p.sizes, p.tuples, p.costs)
    assert q.dense_view is None
    _check_ranked(q, k)


@pytest.mark.parametrize("seed", range(3))
def test_compiled_kbest_many_solutions_with_misses(seed):
    rng = np.random.default_rng(seed)
    C = rng.integers(0, 6, (6, 5)).astype(float)
    C[rng.random(C.shape) < 0.2] = INF
    p = AssignmentProblem.two_d(C, rng.integers(0, 4, 6).astype(float), 2.0)
    _check_ranked(p, 400)


@pytest.mark.parametrize("form", ["plain", "dense-rect", "misses", "forced-rows",
                                  "augmented"])
def test_compiled_kbest_equals_the_generic_path_on_deeper_trees(form):
    """8 x 9 problems (too many solutions to enumerate), k = 150, each LAP form:
    the same objectives as the generic path with scipy per subproblem."""
    rng = np.random.default_rng(len(form))
    C = rng.integers(0, 8, (8, 9)).astype(float)
    C[rng.random(C.shape) < 0.25] = INF
    rm, cm = rng.integers(0, 6, 8).astype(float), rng.integers(0, 6, 9).astype(float)
    if form == "plain":
        p = AssignmentProblem.dense(C[:, :8])
    elif form == "dense-rect":
        p = AssignmentProblem.dense(C)
    elif form == "misses":
        p = AssignmentProblem.two_d(C, rm, cm)
    elif form == "forced-rows":
        p = AssignmentProblem.two_d(C, np.where(np.arange(8) < 4, INF, rm), cm)
    else:
        p = AssignmentProblem.two_d(C, np.where(np.arange(8) < 3, INF, rm),
                                    np.where(np.arange(9) < 3, INF, cm))
    fast, slow = kbest(p, 150), kbest(p, 150, "scipy-lsa")
    assert fast.solver == kbest2d.NAME and len(fast) == len(slow) == 150
    assert fast.objectives == pytest.approx(slow.objectives, abs=1e-9)
    assert len({tuple(s.selected.tolist()) for s in fast}) == len(fast)
    assert all(p.violations(s.selected) is None for s in fast)


def test_k_beyond_the_count_returns_all_and_says_exhausted():
    p = AssignmentProblem.two_d(np.array([[1.0, INF], [2.0, 3.0]]), [INF, 1.0], 1.0)
    n = sum(1 for _ in enumerate_solutions(p))
    r = kbest(p, n + 5)
    assert len(r) == n and r.exhausted
    assert not kbest(p, n - 1).exhausted and kbest(p, n).exhausted


def test_infeasible_problem_gives_nothing():
    r = kbest(AssignmentProblem.dense(np.array([[1.0, INF], [2.0, INF]])), 4)
    assert len(r) == 0 and r.exhausted and r.solver == kbest2d.NAME


def test_generic_path_without_numba_and_for_named_solvers(monkeypatch):
    p = AssignmentProblem.two_d(np.random.default_rng(3).random((4, 5)), 0.3, 0.4)
    fast = kbest(p, 30)
    assert kbest(p, 30, "scipy-lsa").solver == "scipy-lsa"
    monkeypatch.setattr(kbest2d, "available", lambda: False)
    slow = kbest(p, 30)
    assert slow.solver == "scipy-lsa"
    assert fast.objectives == pytest.approx(slow.objectives, abs=1e-12)


# ------------------------------------------------------------------ the LAP kernel
def _scipy(A):
    try:
        r, c = linear_sum_assignment(A)
    except ValueError:
        return None
    return float(A[r, c].sum())


def _assert_certificate(A, x, u, v):
    """Reduced costs >= 0, 0 on the pairs, the free columns at the largest v."""
    R = A - u[:, None] - v[None, :]
    fin = np.isfinite(A)
    assert (R[fin] >= -1e-9).all()
    assert np.abs(R[np.arange(len(x)), x]).max(initial=0.0) <= 1e-9
    free = np.setdiff1d(np.arange(A.shape[1]), x)
    if len(free):
        assert v[free] == pytest.approx(np.full(len(free), v.max()), abs=1e-9)


def _oriented(A):
    return A if A.shape[0] <= A.shape[1] else A.T.copy()


@settings(max_examples=200, deadline=None)
@given(matrices(7), st.booleans())
def test_lap_kernel_equals_scipy(A, floats):
    if floats:
        A = np.where(np.isfinite(A), A + np.random.default_rng(A.size).random(A.shape), A)
    A = _oriented(A)
    ok, x, u, v, cost = lap(A)
    ref = _scipy(A)
    assert ok == (ref is not None)
    if ok:
        assert cost == pytest.approx(ref, abs=1e-9) and len(set(x.tolist())) == len(x)
        _assert_certificate(A, x, u, v)


@settings(max_examples=200, deadline=None)
@given(matrices(7), st.data())
def test_warm_lap_after_forbidding_a_pair_equals_scipy(A, data):
    """Solve, forbid one chosen pair, re-solve by one augmentation to the freed column
    (Murty's child), and compare with scipy on the changed matrix."""
    A = _oriented(A)
    ok, x, u, v, _ = lap(A)
    if not ok:
        return
    i = data.draw(st.integers(0, len(x) - 1))
    c = int(x[i])
    y = np.full(A.shape[1], -1, np.int64)
    y[x] = np.arange(len(x))
    B = A.copy()
    B[i, c] = INF
    x[i], y[c] = -1, -1
    nc = B.shape[1]
    work = (np.empty(nc), np.empty(nc, np.int64), np.zeros(nc, bool), np.empty(nc, np.int64))
    delta = augment(B, i, c, x, y, u, v, np.arange(nc), nc, *work)
    ref = _scipy(B)
    assert (delta < INF) == (ref is not None)
    if ref is not None:
        assert float(B[np.arange(len(x)), x].sum()) == pytest.approx(ref, abs=1e-9)
        _assert_certificate(B, x, u, v)


@settings(max_examples=150, deadline=None)
@given(matrices(7, finite=True), st.data())
def test_warm_lap_from_a_partial_assignment_equals_scipy(A, data):
    """Rows ``0..m-1`` solved first; their state warm-starts the whole matrix."""
    A = _oriented(A)
    m = data.draw(st.integers(1, A.shape[0]))
    ok, x0, u0, v, _ = lap(A[:m])
    assert ok
    x = np.full(A.shape[0], -1, np.int64)
    x[:m] = x0
    y = np.full(A.shape[1], -1, np.int64)
    y[x0] = np.arange(m)
    u = np.zeros(A.shape[0])
    u[:m] = u0
    u[m:] = (A[m:] - v[None, :]).min(axis=1)     # feasible start for the new rows
    assert lap_warm(A, x, y, u, v)
    assert float(A[np.arange(len(x)), x].sum()) == pytest.approx(_scipy(A), abs=1e-9)
    _assert_certificate(A, x, u, v)


def test_times_report_total_and_kernel_preparation_apart():
    r = kbest(AssignmentProblem.two_d(np.eye(3), 0.5, 0.5), 5)
    assert set(r.times) <= {"total", "compile", "cache_load"} and r.times["total"] > 0
    assert r.to_dict()["solver"] == kbest2d.NAME and r.to_dict()["found"] == 5


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 6), st.integers(1, 6), st.data())
def test_form_entries_is_the_size_lap_form_allocates(n1, n2, data):
    rm = np.array(data.draw(st.lists(st.sampled_from([1.0, np.inf]), min_size=n1,
                                     max_size=n1)))
    cm = np.array(data.draw(st.lists(st.sampled_from([1.0, np.inf]), min_size=n2,
                                     max_size=n2)))
    form = kbest2d.lap_form(np.ones((n1, n2)), rm, cm)
    if form is not None:
        assert kbest2d.form_entries(rm, cm) == form.A.size


def test_size_cap_applies_to_the_form_built_not_the_augmentation(monkeypatch):
    """A 10 x 10 problem with every miss allowed ranks on a 10 x 20 form (200 entries),
    not on the 20 x 20 augmentation: under a 300-entry cap it still takes the compiled
    path; with a mandatory row and column (the augmentation) it does not."""
    monkeypatch.setattr(kbest2d, "MAX_FORM_ENTRIES", 300)
    C = np.random.default_rng(5).random((10, 10))
    free = kbest(AssignmentProblem.two_d(C, 0.3, 0.3), 4)
    assert free.solver == "murty2d"
    miss = np.full(10, 0.3)
    miss[0] = np.inf                      # row 1 and column 1 must be assigned
    tight = kbest(AssignmentProblem.two_d(C, miss, miss), 4)
    assert tight.solver != "murty2d"
    generic = kbest(AssignmentProblem.two_d(C, 0.3, 0.3), 4, solver="scipy-lsa")
    assert np.allclose(free.objectives, generic.objectives)


def test_guide_states_the_compiled_ranking_size_cap():
    from pathlib import Path

    guide = (Path(__file__).resolve().parents[1] / "docs" / "guide.md").read_text()
    text = " ".join(guide.split())
    assert kbest2d.MAX_FORM_ENTRIES == 8_000_000 and "at most 8 million entries" in text
    assert "e.g. 2000 x 2000 when every track and measurement may stay unassigned" in text
    miss = np.ones(2000)
    assert kbest2d.form_entries(miss, miss) <= kbest2d.MAX_FORM_ENTRIES
    assert kbest2d.form_entries(np.ones(2001), np.ones(2001)) > kbest2d.MAX_FORM_ENTRIES
