"""Paper 004's double-threshold (I/R) rule: counting, the tie-breaks (18)-(19), the
dynamic schedule, and at most one partner per track where the rule promises it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.tracking.decide.double_threshold import DYNAMIC_SCHEDULE, DoubleThreshold, IRRule
from assocopt.tracking.decide.topology import LARGE, trial_pairs


def test_dynamic_schedule_follows_the_paper_examples():
    r = IRRule(R_max=12)
    assert [r.criterion(k) for k in range(1, 9)] == list(DYNAMIC_SCHEDULE)
    assert r.criterion(12) == (10, 12)
    assert [IRRule().criterion(k) for k in (1, 2, 3, 4, 5, 12)] == [(1, 1), (2, 2), (2, 3),
                                                                  (3, 4), (3, 4), (3, 4)]
    assert IRRule("fixed", I=3, R=5).criterion(9) == (3, 5)
    with pytest.raises(ValueError, match="I <= R"):
        IRRule("fixed", I=4, R=3)


def test_fixed_rule_confirms_after_I_hits_in_a_sliding_window():
    dt = DoubleThreshold(1, 2, IRRule("fixed", I=2, R=2))
    phi = np.array([[1.0, 2.0]])
    assert dt.update(np.array([0]), phi).tolist() == [-1]
    assert dt.update(np.array([1]), phi).tolist() == [-1]     # 1 hit each in window
    assert dt.update(np.array([1]), phi).tolist() == [1]
    assert dt.update(np.array([0]), phi).tolist() == [-1]     # window slid: 1 and 1
    assert dt.update(np.array([-1]), phi).tolist() == [-1]


def test_tie_breaks_largest_quality_then_smallest_mean_lambda():
    # (18): u=0 has m=3 for v=1 and m=2 for v=0 under I=2 -> v=1
    dt = DoubleThreshold(1, 3, IRRule("fixed", I=2, R=5))
    phi = np.array([[1.0, 9.0, 0.5]])
    for v in (0, 1, 0, 1, 1):
        out = dt.update(np.array([v]), phi)
    assert out.tolist() == [1]
    # (19): equal m=2 for v=0 and v=2 -> the smaller mean lambda over the window
    dt = DoubleThreshold(1, 3, IRRule("fixed", I=2, R=4))
    for v, lam in ((0, [3.0, 1.0, 2.0]), (2, [3.0, 1.0, 2.0]), (0, [3.0, 1.0, 2.0]),
                   (2, [1.0, 1.0, 5.0])):
        out = dt.update(np.array([v]), np.array([lam]))
    # mean lambda: v=0 -> 2.5, v=2 -> 2.75
    assert out.tolist() == [0]


@settings(max_examples=60, deadline=None)
@given(n1=st.integers(1, 5), n2=st.integers(1, 5), steps=st.integers(1, 8),
       schedule=st.sampled_from(["dynamic", "fixed"]), exclusive=st.booleans(),
       trial_rule=st.sampled_from(["row", "assignment"]), seed=st.integers(0, 2 ** 31))
def test_each_track_gets_at_most_one_partner(n1, n2, steps, schedule, exclusive, trial_rule,
                                             seed):
    rng = np.random.default_rng(seed)
    dt = DoubleThreshold(n1, n2, IRRule(schedule, I=2, R=3, exclusive=exclusive))
    for _ in range(steps):
        phi = np.where(rng.random((n1, n2)) < 0.3, LARGE, rng.integers(1, 4, (n1, n2)) * 1.0)
        trial = trial_pairs(phi, trial_rule)
        real = trial[trial >= 0]
        if trial_rule == "assignment":
            assert len(set(real.tolist())) == len(real)
        assert (phi[np.flatnonzero(trial >= 0), real] < LARGE).all()
        out = dt.update(trial, phi)
        assert out.shape == (n1,) and ((out >= -1) & (out < n2)).all()
        if exclusive:
            taken = out[out >= 0]
            assert len(set(taken.tolist())) == len(taken)


def test_update_refuses_bad_shapes():
    dt = DoubleThreshold(2, 2)
    with pytest.raises(ValueError, match="shape"):
        dt.update(np.array([0]), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="sensor-2 index"):
        dt.update(np.array([0, 5]), np.zeros((2, 2)))
