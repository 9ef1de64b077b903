"""Paper 001's decisions: maximum-degree rule, 2-D assignment counterpart, weighted
test, and the association-quality counter with fixing."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.tracking.costs.association_degree import DegreeParams
from assocopt.tracking.decide.max_degree import (DecisionOptions, QualityCounter,
                                                 TrackAssociator, assignment_rule,
                                                 max_degree_rule, shared_columns, weighted_rule)


def _brute_best(m, eps, cost):
    """Smallest total cost over all partial one-to-one matchings (the oracle)."""
    n1, n2 = m.shape
    c = (lambda v: -np.log(v)) if cost == "neglog" else (lambda v: 1.0 - v)
    miss = c(eps) / 2
    best = np.inf
    for k in range(min(n1, n2) + 1):
        for rows in itertools.combinations(range(n1), k):
            for cols in itertools.permutations(range(n2), k):
                if any(m[r, q] <= 0 for r, q in zip(rows, cols)):
                    continue
                tot = sum(c(m[r, q]) for r, q in zip(rows, cols)) + miss * (n1 + n2 - 2 * k)
                best = min(best, tot)
    return best


@given(st.integers(1, 4), st.integers(1, 4), st.integers(0, 10 ** 6),
       st.sampled_from(["neglog", "one-minus"]))
@settings(max_examples=60, deadline=None)
def test_assignment_is_one_to_one_and_optimal(n1, n2, seed, cost):
    rng = np.random.default_rng(seed)
    m = rng.uniform(0, 1, size=(n1, n2)) * (rng.random((n1, n2)) > 0.2)
    p = assignment_rule(m, 0.5, cost)
    taken = p[p >= 0]
    assert len(set(taken.tolist())) == len(taken)                   # never two partners
    c = (lambda v: -np.log(v)) if cost == "neglog" else (lambda v: 1.0 - v)
    miss = c(0.5) / 2
    got = sum(c(m[i, j]) for i, j in enumerate(p) if j >= 0) + \
        miss * (n1 + n2 - 2 * len(taken))
    assert got == pytest.approx(_brute_best(m, 0.5, cost))


def test_max_degree_rule_may_give_one_column_two_rows():
    m = np.array([[0.8, 0.2], [0.9, 0.1], [0.3, 0.4]])
    p = max_degree_rule(m, 0.5)
    assert p.tolist() == [0, 0, -1] and shared_columns(p) == 1
    assert assignment_rule(m, 0.5).tolist() == [-1, 0, -1]
    assert assignment_rule(m, 0.5, "one-minus").tolist() == [-1, 0, -1]
    assert assignment_rule(np.zeros((2, 3)), 0.5).tolist() == [-1, -1]
    assert assignment_rule(np.zeros((0, 3)), 0.5).tolist() == []


def test_weighted_rule_gate_and_nearest():
    D = np.array([[5.0, 1.0, 20.0], [14.0, 30.0, 13.0], [np.inf, 40.0, 50.0]])
    assert weighted_rule(D, 13.28).tolist() == [1, 2, -1]


def test_options_are_checked():
    for bad in ({"rule": "x"}, {"counter": "x"}, {"cost": "x"}, {"eps": 1.0},
                {"fix_at": 0}, {"gate_alpha": 0.0}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            DecisionOptions(**bad)


# -------------------------------------------------------------------- counter
def _feed(counter, steps):
    for s in steps:
        counter.update(np.asarray(s))
    return counter


def test_counter_fixes_at_six_and_closes_the_pair():
    c = _feed(QualityCounter(2, 2, "floor", 6), [[0, -1]] * 5)
    assert c.delta[0, 0] == 5 and c.fixed.tolist() == [-1, -1]
    c.update(np.array([0, 0]))
    assert c.fixed.tolist() == [0, -1] and c.col_fixed.tolist() == [True, False]
    assert c.delta[1, 0] == 1                   # the shared column counted for row 1 too
    before = c.delta.copy()
    c.update(np.array([-1, -1]))                # closed row/column are no longer counted
    assert c.delta[0, 0] == before[0, 0] and c.delta[1, 0] == before[1, 0]
    assert c.delta[1, 1] == 0                   # floor


@pytest.mark.parametrize("semantics,expect", [("literal", [[3, -5], [-5, -5]]),
                                              ("floor", [[3, 0], [0, 0]]),
                                              ("seen", [[3, 0], [0, 0]])])
def test_counter_semantics(semantics, expect):
    steps = [[0, -1]] * 4 + [[-1, -1]] + [[0, -1]] * 0
    c = _feed(QualityCounter(2, 2, semantics, 6), steps)
    assert c.delta.tolist() == [[4 - 1, expect[0][1]], expect[1]]


def test_counter_first_association_goes_from_zero_to_one_unless_literal():
    for sem, first in (("literal", -2), ("floor", 1), ("seen", 1)):
        c = _feed(QualityCounter(1, 2, sem), [[0], [0], [0], [1]])
        assert c.delta[0, 1] == first, sem          # literal: -1, -1, -1, then +1


def test_counter_off_never_fixes():
    c = _feed(QualityCounter(1, 1, "off"), [[0]] * 10)
    assert c.fixed.tolist() == [-1] and c.delta[0, 0] == 0


def test_associator_reports_fixed_pairs_and_removes_them_from_tests():
    n = 3
    D = np.diag([0.1, 0.1, 0.1]) + 50 * (1 - np.eye(n))
    f = np.arange(3 * n, dtype=float).reshape(n, 3) * 10
    params = DegreeParams(tolerances=(1.0, 1.0, 1.0))
    for rule in ("max-degree", "assignment", "weighted"):
        a = TrackAssociator(n, n, params, DecisionOptions(rule=rule))
        outs = [a.step(D, f, f) for _ in range(7)]
        assert all(o.tolist() == [0, 1, 2] for o in outs), rule
        assert a.counter.fixed.tolist() == [0, 1, 2]
        # once fixed, even contrary evidence leaves the pairs alone
        swapped = a.step(D[:, ::-1], f, f[::-1])
        assert swapped.tolist() == [0, 1, 2]
