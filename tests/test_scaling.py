"""Costs beyond 2**50: big-M penalties set aside when provably unused, else scaling.

Every exact back end is compared with an independent oracle (every feasible solution
enumerated and priced by ``math.fsum``) on small problems in which some costs are huge:
written as "forbidden" (not needed by the optimum) or needed for feasibility.  A claim
of optimality must give the oracle's objective, and a bound must never exceed it, to
within the floating-point resolution of the objective itself (1e-9 of its magnitude:
with a cost of 2**51 in the optimum, 5 and 6 added to it differ by 4e-16 of it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt import AssignmentProblem, Status, solve
from assocopt.solvers import registered
from assocopt.solvers.scaling import SCALE_ABOVE
from assocopt.solvers.baseline.bruteforce import enumerate_solutions

EXACT = sorted(n for n, c in registered().items()
               if c.exact and c.integer and c.is_available()
               and n not in ("bruteforce", "greedy"))


def _oracle(p: AssignmentProblem) -> float:
    return min(math.fsum(p.costs[s].tolist()) for s in enumerate_solutions(p))


@st.composite
def big_m_problems(draw) -> AssignmentProblem:
    ndim = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(2, 4))
    rng = np.random.default_rng(draw(st.integers(0, 2 ** 32 - 1)))
    C = rng.integers(0, 10, (n,) * ndim).astype(float)
    big = draw(st.sampled_from([2.0 ** 51, 1e16, 1e20, 1e100, 1e300]))
    share = draw(st.sampled_from([0.05, 0.3, 0.8]))
    C[rng.random(C.shape) < share] = big
    if draw(st.booleans()):               # a row of big costs only: big-M is needed
        C[0] = big
    return AssignmentProblem.dense(C)


@pytest.mark.parametrize("solver", EXACT)
@settings(max_examples=25, deadline=None)
@given(p=big_m_problems())
def test_claims_hold_with_huge_costs(solver, p):
    most = registered()[solver].max_ndim
    if most is not None and len(p.sizes) > most:
        return
    best = _oracle(p)
    sol = solve(p, solver)
    assert sol.has_solution
    slack = 1e-9 * abs(best)
    if sol.status is Status.OPTIMAL:
        assert abs(sol.objective - best) <= slack
        if abs(best) < SCALE_ABOVE:            # no huge cost in the optimum: exact
            assert sol.objective == best
    if sol.bound is not None:
        assert sol.bound <= best + slack + 1e-9


def test_unused_big_m_is_set_aside_and_recorded():
    C = np.random.default_rng(0).integers(0, 10, (4, 4)).astype(float)
    C[0, 0] = 1e20                                    # "forbidden" written as big-M
    p = AssignmentProblem.dense(C)
    for solver in ("highs", "scipy", "lagrangian-exact"):
        sol = solve(p, solver)
        assert sol.status is Status.OPTIMAL and sol.objective == _oracle(p)
        assert sol.info["big_m"]["set_aside"] == 1 and "cost_scale" not in sol.info
        assert sol.selected.max() < p.n_candidates and p.violations(sol.selected) is None


def test_needed_big_m_is_scaled():
    """When the big costs cannot all be avoided the exact scaling is used."""
    C = np.ones((3, 3))
    C[0] = 1e300                                      # row 0 has only huge costs
    sol = solve(AssignmentProblem.dense(C), "highs")
    assert "cost_scale" in sol.info and "big_m" not in sol.info
    assert sol.objective == 1e300 + 2.0 and sol.status is Status.OPTIMAL


def test_huge_negative_costs_are_never_set_aside():
    C = np.ones((3, 3))
    C[1, 2] = -1e200
    sol = solve(AssignmentProblem.dense(C), "highs")
    assert "big_m" not in sol.info and sol.objective == -1e200 + 2.0
