"""The multi-frame window problem against brute force and an independent MILP model."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.tracking.mfa import (chosen_hypotheses, dominated, nscan_prune,
                                   ranked_window, solve_window, tag_arrays, window_problem)


@st.composite
def hypothesis_sets(draw, max_tracks=4, max_slots=3, max_meas=3, max_per_track=4):
    """Random per-track hypothesis lists (repeated histories and costs included)."""
    T = draw(st.integers(1, max_tracks))
    S = draw(st.integers(1, max_slots))
    rows, tracks, costs = [], [], []
    for t in range(T):
        for _ in range(draw(st.integers(1, max_per_track))):
            rows.append(draw(st.lists(st.integers(0, max_meas), min_size=S, max_size=S)))
            tracks.append(t)
            costs.append(draw(st.sampled_from([0.0, 0.5, 1.0, 2.5, np.inf]) |
                              st.floats(-2.0, 5.0, allow_nan=False)))
        if all(np.isinf(c) for c, tr in zip(costs, tracks) if tr == t):
            costs[-1] = 1.0
    return np.array(tracks), np.array(costs), np.array(rows).reshape(-1, S)


def every_global_hypothesis(track, cost, history):
    """All feasible global hypotheses by enumeration: (cost, choice per track)."""
    T = int(track.max()) + 1
    per = [np.flatnonzero((track == t) & np.isfinite(cost)) for t in range(T)]
    out = []
    for choice in itertools.product(*per):
        used = [(s, m) for h in choice for s, m in enumerate(history[h]) if m > 0]
        if len(used) == len(set(used)):
            out.append((float(sum(cost[list(choice)])), np.array(choice)))
    out.sort(key=lambda f: f[0])
    return out


def milp_set_packing(track, cost, history):
    """Optimum of the set packing written directly for scipy's milp (one variable per
    hypothesis): exactly one per track, each (slot, measurement) at most once."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    ok = np.isfinite(cost)
    H, T = len(cost), int(track.max()) + 1
    rows = [(track == t) & ok for t in range(T)]
    lo, hi = [1.0] * T, [1.0] * T
    for s in range(history.shape[1]):
        for m in np.unique(history[:, s][history[:, s] > 0]):
            rows.append((history[:, s] == m) & ok)
            lo.append(0.0)
            hi.append(1.0)
    c = np.where(ok, cost, 0.0)
    res = milp(c, constraints=LinearConstraint(np.array(rows, float), lo, hi),
               integrality=np.ones(H), bounds=Bounds(0, ok.astype(float)))
    return res.fun if res.status == 0 else None


@settings(max_examples=100)
@given(hypothesis_sets())
def test_window_optimum_equals_brute_force_and_milp(data):
    track, cost, history = data
    wp = window_problem(track, cost, history)
    sol, choice = solve_window(wp)
    every = every_global_hypothesis(track, cost, history)
    ref = milp_set_packing(track, cost, history)
    if not every:
        assert not sol.has_solution and ref is None
        return
    assert sol.status.value == "optimal" and sol.gap <= 1e-12   # proven (float sums)
    assert sol.objective == pytest.approx(every[0][0], abs=1e-9)
    assert ref == pytest.approx(every[0][0], abs=1e-6)
    # the choice is a real global hypothesis of that cost: one per track, no reuse
    assert (track[choice] == np.arange(len(choice))).all()
    assert float(cost[choice].sum()) == pytest.approx(sol.objective, abs=1e-9)
    used = [(s, m) for h in choice for s, m in enumerate(history[h]) if m > 0]
    assert len(used) == len(set(used))


@settings(max_examples=60)
@given(hypothesis_sets(max_tracks=3, max_per_track=4), st.integers(1, 12))
def test_k_best_global_hypotheses_equal_the_enumeration(data, k):
    track, cost, history = data
    wp = window_problem(track, cost, history)
    every = every_global_hypothesis(track, cost, history)
    costs, choices, ranked = ranked_window(wp, k)
    assert len(costs) == min(k, len(every))
    np.testing.assert_allclose(costs, [c for c, _ in every[:k]], atol=1e-9)
    keys = {tuple(c) for c in choices}
    assert len(keys) == len(choices)                  # distinct global hypotheses
    valid = {tuple(ch): c for c, ch in every}
    for c, ch in zip(costs, choices):
        assert valid[tuple(ch)] == pytest.approx(c, abs=1e-9)


def test_problem_shape_free_singletons_and_shared_tuples():
    track = np.array([0, 0, 0, 1, 1])
    cost = np.array([1.0, 0.5, 2.0, 0.1, np.inf])
    history = np.array([[7, 3], [7, 3], [0, 3], [7, 0], [9, 9]])
    wp = window_problem(track, cost, history)
    p = wp.problem
    assert p.sizes == (2, 1, 1)                       # measurement 9 only in a weight-0 one
    assert wp.n_hypotheses == 3 and wp.candidate[4] == -1
    assert wp.candidate[0] == wp.candidate[1]          # one tuple, cheapest stands for it
    assert wp.representative[wp.candidate[0]] == 1
    free = p.tuples[p.tuples[:, 0] == 0]
    assert sorted(map(tuple, free)) == [(0, 0, 1), (0, 1, 0)]
    assert (p.costs[p.tuples[:, 0] == 0] == 0).all()
    sol, choice = solve_window(wp)
    assert list(choice) == [2, 3] and sol.objective == pytest.approx(2.1)
    assert list(wp.measurements[0]) == [7] and list(wp.measurements[1]) == [3]


def test_free_cost_is_charged_per_unused_measurement():
    track, cost = np.array([0, 0]), np.array([0.0, 1.0])
    history = np.array([[0], [4]])
    assert solve_window(window_problem(track, cost, history))[0].objective == 0.0
    sol, choice = solve_window(window_problem(track, cost, history, free_cost=5.0))
    assert list(choice) == [1] and sol.objective == 1.0


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="track 1 has no hypothesis"):
        window_problem([0, 1], [1.0, np.inf], [[0], [1]])
    with pytest.raises(ValueError, match="track 2 has no hypothesis"):
        window_problem([0, 1], [1.0, 1.0], [[0], [1]], n_tracks=3)
    with pytest.raises(ValueError, match="cost of hypothesis 1 is nan"):
        window_problem([0, 0], [1.0, np.nan], [[0], [1]])
    with pytest.raises(ValueError, match="history must have shape"):
        window_problem([0, 0], [1.0, 1.0], [0, 1])
    with pytest.raises(ValueError, match="non-negative"):
        window_problem([0, 0], [1.0, 1.0], [[0], [-1]])


def test_no_tracks_and_no_measurements():
    wp = window_problem(np.zeros(0, int), np.zeros(0), np.zeros((0, 3), int))
    sol, choice = solve_window(wp)
    assert sol.objective == 0 and len(choice) == 0
    wp = window_problem([0, 0, 1], [2.0, 1.0, 3.0], np.zeros((3, 2), int))
    assert wp.problem.sizes == (2, 0, 0)
    assert list(solve_window(wp)[1]) == [1, 2]


def test_nscan_prune_keeps_agreement_on_the_oldest_scan():
    track = np.array([0, 0, 0, 1, 1, 1])
    labels = np.array([[1, 2], [1, 0], [2, 1], [0, 1], [3, 0], [0, 2]])
    keep = nscan_prune(track, labels, [np.array([1, 3])])
    assert keep.tolist() == [True, True, False, True, False, True]
    keep = nscan_prune(track, labels, [np.array([1, 3]), np.array([2, 4])])
    assert keep.all()
    keep = nscan_prune(track, labels, [np.array([1, 3])], n_old=2)
    assert keep.tolist() == [False, True, False, True, False, False]


def test_tag_arrays_pad_truncate_and_pairs():
    hist, lab = tag_arrays([[], [3], [1, 2, 3, 4]], 3)
    assert hist.tolist() == [[0, 0, 0], [0, 0, 3], [2, 3, 4]]
    assert (lab[:, :, 0] == hist).all() and (lab[:, :, 1] == 0).all()
    hist, lab = tag_arrays([[(2, 1), (0, 0)], [(3, 0)]], 2)
    assert hist.tolist() == [[2, 0], [0, 3]]
    assert lab.tolist() == [[[2, 1], [0, 0]], [[0, -1], [3, 0]]]
    with pytest.raises(ValueError, match="all hold detection indices"):
        tag_arrays([[(2, 1)], [3]], 2)
    with pytest.raises(ValueError, match="window must be a positive integer"):
        tag_arrays([[1]], 0)


def test_chosen_hypotheses_of_an_infeasible_window_is_an_error():
    wp = window_problem([0, 1], [1.0, 1.0], [[5], [5]])
    sol, choice = solve_window(wp)
    assert choice is None and sol.status.value == "infeasible"
    with pytest.raises(ValueError, match="no solution"):
        chosen_hypotheses(wp, sol)


@settings(max_examples=40)
@given(hypothesis_sets(), st.sampled_from(["highs", "scipy", "bnb", "lagrangian-exact",
                                           "ortools-cpsat"]))
def test_every_exact_back_end_solves_the_window_problem(data, solver):
    track, cost, history = data
    wp = window_problem(track, cost, history)
    every = every_global_hypothesis(track, cost, history)
    sol, choice = solve_window(wp, solver)
    if not every:
        assert not sol.has_solution
        return
    assert sol.objective == pytest.approx(every[0][0], abs=1e-6)
    assert float(cost[choice].sum()) == pytest.approx(sol.objective, abs=1e-6)


def dominated_by_pairs(tuples, costs, free_cost):
    """The dominance of :func:`dominated`, pair by pair in Python."""
    out = []
    for u, cu in zip(tuples.tolist(), costs.tolist()):
        hit = False
        for v, cv in zip(tuples.tolist(), costs.tolist()):
            same = v[0] == u[0] and all(b in (0, a) for a, b in zip(u[1:], v[1:]))
            freed = sum(a > 0 and b == 0 for a, b in zip(u[1:], v[1:]))
            hit |= same and freed > 0 and cv + free_cost * freed < cu - 1e-12 * max(1, abs(cu))
        out.append(hit)
    return np.array(out, bool)


@settings(max_examples=80)
@given(hypothesis_sets(max_slots=4), st.sampled_from([0.0, 0.0, 0.7, -0.4]))
def test_dropping_dominated_hypotheses_keeps_the_optimum(data, free_cost):
    track, cost, history = data
    full = window_problem(track, cost, history, free_cost=free_cost)
    wp = window_problem(track, cost, history, free_cost=free_cost, drop_dominated=True)
    U = full.n_hypotheses
    mask = dominated(full.problem.tuples[:U], full.problem.costs[:U], free_cost)
    assert mask.tolist() == dominated_by_pairs(full.problem.tuples[:U],
                                               full.problem.costs[:U], free_cost).tolist()
    assert wp.n_dominated == mask.sum() and wp.n_hypotheses == U - mask.sum()
    assert wp.problem.n_candidates == full.problem.n_candidates - mask.sum()
    a, _ = solve_window(full)
    b, choice = solve_window(wp)
    assert a.has_solution == b.has_solution
    if a.has_solution:
        assert b.objective == pytest.approx(a.objective, abs=1e-9)
        unused = sum(wp.problem.sizes[1:]) - int((history[choice] > 0).sum())
        extra = free_cost * unused                     # measurements left free
        assert float(cost[choice].sum()) + extra == pytest.approx(b.objective, abs=1e-9)
        assert (wp.candidate[choice] >= 0).all()


def test_dominated_tuples_are_left_out_and_ranking_refuses_them():
    track = np.array([0, 0, 0, 1])
    cost = np.array([1.0, 2.0, 0.5, 0.3])
    history = np.array([[4, 0], [4, 5], [0, 0], [4, 5]])
    wp = window_problem(track, cost, history, drop_dominated=True)
    assert wp.n_dominated == 2 and wp.candidate.tolist()[:3] == [-1, -1, 0]
    sol, choice = solve_window(wp)
    assert list(choice) == [2, 3] and sol.objective == pytest.approx(0.8)
    with pytest.raises(ValueError, match="drop_dominated=False"):
        ranked_window(wp, 2)
    assert not dominated(np.zeros((0, 3), np.int64), np.zeros(0)).any()
