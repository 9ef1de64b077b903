"""maximize=True: every back end answers the maximisation as the minimisation of the
negated scores, with objective and bound reported in the scores' sense."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

from assocopt import AssignmentProblem, InvalidProblemError, Status, solve
from assocopt.solvers import registered
from assocopt.testing import KINDS, problems

from conftest import LP, installed

ALL = sorted(n for n, cls in registered().items() if cls.integer)


def as_scores(p: AssignmentProblem) -> AssignmentProblem:
    """The same problem given as scores (negated costs) with ``maximize=True``."""
    if p.kind == "dense":
        return AssignmentProblem.dense(-p.to_cost_matrix(), maximize=True)
    if p.kind == "two_d":
        rm, cm = p.miss_costs()
        return AssignmentProblem.two_d(-p.to_cost_matrix(), -rm, -cm, maximize=True)
    return AssignmentProblem.sparse(p.sizes, p.tuples, -p.costs, maximize=True)


def _kinds_for(name: str) -> tuple[str, ...]:
    return ("square", "rect", "miss") if registered()[name].max_ndim == 2 else KINDS


#: back ends whose choice among equally good solutions may change from run to run
#: (CP-SAT searches with several workers in parallel)
TIES_MAY_DIFFER = {"ortools-cpsat"}


@pytest.mark.parametrize("name", [installed(n) for n in ALL])
def test_maximize_equals_minimising_the_negated_scores(name):
    integer = None if registered()[name].exact_float_costs else True

    @settings(max_examples=12)
    @given(problems(_kinds_for(name), integer=integer))
    def check(p):
        q = as_scores(p)
        assert q.maximize and np.array_equal(np.sort(q.costs), np.sort(p.costs))
        lo, hi = solve(p, name), solve(q, name)
        assert hi.status == lo.status and hi.maximize and not lo.maximize
        if lo.objective is None:
            assert hi.objective is None
            return
        assert hi.objective == pytest.approx(-lo.objective, abs=1e-9)
        # the same choice, up to ties: hi's tuples (same candidate order in q and p) cost
        # lo's optimum under p's costs (multi-worker CP-SAT may break ties differently)
        assert float(np.sum(p.costs[np.asarray(hi.selected)])) == pytest.approx(
            lo.objective, abs=1e-9)
        if name in TIES_MAY_DIFFER:
            return
        assert sorted(map(tuple, hi.tuples.tolist())) == sorted(map(tuple, lo.tuples.tolist()))
        if lo.bound is not None:
            assert hi.bound == pytest.approx(-lo.bound, abs=1e-9)
            assert hi.bound >= hi.objective - 1e-9          # an upper bound
            assert hi.gap == pytest.approx(lo.gap, abs=1e-12)
    check()


@pytest.mark.parametrize("name", [installed(n) for n in LP])
def test_maximize_lp_relaxation(name):
    p = AssignmentProblem.dense(np.random.default_rng(3).random((3, 3, 3)))
    lo, hi = solve(p, name, relax="lp"), solve(as_scores(p), name, relax="lp")
    assert hi.objective == pytest.approx(-lo.objective, abs=1e-7)
    assert hi.bound >= hi.objective - 1e-9


def test_maximize_matches_scipy():
    from scipy.optimize import linear_sum_assignment

    S = np.random.default_rng(0).random((6, 9))
    r, c = linear_sum_assignment(S, maximize=True)
    sol = solve(AssignmentProblem.dense(S, maximize=True))
    assert sol.objective == pytest.approx(S[r, c].sum())
    assert sol.bound == pytest.approx(sol.objective) and sol.to_dict()["maximize"]


def test_maximize_forbids_minus_inf_and_rejects_plus_inf():
    S = np.array([[1.0, -np.inf], [2.0, 5.0]])
    sol = solve(AssignmentProblem.dense(S, maximize=True))
    assert sol.status is Status.OPTIMAL and sol.objective == 6.0
    with pytest.raises(InvalidProblemError, match=r"\+inf .*-inf means forbidden"):
        AssignmentProblem.dense([[np.inf, 1.0], [1.0, 1.0]], maximize=True)
    with pytest.raises(InvalidProblemError, match="-inf"):
        AssignmentProblem.dense([[-np.inf, 1.0], [1.0, 1.0]])


def test_testing_helpers_understand_maximize():
    from assocopt.testing import assert_optimal, assert_valid_bound, random_problem

    p = as_scores(random_problem(np.random.default_rng(2), "sd", sizes=(3, 3, 2)))
    sol = solve(p, "highs")
    assert_optimal(p, sol)
    assert_valid_bound(p, solve(p, "highs", relax="lp"))
