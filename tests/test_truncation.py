"""Observation-sequence truncation (paper 000 Steps A-C) on hand-built cases, every
reading option, and random inputs: each observation always in exactly one relation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.sparse.csgraph import minimum_spanning_tree

from assocopt.tracking.decide.truncation import (MIDDLE_RULES, ORDERINGS, TIE_BREAKS,
                                        TRAVERSED_READINGS, VISITED_READINGS,
                                        TruncationOptions, coarse_truncation,
                                        fine_truncation, md_nd, single_linkage_order, truncate)

NAN = np.nan
# Observations 0, 1 (sensor 1) and 2, 3, 4 (sensor 2): pairs (0, 2) and (1, 3)
# well separated, 4 isolated.
PI_TWO_PAIRS = np.array([[NAN, .01, .90, .02, .05],
                         [.01, NAN, .03, .80, .04],
                         [.90, .03, NAN, .02, .06],
                         [.02, .80, .02, NAN, .01],
                         [.05, .04, .06, .01, NAN]])
SENSOR_TWO_PAIRS = [1, 1, 2, 2, 2]

ALL_OPTIONS = [TruncationOptions(ordering=o, tie_break=t, traversed=tr, visited=v, middle_rule=m)
               for o, t, tr, v, m in itertools.product(ORDERINGS, TIE_BREAKS, TRAVERSED_READINGS,
                                                       VISITED_READINGS, MIDDLE_RULES)]


def test_two_separated_pairs_and_one_isolated_observation():
    res = truncate(PI_TWO_PAIRS, SENSOR_TWO_PAIRS)
    # Step A (Prim from z_1 = index 0): 0 -.90- 2 -.06- 4 -.04- 1 -.80- 3
    assert res.order.tolist() == [0, 2, 4, 1, 3]
    assert np.allclose(res.measures, [.90, .06, .04, .80])
    # Step B: f = 1, .90, .06, .04, .80; the only i in 2..4 with f(i) < f(i+1) is i = 4
    assert res.segments == ((0, 2), (3, 4))
    assert res.relations.pairs == ((0, 2), (1, 3))
    assert res.relations.isolated == (4,)


@pytest.mark.parametrize("opt", ALL_OPTIONS, ids=lambda o: "-".join(
    str(v) for k, v in o.as_dict().items() if k in ("ordering", "tie_break", "traversed",
                                                    "visited", "middle_rule")))
def test_two_pairs_example_under_every_reading(opt):
    rel = md_nd(PI_TWO_PAIRS, SENSOR_TWO_PAIRS, opt)
    assert rel.pairs == ((0, 2), (1, 3)) and rel.isolated == (4,)


def test_coarse_truncation_indices():
    # f = 1, .5, .2, .3, .4 -> cuts before positions 2 (f(3)=.2 < f(4)=.3) and 3
    assert coarse_truncation([.5, .2, .3, .4]) == [(0, 1), (2, 2), (3, 4)]
    # i = 2 .. N-1 only (f(1) = 1 is artificial): v_N never starts a segment on its own
    assert coarse_truncation([.1, .9]) == [(0, 0), (1, 2)]
    assert coarse_truncation([.1, .2, .3]) == [(0, 0), (1, 1), (2, 3)]
    assert coarse_truncation([.9, .1]) == [(0, 2)]
    assert coarse_truncation([]) == [(0, 0)]
    assert coarse_truncation([.3]) == [(0, 1)]
    # strict test: equal neighbours do not cut
    assert coarse_truncation([.5, .5, .3]) == [(0, 3)]
    assert coarse_truncation([.2, .5, .5, .5]) == [(0, 0), (1, 4)]


def test_single_node_segments_are_isolated():
    assert fine_truncation([7], [], [1] * 8) == [(7,)]
    # A chain whose coarse truncation leaves a single-node segment in the middle.
    L = [.5, .2, .3, .4]
    segs = coarse_truncation(L)
    assert (2, 2) in segs
    pi = np.full((5, 5), 0.001)
    for k, l in enumerate(L):           # Prim from 0 visits 0, 1, 2, 3, 4 in order
        pi[k, k + 1] = pi[k + 1, k] = l
    np.fill_diagonal(pi, NAN)
    res = truncate(pi, [1, 2, 1, 2, 1])
    assert res.order.tolist() == [0, 1, 2, 3, 4] and res.segments == tuple(segs)
    assert res.relations.isolated == (2,)
    assert res.relations.pairs == ((0, 1), (4, 3))      # (sensor-1, sensor-2) order


def test_same_sensor_neighbours_first_measure():
    # nodes a (s1), b (s1), c (s2); l = .9 (a-b, same sensor), .5 (b-c)
    s = np.array([1, 1, 2])
    # m = 1, same sensor, not all traversed: isolate a.  Then m = 2 = n_t: V = {b, c},
    # different sensors, l_2 > l_1 fails and every measure is traversed: isolate b, c.
    assert sorted(fine_truncation([0, 1, 2], [.9, .5], s)) == [(0,), (1,), (2,)]
    # With l = .9 (a-b), .95 (b-c): b-c first (m = n_t, different sensors, .95 > .9): match.
    assert sorted(fine_truncation([0, 1, 2], [.9, .95], s)) == [(0,), (1, 2)]


def test_same_sensor_neighbours_in_the_middle_go_straight_back_to_step1():
    # a(s1) b(s2) c(s2) d(s1); l = .6, .9 (b-c same sensor, middle), .5
    s = np.array([1, 2, 2, 1])
    out = fine_truncation([0, 1, 2, 3], [.6, .9, .5], s)
    # m = 2: nothing decided; m = 1: .6 > .9 fails, not all traversed: isolate a;
    # m = 3 = n_t: .5 > .9 fails, all traversed: the undecided b, c, d isolated.
    assert sorted(out) == [(0,), (1,), (2,), (3,)]


def test_same_sensor_last_measure_isolates_second_node():
    s = np.array([1, 2, 2])
    out = fine_truncation([0, 1, 2], [.5, .9], s)
    # m = 2 = n_t, same sensor, not all traversed: isolate c; m = 1: V = {a, b},
    # .5 > .9 fails, all traversed: isolate a and b.
    assert out[0] == (2,) and sorted(out) == [(0,), (1,), (2,)]


def test_middle_cross_sensor_peak_is_matched():
    # a(s1) b(s1) c(s2) d(s2): l = .3, .9, .2 -> m = 2 is a peak: match b-c
    s = np.array([1, 1, 2, 2])
    out = fine_truncation([0, 1, 2, 3], [.3, .9, .2], s)
    assert (1, 2) in out and sorted(x for c in out for x in c) == [0, 1, 2, 3]


def _local_maxima_oracle(nodes, measures, sensor):
    """Closed form of Step C (derived): match the cross-sensor pairs whose measure is a
    strict local maximum of the segment's sequence; isolate every other node."""
    L, c = list(measures), list(nodes)
    n = len(L)
    pairs = []
    for k in range(n):
        left = L[k - 1] if k > 0 else -np.inf
        right = L[k + 1] if k < n - 1 else -np.inf
        if L[k] > left and L[k] > right and sensor[c[k]] != sensor[c[k + 1]]:
            pairs.append((c[k], c[k + 1]))
    matched = {x for p in pairs for x in p}
    return sorted(pairs + [(x,) for x in c if x not in matched])


@settings(max_examples=300)
@given(st.integers(0, 7).flatmap(lambda n: st.tuples(
    st.lists(st.sampled_from([0.1, 0.5, 0.9]) | st.floats(0, 1), min_size=n, max_size=n),
    st.lists(st.sampled_from([1, 2]), min_size=n + 1, max_size=n + 1))),
    st.sampled_from(ALL_OPTIONS))
def test_step_c_under_every_reading_equals_local_maxima_rule(inp, opt):
    L, s = inp
    s = np.array(s)
    out = fine_truncation(range(len(s)), L, s, opt)
    assert sorted(out) == _local_maxima_oracle(range(len(s)), L, s)


def test_equal_neighbouring_measures_are_not_local_maxima():
    # a(s1) b(s2) c(s1) d(s2) e(s1): l = .1 .5 .5 .1 -> no strict peak, nothing matched
    s = np.array([1, 2, 1, 2, 1])
    assert sorted(fine_truncation(range(5), [.1, .5, .5, .1], s)) == [(i,) for i in range(5)]
    # ... but a strict peak next to it is: l = .1 .5 .6 .1 -> match c-d
    assert (2, 3) in fine_truncation(range(5), [.1, .5, .6, .1], s)


def test_readings_take_different_clauses_to_the_same_partition():
    s = np.array([1, 1, 2])
    base = fine_truncation([0, 1, 2], [.9, .5], s)
    after = fine_truncation([0, 1, 2], [.9, .5], s, TruncationOptions(traversed="after_step"))
    # on_selection: the all-traversed clause isolates b and c together; after_step: it
    # cannot fire, so c is isolated by the m = n_t clause and b at the end.
    assert base == [(0,), (1,), (2,)] and after == [(0,), (2,), (1,)]


def test_prim_levels_form_a_maximum_spanning_tree():
    rng = np.random.default_rng(0)
    for _ in range(20):
        n = int(rng.integers(2, 12))
        A = rng.random((n, n))
        pi = (A + A.T) / 2
        np.fill_diagonal(pi, NAN)
        v, l = single_linkage_order(pi, start=int(rng.integers(n)))
        assert sorted(v.tolist()) == list(range(n))
        W = 2.0 - np.nan_to_num(pi, nan=2.0)        # min spanning tree of 2 - pi
        mst = minimum_spanning_tree(np.triu(W)).toarray()
        assert l.sum() == pytest.approx((2.0 - mst[mst > 0]).sum())
        for k in range(1, n):            # l_{k} = best link from the visited prefix to v_{k+1}
            assert l[k - 1] == pytest.approx(np.nanmax(pi[np.ix_(v[:k], [v[k]])]))


def test_dendrogram_ordering_is_a_permutation_with_merge_levels():
    v, l = single_linkage_order(PI_TWO_PAIRS, ordering="dendrogram")
    assert sorted(v.tolist()) == list(range(5)) and len(l) == 4
    assert max(l) == pytest.approx(.90)


def test_bad_inputs():
    with pytest.raises(ValueError, match="square"):
        md_nd(np.zeros((2, 3)), [1, 2])
    with pytest.raises(ValueError, match="sensor"):
        md_nd(np.zeros((2, 2)), [1, 3])
    with pytest.raises(ValueError, match="finite"):
        md_nd(np.array([[0, np.inf], [np.inf, 0]]), [1, 2])
    with pytest.raises(ValueError, match="ordering"):
        TruncationOptions(ordering="x")


def test_tiny_inputs():
    assert md_nd(np.zeros((0, 0)), []).n == 0
    assert md_nd(np.full((1, 1), NAN), [2]).isolated == (0,)
    assert md_nd(np.array([[NAN, .3], [.3, NAN]]), [1, 2]).pairs == ((0, 1),)
    assert md_nd(np.array([[NAN, .3], [.3, NAN]]), [1, 1]).isolated == (0, 1)


@st.composite
def random_inputs(draw):
    n = draw(st.integers(1, 12))
    vals = draw(st.lists(st.sampled_from([0.0, 0.1, 0.25, 0.5, 0.9]) | st.floats(0, 1),
                         min_size=n * n, max_size=n * n))
    A = np.array(vals).reshape(n, n)
    pi = np.maximum(A, A.T)
    np.fill_diagonal(pi, NAN)
    sensor = np.array(draw(st.lists(st.sampled_from([1, 2]), min_size=n, max_size=n)))
    return pi, sensor


@given(random_inputs(), st.sampled_from(ALL_OPTIONS))
def test_every_observation_in_exactly_one_relation_on_random_inputs(inp, opt):
    pi, sensor = inp
    rel = md_nd(pi, sensor, opt)          # Relations.from_clusters asserts the partition
    assert rel.n == len(sensor)
    members = [i for p in rel.pairs for i in p] + list(rel.isolated)
    assert sorted(members) == list(range(len(sensor)))
    assert all(sensor[i] == 1 and sensor[j] == 2 for i, j in rel.pairs)
