"""The direct route of dense 2-D problems gives the general route's Solution.

:func:`assocopt.solve` answers dense 2-D problems with default options through
:mod:`assocopt.solvers.twod.direct`; here every field of its Solution is compared with the
general route's (forced by switching the direct route off) on random problems:
rectangular, with and without misses, forbidden entries and misses, maximisation,
integer costs with many ties, and infeasible ones (which the direct route hands back).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from assocopt import AssignmentProblem, Status, solve
from assocopt.solving import api
from assocopt.solvers.twod import direct as direct2d
from assocopt.problems.values import _as_matrix


def _general(problem: AssignmentProblem, monkeypatch) -> object:
    with monkeypatch.context() as m:
        m.setattr(api, "_DIRECT", lambda problem, d, t0: None)
        return solve(problem)


def _same(a, b) -> None:
    assert a.status is b.status
    for name in ("objective", "bound", "solver", "solver_version", "message",
                 "relaxation", "integral", "maximize"):
        assert getattr(a, name) == getattr(b, name), name
    for name in ("selected", "tuples", "x"):
        va, vb = getattr(a, name), getattr(b, name)
        assert (va is None) == (vb is None), name
        if va is not None:
            assert va.dtype == vb.dtype and np.array_equal(va, vb), name
    assert a.info == b.info
    # the first solve of a process also records its back end's import time
    assert set(a.times) - {"import"} == set(b.times) - {"import"}


@st.composite
def twod_problems(draw) -> AssignmentProblem:
    big = draw(st.sampled_from([9, 9, 9, 40]))       # 40: past the list split
    n1, n2 = draw(st.integers(1, big)), draw(st.integers(1, big))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    rng = np.random.default_rng(seed)
    ties = draw(st.booleans())
    C = rng.integers(0, 4, (n1, n2)).astype(float) if ties else rng.random((n1, n2))
    if draw(st.booleans()):
        C[rng.random(C.shape) < draw(st.sampled_from([0.1, 0.5]))] = np.inf
    maximize = draw(st.booleans())
    miss = draw(st.sampled_from(["dense", "both", "rows", "cols", "partial"]))
    if miss == "dense":
        p_args = ()
    else:
        rm = rng.integers(0, 3, n1).astype(float) if ties else rng.random(n1)
        cm = rng.integers(0, 3, n2).astype(float) if ties else rng.random(n2)
        if miss == "rows":
            cm = None
        elif miss == "cols":
            rm = None
        elif miss == "partial":
            rm[rng.random(n1) < 0.5] = np.inf
            cm[rng.random(n2) < 0.5] = np.inf
        p_args = (rm, cm)
    if maximize:
        C = -C
        p_args = tuple(None if v is None else -v for v in p_args)
    if not p_args:
        return AssignmentProblem.dense(C, maximize=maximize)
    return AssignmentProblem.two_d(C, *p_args, maximize=maximize)


@settings(max_examples=400, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(twod_problems())
def test_direct_route_equals_general_route(monkeypatch, p):
    _same(solve(p), _general(p, monkeypatch))


@pytest.mark.parametrize("case", ["square", "clipped", "other"])
def test_each_branch_is_taken_and_agrees(monkeypatch, case):
    """The two written-out branches really run (a spy counts them) and agree."""
    rng = np.random.default_rng(5)
    if case == "square":
        p, branch = AssignmentProblem.dense(rng.random((7, 7))), "_square"
    elif case == "clipped":
        p, branch = AssignmentProblem.two_d(rng.random((6, 8)), rng.random(6),
                                            rng.random(8)), "_clipped"
    else:
        p, branch = AssignmentProblem.two_d(rng.random((8, 6)), 0.4, 0.4), "assign_dense"
    calls = []
    real = getattr(direct2d, branch)

    def spy(*args, **kw):
        calls.append(1)
        return real(*args, **kw)

    with monkeypatch.context() as m:
        m.setattr(direct2d, branch, spy)
        fast = solve(p)
    assert calls == [1]
    _same(fast, _general(p, monkeypatch))


def test_infeasible_problem_is_reported_by_the_general_route(monkeypatch):
    C = np.array([[1.0, np.inf], [2.0, np.inf]])     # column 1 must be met by nobody
    p = AssignmentProblem.two_d(C, None, np.array([0.5, np.inf]))
    sol = solve(p)
    assert sol.status is Status.INFEASIBLE
    _same(sol, _general(p, monkeypatch))


def test_a_wrong_lap_answer_is_not_trusted(monkeypatch):
    """A LAP answer that repeats a column is refused by the re-check (the general
    route then reports the back end's failure)."""
    p = AssignmentProblem.two_d(np.zeros((3, 3)), 5.0, 5.0)

    def broken(R):
        return np.arange(3), np.zeros(3, np.int64)

    monkeypatch.setattr(direct2d, "_lsa", broken)
    assert direct2d.solve_direct(p, p.dense_view, 0.0) is None


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64),
                min_size=1, max_size=30))
def test_range_bound_from_the_sum_of_squares(values):
    """The one-pass validation: accepted exactly when every entry is finite and within
    1e300 (or +inf, forbidden); the bound it keeps is at least the largest magnitude."""
    arr = np.array(values)
    finite = arr[np.isfinite(arr)]
    bad = np.isnan(arr).any() or np.isneginf(arr).any() or \
        (finite.size and np.abs(finite).max() > 1e300)
    if bad:
        with pytest.raises(Exception):
            _as_matrix(arr, "x", False)
        return
    out, all_finite, bound = _as_matrix(arr, "x", False)
    assert np.array_equal(out, arr) and all_finite == bool(np.isfinite(arr).all())
    if all_finite:
        assert bound >= np.abs(arr).max()
        assert bound <= math.sqrt(arr.size) * np.abs(arr).max() * (1 + 1e-5) + 1e-149


def test_scaling_still_triggers_just_above_the_threshold():
    """The bound never hides a magnitude above 2**50: such costs never reach the back
    end as they are (here set aside as unused big-M; needed, they are scaled)."""
    C = np.array([[2.0 ** 51, 1.0], [1.0, 2.0 ** 51]])
    sol = solve(AssignmentProblem.dense(C))
    assert sol.info["big_m"]["set_aside"] == 2 and sol.objective == 2.0
    C = np.array([[2.0 ** 51, 2.0 ** 51], [1.0, 2.0]])
    sol = solve(AssignmentProblem.dense(C))
    assert "cost_scale" in sol.info and sol.objective == 2.0 ** 51 + 1.0
    C = np.array([[2.0 ** 49, 1.0], [1.0, 2.0 ** 49]])
    info = solve(AssignmentProblem.dense(C)).info
    assert "cost_scale" not in info and "big_m" not in info


@pytest.mark.parametrize("n1, n2, miss", [(150, 150, False), (120, 200, False),
                                          (60, 90, True), (200, 130, True)])
def test_larger_problems_agree(monkeypatch, n1, n2, miss):
    """Beyond the list split: the square branch and the general check at size."""
    rng = np.random.default_rng(n1 + n2)
    C = rng.random((n1, n2))
    if n1 != n2:                     # the square one stays all finite: its own branch
        C[rng.random(C.shape) < 0.05] = np.inf
        C[np.arange(min(n1, n2)), np.arange(min(n1, n2))] = 0.5     # stay feasible
    p = AssignmentProblem.two_d(C, rng.random(n1), rng.random(n2)) if miss else \
        AssignmentProblem.dense(C)
    _same(solve(p), _general(p, monkeypatch))
