"""Every decision rule of ``assocopt.tracking.decide`` on unequal, empty and all-fixed
sides: it never raises, gives each track at most one partner (an index in range or -1),
and the one-to-one rules never give one partner to two tracks.

The paper-001 associator once raised IndexError when every node-2 track was fixed
while node-1 tracks were still open (2 x 1 tracks at scan 6); these tests drive every
rule through such cases.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st

from assocopt.tracking.costs.association_degree import DegreeParams
from assocopt.tracking.decide.did import DIDParams, did_decide
from assocopt.tracking.decide.double_threshold import DoubleThreshold, IRRule
from assocopt.tracking.decide.max_degree import (COUNTER_SEMANTICS, RULES, DecisionOptions,
                                                 TrackAssociator, assignment_rule,
                                                 max_degree_rule, weighted_rule)
from assocopt.tracking.decide.md2da import md_2da
from assocopt.tracking.decide.multi_node import three_node_decision
from assocopt.tracking.decide.nearest import gnn_assign, nearest_neighbour
from assocopt.tracking.decide.topology import LARGE, trial_pairs
from assocopt.tracking.decide.truncation import md_nd

sizes = st.integers(0, 5)
seeds = st.integers(0, 2 ** 32 - 1)
SETTINGS = settings(max_examples=40, deadline=None)


def _partners_ok(p, n_rows: int, n_cols: int, one_to_one: bool) -> None:
    p = np.asarray(p)
    assert p.shape == (n_rows,)
    assert np.all((p >= -1) & (p < n_cols))
    if one_to_one:
        taken = p[p >= 0]
        assert len(np.unique(taken)) == len(taken)


def _degrees(rng, n1, n2):
    m = rng.uniform(0, 1, size=(n1, n2)) * (rng.random((n1, n2)) > 0.2)
    if n1 and n2 and rng.random() < 0.3:
        m[:] = m[0, 0]                                                    # ties everywhere
    return m


@given(sizes, sizes, seeds)
@SETTINGS
def test_single_step_rules(n1, n2, seed):
    rng = np.random.default_rng(seed)
    m = _degrees(rng, n1, n2)
    _partners_ok(max_degree_rule(m, 0.5), n1, n2, one_to_one=False)       # paper's: may share
    for cost in ("neglog", "one-minus"):
        _partners_ok(assignment_rule(m, 0.5, cost), n1, n2, one_to_one=True)
    D = rng.exponential(10.0, size=(n1, n2))
    _partners_ok(weighted_rule(D, 13.28), n1, n2, one_to_one=False)
    _partners_ok(gnn_assign(D, 12.0), n1, n2, one_to_one=True)
    _partners_ok(nearest_neighbour(D, 12.0), n2, n1, one_to_one=False)  # per track (column)
    phi = np.where(rng.random((n1, n2)) < 0.3, LARGE, D)
    _partners_ok(trial_pairs(phi, "row"), n1, n2, one_to_one=False)
    _partners_ok(trial_pairs(phi, "assignment"), n1, n2, one_to_one=True)


@given(sizes, sizes, seeds, st.sampled_from(RULES), st.sampled_from(COUNTER_SEMANTICS),
       st.integers(1, 3))
@SETTINGS
def test_track_associator_unequal_and_all_fixed_sides(n1, n2, seed, rule, counter, fix_at):
    """Constant evidence for ``fix_at + 3`` scans: pairs get fixed until one side runs out."""
    rng = np.random.default_rng(seed)
    D = 100.0 + rng.exponential(5.0, size=(n1, n2))
    k = min(n1, n2)
    D[np.arange(k), np.arange(k)] = 0.01                  # track i of both nodes: one emitter
    f1 = rng.normal(size=(n1, 3)) * 0.01
    f2 = rng.normal(size=(n2, 3)) * 0.01
    a = TrackAssociator(n1, n2, DegreeParams(tolerances=(1.0, 1.0, 1.0)),
                        DecisionOptions(rule=rule, counter=counter, fix_at=fix_at))
    for _ in range(fix_at + 3):
        p = a.step(D, f1, f2)
        _partners_ok(p, n1, n2, one_to_one=(rule == "assignment"))
        fixed = a.counter.fixed
        _partners_ok(fixed, n1, n2, one_to_one=True)                      # fixed pairs: 1-1
        assert np.all(p[fixed >= 0] == fixed[fixed >= 0])
    if counter != "off":
        # decisive evidence for the first min(n1, n2) pairs: the counter fixes them and
        # the larger side keeps open tracks with no open partner (the old crash case)
        assert a.counter.fixed[:k].tolist() == list(range(k))


def test_two_by_one_at_scan_six_does_not_raise():
    a = TrackAssociator(2, 1, DegreeParams())
    f1, f2, D = np.ones((2, 3)), np.ones((1, 3)), np.array([[1.0], [2.0]])
    out = [a.step(D, f1, f2).tolist() for _ in range(8)]
    assert out[5] == [0, 0] and out[6] == [0, -1] and out[7] == [0, -1]


def test_track_associator_rejects_wrong_shapes():
    a = TrackAssociator(2, 1, DegreeParams())
    import pytest
    with pytest.raises(ValueError, match="D must have shape"):
        a.step(np.ones((1, 2)), np.ones((2, 3)), np.ones((1, 3)))
    with pytest.raises(ValueError, match="features"):
        a.step(np.ones((2, 1)), np.ones((2, 2)), np.ones((1, 3)))


@given(sizes, sizes, sizes, seeds)
@SETTINGS
def test_three_node_decision(n1, n2, n3, seed):
    rng = np.random.default_rng(seed)
    tup = three_node_decision(_degrees(rng, n1, n2), _degrees(rng, n1, n3),
                              _degrees(rng, n2, n3), 0.5, solver="highs")
    assert tup.shape == (n1, 3)
    assert np.all(tup[:, 0] == np.arange(n1))
    for ax, n in ((1, n2), (2, n3)):
        _partners_ok(tup[:, ax], n1, n, one_to_one=True)


@given(sizes, sizes, seeds, st.booleans(), st.sampled_from(["dynamic", "fixed"]))
@SETTINGS
def test_double_threshold(n1, n2, seed, exclusive, schedule):
    rng = np.random.default_rng(seed)
    dt = DoubleThreshold(n1, n2, IRRule(schedule, I=2, R=3, exclusive=exclusive))
    for _ in range(5):
        phi = rng.exponential(1.0, size=(n1, n2))
        trial = trial_pairs(phi, "row")
        _partners_ok(dt.update(trial, phi), n1, n2, one_to_one=exclusive)


@given(st.integers(0, 4), st.integers(1, 4), sizes, seeds)
@SETTINGS
def test_did(R, m, n, seed):
    rng = np.random.default_rng(seed)
    res = did_decide(rng.uniform(0, 1, size=(R, m, n)), DIDParams())
    _partners_ok(res.choice, R, n, one_to_one=False)                    # one record per report


@given(sizes, sizes, seeds)
@SETTINGS
def test_zhang_decisions(n1, n2, seed):
    """MD-ND and MD-2DA: a partition, each observation with at most one partner."""
    rng = np.random.default_rng(seed)
    s = np.array([1] * n1 + [2] * n2)
    P = rng.uniform(0, 1, size=(n1 + n2, n1 + n2))
    P = (P + P.T) / 2
    for rel in (md_nd(P, s), md_2da(P, s, tau=0.3).relations):
        rel.check()                                                      # exactly one relation
        assert all(s[i] == 1 and s[j] == 2 for i, j in rel.pairs)
