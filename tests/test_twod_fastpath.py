"""The per-scan fast paths of the dense 2-D constructors keep every check.

The constructors take the largest cost magnitude from the one min/max pass of the
validation and hand it to ``solve``'s cost-scaling test; here it is compared with an
independent computation, and the scalar miss costs (a shared constant, no array
validation) are checked to be refused where an array would be.
"""

from __future__ import annotations

import numpy as np
import pytest

from assocopt import AssignmentProblem, solve
from assocopt.runtime.errors import InvalidProblemError


def _reference_amax(*arrays: np.ndarray) -> float:
    vals = np.concatenate([np.ravel(np.asarray(a, float)) for a in arrays])
    vals = vals[np.isfinite(vals)]
    return float(np.abs(vals).max()) if vals.size else 0.0


@pytest.mark.parametrize("maximize", [False, True])
@pytest.mark.parametrize("forbid", [False, True])
@pytest.mark.parametrize("miss", ["none", "scalar", "array", "forbidden"])
def test_max_abs_cost_matches_independent_computation(maximize, forbid, miss):
    rng = np.random.default_rng(7)
    C = rng.normal(scale=50.0, size=(4, 6))
    if forbid:
        C[1, 2] = -np.inf if maximize else np.inf
    if miss == "none":
        p, parts = AssignmentProblem.dense(C, maximize=maximize), [C]
    elif miss == "scalar":
        p, parts = AssignmentProblem.two_d(C, -3.5, 120.0, maximize=maximize), \
            [C, [3.5, 120.0]]
    elif miss == "array":
        rm, cm = rng.normal(size=4) * 300, rng.normal(size=6)
        p, parts = AssignmentProblem.two_d(C, rm, cm, maximize=maximize), [C, rm, cm]
    else:
        rm = np.full(4, np.inf if not maximize else -np.inf)
        p, parts = AssignmentProblem.two_d(C, rm, 2.0, maximize=maximize), [C, [2.0]]
    assert p.dense_view.max_abs_cost() == _reference_amax(*parts)


def test_all_finite_flag_from_the_range_pass():
    C = np.arange(9.0).reshape(3, 3)
    assert AssignmentProblem.dense(C).dense_view.all_finite
    C[0, 0] = np.inf
    d = AssignmentProblem.dense(C).dense_view
    assert not d.all_finite and d.n_pairs == 8
    C[0, 0] = np.nan
    with pytest.raises(InvalidProblemError, match="NaN"):
        AssignmentProblem.dense(C)
    C[0, 0] = -np.inf
    with pytest.raises(InvalidProblemError, match="-inf"):
        AssignmentProblem.dense(C)
    C[0, 0] = 1e301
    with pytest.raises(InvalidProblemError, match="accepted range"):
        AssignmentProblem.dense(C)


@pytest.mark.parametrize("bad", [1e301, -1e301, 10 ** 400])
def test_scalar_miss_cost_out_of_range_is_refused(bad):
    with pytest.raises(InvalidProblemError, match="accepted range"):
        AssignmentProblem.two_d(np.ones((2, 2)), bad, 0.5)


def test_boolean_scalar_miss_cost_is_refused():
    with pytest.raises(InvalidProblemError, match="boolean"):
        AssignmentProblem.two_d(np.ones((2, 2)), True, 0.5)


def test_scalar_and_array_miss_costs_give_the_same_solution():
    rng = np.random.default_rng(3)
    C = rng.random((5, 7))
    a = solve(AssignmentProblem.two_d(C, 0.3, 0.4))
    b = solve(AssignmentProblem.two_d(C, np.full(5, 0.3), np.full(7, 0.4)))
    assert a.objective == b.objective
    assert np.array_equal(a.tuples, b.tuples) and np.array_equal(a.selected, b.selected)


def test_huge_costs_are_still_scaled():
    """The magnitude kept from validation triggers the exact power-of-two scaling."""
    C = np.array([[4.0, 1.0], [2.0, 3.0]]) * 1e200
    sol = solve(AssignmentProblem.dense(C))
    assert sol.objective == 3e200 and "cost_scale" in sol.info


@pytest.mark.parametrize("seed", range(40))
def test_small_and_bulk_checks_agree_on_rectangular_dense(seed):
    """The list-based check and the numpy one agree on ``dense`` problems too (the
    surplus of the larger side is free slack, never reported), forbidden entries and
    infeasible answers included."""
    rng = np.random.default_rng(seed)
    n1, n2 = rng.integers(1, 7, size=2)
    C = rng.random((n1, n2))
    C[rng.random(C.shape) < 0.2] = np.inf
    d = AssignmentProblem.dense(C).dense_view
    for _ in range(10):
        cor = rng.integers(-1, n2 + 1, size=n1)
        a, b = d._check_small(cor), d._check_bulk(cor)
        assert isinstance(a, str) == isinstance(b, str)
        if not isinstance(a, str):
            assert np.array_equal(a.selected, b.selected)
            assert np.array_equal(a.tuples, b.tuples) and a.objective == b.objective


@pytest.mark.parametrize("bad, word", [(np.nan, "is NaN"), (-np.inf, "is -inf")])
def test_a_scalar_miss_cost_is_named_as_a_scalar(bad, word):
    with pytest.raises(InvalidProblemError, match=f"^row_miss {word}"):
        AssignmentProblem.two_d(np.ones((2, 2)), bad, 1.0)
    with pytest.raises(InvalidProblemError, match=r"contains NaN \(first at index \(1,\)\)"):
        AssignmentProblem.two_d(np.ones((2, 2)), [0.5, np.nan], 1.0)
