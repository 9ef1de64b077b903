"""One conformance suite run against every installed back end.

Every exact back end must equal brute force on random small problems of every
family (2-D square / rectangular / with miss costs, axial 3-D and 4-D, S-D with
dummies), agree on known cases, detect infeasibility, handle empty problems and
leave the input untouched.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from assocopt import AssignmentProblem, SolverCapabilityError, Status, solve
from assocopt.solvers import registered
from assocopt.testing import KINDS, assert_feasible, assert_optimal, problems

from conftest import EXACT, LP, installed


def _kinds_for(name: str) -> tuple[str, ...]:
    if registered()[name].max_ndim == 2:
        return ("square", "rect", "miss")
    return KINDS


@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_exact_backend_equals_brute_force(name):
    integer = None if registered()[name].exact_float_costs else True

    @given(problems(_kinds_for(name), integer=integer))
    def check(p):
        assert_optimal(p, solve(p, name))
    check()


@pytest.mark.parametrize("name", [installed(n) for n, cls in registered().items()
                                  if cls.exact and not cls.exact_float_costs])
def test_scaled_backend_within_its_reported_bound_on_float_costs(name):
    @given(problems(_kinds_for(name), integer=False))
    def check(p):
        sol = solve(p, name)
        ref = solve(p, "bruteforce").objective
        assert sol.status in (Status.OPTIMAL, Status.FEASIBLE), sol.message
        assert_feasible(p, sol)
        assert sol.bound is not None and sol.bound <= ref + 1e-9
        assert sol.objective - ref <= sol.objective - sol.bound + 1e-9
    check()


@pytest.mark.parametrize("name", [installed(n) for n in LP])
def test_lp_bound_below_ilp_optimum(name):
    @given(problems())
    def check(p):
        lp = solve(p, name, relax="lp")
        ilp = solve(p, "bruteforce")
        assert lp.status is Status.OPTIMAL, lp.message
        assert lp.relaxation == "lp" and lp.x is not None
        assert lp.objective <= ilp.objective + 1e-7 * max(1.0, abs(ilp.objective))
        if lp.integral:   # an integral LP optimum is an ILP optimum
            assert_feasible(p, lp)
            assert lp.objective == pytest.approx(ilp.objective, rel=1e-7, abs=1e-7)
    check()


@given(problems())
def test_greedy_is_feasible_and_never_below_optimum(p):
    g = solve(p, "greedy")
    assert g.status is Status.FEASIBLE, g.message
    assert_feasible(p, g)
    assert g.bound is None
    assert g.objective >= solve(p, "bruteforce").objective - 1e-9


def test_brute_force_counts_every_solution():
    from assocopt.solvers.bruteforce import count_solutions
    assert count_solutions(AssignmentProblem.dense(np.zeros((4, 4)))) == 24
    assert count_solutions(AssignmentProblem.dense(np.zeros((3, 3, 3)))) == 36
    # 2 targets, 3 sensors with dummies allowed: every partition of the measurements
    T = np.array([t for t in np.ndindex(3, 3, 3) if any(t)])
    assert count_solutions(AssignmentProblem.sparse((2, 2, 2), T, np.zeros(len(T)))) > 4
    # paper 002 with P_D = 1: only full tuples -> (2!)^2 = 4 feasible solutions
    full = np.array([t for t in np.ndindex(3, 3, 3) if all(t)])
    assert count_solutions(AssignmentProblem.sparse((2, 2, 2), full, np.zeros(len(full)))) == 4


KNOWN = [
    # (problem, optimum, chosen tuples): hand-checked small cases
    (AssignmentProblem.dense([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]]), 5.0,
     [[1, 2], [2, 1], [3, 3]]),
    (AssignmentProblem.two_d([[10.0, 10.0]], row_miss=[1.0], col_miss=[2.0, 3.0]), 6.0,
     [[1, 0], [0, 1], [0, 2]]),
    (AssignmentProblem.two_d([[1.0, np.inf], [np.inf, np.inf]], row_miss=5.0, col_miss=5.0),
     11.0, [[1, 1], [2, 0], [0, 2]]),
    (AssignmentProblem.dense([[[1.0, 9.0], [9.0, 9.0]], [[9.0, 9.0], [9.0, 1.0]]]), 2.0,
     [[1, 1, 1], [2, 2, 2]]),
]


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce"]])
@pytest.mark.parametrize("case", range(len(KNOWN)))
def test_known_small_cases(name, case):
    p, opt, tuples = KNOWN[case]
    if registered()[name].max_ndim == 2 and p.ndim > 2:
        pytest.skip("2-D back end")
    sol = solve(p, name)
    assert sol.status is Status.OPTIMAL, sol.message
    assert sol.objective == opt
    assert sorted(sol.tuples.tolist()) == sorted(tuples)


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce"]])
def test_structurally_infeasible(name):
    # rows and columns must all be covered, but 3 rows cannot meet 2 columns
    p = AssignmentProblem.sparse((3, 2), [[1, 1], [2, 2], [3, 1], [3, 2]], [1, 1, 1, 1])
    sol = solve(p, name)
    assert sol.status is Status.INFEASIBLE, sol.message
    assert sol.objective is None and sol.tuples is None


@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_uncovered_index_is_named(name):
    p = AssignmentProblem.sparse((2, 2), [[1, 1], [2, 1]], [1.0, 2.0])
    sol = solve(p, name)
    assert sol.status is Status.INFEASIBLE
    assert "real index 2 (1-based) of axis 1" in sol.message


@pytest.mark.parametrize("name", [installed(n) for n in EXACT + ["bruteforce", "greedy"]])
def test_empty_problem(name):
    sol = solve(AssignmentProblem.dense(np.zeros((0, 0))), name)
    assert sol.status is Status.OPTIMAL and sol.objective == 0 and len(sol.tuples) == 0


@pytest.mark.parametrize("name", [installed(n) for n in EXACT])
def test_input_not_modified(name):
    rng = np.random.default_rng(7)
    T = np.array([t for t in np.ndindex(3, 3, 3) if any(t)])
    c = rng.normal(size=len(T))
    T0, c0 = T.copy(), c.copy()
    if registered()[name].max_ndim == 2:
        C = rng.random((3, 4))
        C0 = C.copy()
        solve(AssignmentProblem.two_d(C, row_miss=0.5, col_miss=0.5), name)
        assert (C == C0).all()
        return
    solve(AssignmentProblem.sparse((2, 2, 2), T, c), name)
    assert (T == T0).all() and (c == c0).all()


@pytest.mark.parametrize("name", [installed(n) for n in LP])
def test_lp_relaxation_can_be_fractional(name):
    # 3-AP, n = 2: the four zero-cost tuples cover every index twice but no two of
    # them are disjoint, so x = 1/2 on each gives LP = 0 while every integer
    # solution uses a tuple of cost 10.
    zero = [[1, 1, 1], [1, 2, 2], [2, 1, 2], [2, 2, 1]]
    rest = [list(t) for t in np.ndindex(3, 3, 3) if all(t) and list(t) not in zero]
    p = AssignmentProblem.sparse((2, 2, 2), zero + rest, [0.0] * 4 + [10.0] * len(rest))
    assert solve(p, "bruteforce").objective == 10.0
    lp = solve(p, name, relax="lp")
    assert lp.status is Status.OPTIMAL
    assert lp.objective == pytest.approx(0.0, abs=1e-9)
    assert lp.integral is False
    assert lp.tuples is None and lp.selected is None
    assert lp.x[:4] == pytest.approx([0.5] * 4, abs=1e-6)


def test_two_d_only_backend_refuses_3d():
    p = AssignmentProblem.dense(np.ones((2, 2, 2)))
    with pytest.raises(SolverCapabilityError, match="at most 2 axes"):
        solve(p, "scipy-lsa")


def test_lp_only_request_on_ilp_only_backend():
    with pytest.raises(SolverCapabilityError, match="cannot solve LP"):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "bruteforce", relax="lp")


def test_unknown_solver_lists_valid_names():
    from assocopt import UnknownSolverError
    with pytest.raises(UnknownSolverError, match="valid names: .*highs"):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "cplexx")


@pytest.mark.parametrize("kw, match", [
    ({"time_limit": -1}, "time_limit"), ({"mip_gap": -0.1}, "mip_gap"),
    ({"threads": 0}, "threads"), ({"relax": "qp"}, "relax"),
])
def test_bad_options(kw, match):
    from assocopt import InvalidProblemError
    with pytest.raises(InvalidProblemError, match=match):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "highs", **kw)


def test_auto_picks_fast_path_in_2d_and_an_exact_method_otherwise():
    assert solve(AssignmentProblem.dense(np.ones((3, 3))), "auto").solver == "scipy-lsa"
    p = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
    sol = solve(p, "auto")
    assert registered()[sol.solver].exact
    assert_optimal(p, sol)
    assert solve(p, "auto", relax="lp").solver == "highs"


def test_solution_reports_times_and_version():
    sol = solve(AssignmentProblem.dense(np.ones((3, 3, 3))), "highs")
    assert set(sol.times) >= {"build", "solve", "total"}
    assert sol.solver_version
    d = sol.to_dict()
    assert d["status"] == "optimal" and d["time_s"] == sol.times["total"]
