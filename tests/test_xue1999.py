"""Paper 003 (Xue et al. 1999): DID's two stages against a loop-based re-implementation,
hand-built stage-1 cases, the GNN / NN counterparts, the crossing-targets scenario and
tracker, and the reproduction's summary and page."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from assocopt.tracking.decide.did import (AMBIGUOUS, NEW, UNIQUE, DIDParams, did_decide,
                                          dominance, initial_states, relative_errors,
                                          stage1_case, stage2, strength_matrix)
from assocopt.tracking.decide.nearest import gnn_assign, nearest_neighbour
from assocopt.tracking.scenarios.xue1999 import Xue1999
from assocopt.tracking.scenarios.xue1999_tracker import (METHODS, association_costs,
                                                         run_metrics, run_tracker)
from conftest import check_page_against_summary, page_block

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------ loop-based re-implementation
def ref_did(a0, A, *, scale=None, floor=None, categorical=(), M=1.0, Mp=6.0, B=0.2,
            max_iter=50, select="movable", score="final", min_updates=0):
    """One report, written from the paper's steps with plain loops (no numpy in bulk)."""
    m, n = len(A), len(A[0])
    s_on = [[0.0] * n for _ in range(m)]
    for i in range(m):
        for j in range(n):
            diff = abs(a0[i] - A[i][j])
            if i in categorical:
                delta = 0.0 if diff == 0 else math.inf
            elif scale is not None:
                delta = diff / scale[i]
            else:
                delta = diff / max(abs(A[i][j]), floor[i])
            eta = delta / M
            s_off = 1.0 if eta >= Mp else eta / Mp
            s_on[i][j] = 1.0 - s_off
    Bm = [[0.0 if i == l else B for l in range(m)] for i in range(m)]
    on = lambda s: s >= 1.0 - s
    cols_on = [all(on(s_on[i][j]) for i in range(m)) for j in range(n)]
    cols_off = [all(not on(s_on[i][j]) for i in range(m)) for j in range(n)]
    if all(cols_off):
        return {"choice": -1, "stage": 1, "converged": True, "states": s_on}
    if sum(cols_on) == 1 and all(a or b for a, b in zip(cols_on, cols_off)):
        return {"choice": cols_on.index(True), "stage": 1, "converged": True, "states": s_on}
    converged = True
    initial = [row[:] for row in s_on]
    assoc = {}
    for j in range(n):
        if cols_off[j]:
            continue
        col = [s_on[i][j] for i in range(m)]
        for it in range(max_iter):
            states = [on(s) for s in col]
            if it >= min_updates and (all(states) or not any(states)):
                break
            ys = [sum(Bm[i][l] * (col[l] - (1.0 - col[l])) for l in range(m) if l != i)
                  for i in range(m)]
            cand = [i for i in range(m) if select == "literal" or
                    (ys[i] > 0 and col[i] < 1.0) or (ys[i] < 0 and col[i] > 0.0)]
            if not cand:
                break
            istar = min(cand, key=lambda i: (abs(col[i] - 0.5), i))
            new = min(1.0, max(0.0, col[istar] + ys[istar]))
            if new == col[istar]:
                break
            col[istar] = new
        states = [on(s) for s in col]
        settled = all(states) or not any(states)
        converged &= settled
        for i in range(m):
            s_on[i][j] = col[i]
        if all(states):
            src = col if score == "final" else [initial[i][j] for i in range(m)]
            assoc[j] = sum(src)
    if not assoc:
        return {"choice": -1, "stage": 2, "converged": converged, "states": s_on}
    best = max(assoc.values())
    return {"choice": min(j for j, q in assoc.items() if q == best), "stage": 2,
            "converged": converged, "states": s_on}


def _random_inputs(rng, R, m, n):
    A = rng.normal(0, 1, (m, n))
    reports = A[:, rng.integers(0, n, R)].T + rng.normal(0, 1.5, (R, m))
    cat = rng.random(m) < 0.25
    A[cat] = rng.integers(0, 2, (cat.sum(), n))
    reports[:, cat] = rng.integers(0, 2, (R, cat.sum()))
    return reports, A, cat


@pytest.mark.parametrize("min_updates", [0, 1])
@pytest.mark.parametrize("select", ["movable", "literal"])
@pytest.mark.parametrize("score", ["final", "initial"])
@pytest.mark.parametrize("error", ["scale", "origin"])
def test_did_matches_loop_reimplementation_on_random_inputs(select, score, error, min_updates):
    rng = np.random.default_rng(["movable", "literal"].index(select) * 8
                                + ["final", "initial"].index(score) * 4
                                + ["scale", "origin"].index(error) * 2 + min_updates)
    n_stage2 = 0
    for _ in range(40):
        R, m, n = rng.integers(1, 5), rng.integers(2, 7), rng.integers(1, 6)
        reports, A, cat = _random_inputs(rng, R, m, n)
        scale = rng.uniform(0.2, 2.0, m)
        floor = rng.uniform(0.05, 0.5, m)
        p = DIDParams(M=float(rng.uniform(0.3, 2)), M_prime=float(rng.uniform(1, 8)),
                      B=float(rng.uniform(0, 1)), max_iter=int(rng.integers(0, 30)),
                      select=select, score=score, min_updates=min_updates)
        kw = {"scale": scale} if error == "scale" else {"floor": floor}
        delta = relative_errors(reports, A, error=error, categorical=cat, **kw)
        res = did_decide(initial_states(delta, p), p)
        for r in range(R):
            ref = ref_did(reports[r], A.tolist(), categorical=set(np.flatnonzero(cat)),
                          M=p.M, Mp=p.M_prime, B=p.B, max_iter=p.max_iter, select=select,
                          score=score, min_updates=min_updates, **({"scale": scale} if error == "scale" else
                                          {"floor": floor}))
            assert res.choice[r] == ref["choice"]
            assert res.stage[r] == ref["stage"]
            assert bool(res.converged[r]) == ref["converged"]
            assert np.allclose(res.states[r], ref["states"], atol=1e-12)
            n_stage2 += ref["stage"] == 2
    assert n_stage2 > 10                  # the comparison exercised stage 2


# ------------------------------------------------------------ stage 1 by hand
P = DIDParams(M=1.0, M_prime=6.0, B=0.2)


def test_stage1_normalisation_reads_eta():
    s = initial_states(np.array([0.0, 1.5, 3.0, 5.9, 6.0, 60.0, np.inf]), P)
    assert np.allclose(s, [1.0, 0.75, 0.5, 1 - 5.9 / 6, 0.0, 0.0, 0.0])
    assert dominance(s).tolist() == [True, True, True, False, False, False, False]
    s2 = initial_states(np.array([3.0]), DIDParams(M=0.5, M_prime=12.0))
    assert np.allclose(s2, 0.5)                  # eta = 6 = M'/2: on (s_on >= s_off)


def test_stage1_case_1_no_factor_on_is_a_new_target():
    delta = np.full((1, 3, 2), 4.0)              # eta = 4 > M'/2 everywhere
    res = did_decide(initial_states(delta, P), P)
    assert res.stage1.tolist() == [NEW] and res.choice.tolist() == [-1]
    assert res.stage.tolist() == [1] and res.iterations.tolist() == [0]


def test_stage1_case_2_one_column_all_on_others_all_off():
    delta = np.array([[[0.5, 5.0, 4.0], [1.0, 4.0, 3.5], [0.0, np.inf, 9.0]]])
    S = initial_states(delta, P)
    case, k = stage1_case(S)
    assert case.tolist() == [UNIQUE] and k.tolist() == [0]
    res = did_decide(S, P)
    assert res.choice.tolist() == [0] and res.stage.tolist() == [1]
    assert np.array_equal(res.states, S)          # decided without stage 2: untouched
    assert res.score[0] == pytest.approx(S[0, :, 0].sum())


def test_stage1_case_3_goes_to_stage_2():
    mixed = np.array([[[0.5, 5.0], [1.0, 4.0], [5.0, 9.0]]])     # column 0 mixes on/off
    two = np.array([[[0.5, 1.0], [1.0, 0.2], [0.0, 0.0]]])       # two columns all on
    for delta in (mixed, two):
        assert stage1_case(initial_states(delta, P))[0].tolist() == [AMBIGUOUS]
    res = did_decide(initial_states(two, P), P)
    q = initial_states(two, P)[0].sum(axis=0)
    assert res.stage.tolist() == [2] and res.choice[0] == int(np.argmax(q))
    # columns that already agree are not moved by stage 2
    assert res.iterations.tolist() == [0]
    assert np.array_equal(res.states, initial_states(two, P))
    res_m = did_decide(initial_states(mixed, P), P)
    assert res_m.iterations[0] > 0 and np.array_equal(res_m.states[0, :, 1],
                                                      initial_states(mixed, P)[0, :, 1])


def test_stage2_flips_the_minority_factor_and_respects_bounds():
    s = np.array([[0.9, 0.9, 0.9, 0.9, 0.0]])     # 4 factors strongly on, IFF mismatch
    B = strength_matrix(0.2, 5)
    fin, settled, it = stage2(s, B, 100, "movable")
    assert settled[0] and dominance(fin).all() and fin.max() <= 1.0
    lit, settled_l, _ = stage2(s, B, 100, "literal")
    assert not settled_l[0]                       # literal: saturated factor 0 stalls
    assert np.all((0 <= lit) & (lit <= 1))


def test_do_while_moves_a_column_that_already_agrees_hand_worked():
    # s_on (x, y, vx, vy, IFF) = (0.8, 0.8, 0.8, 0.8, 1), B = 0.05: the column agrees, so the
    # while reading leaves it; the do-while makes one update of the most ambiguous factor
    # (x: |0.8 - 0.5| = 0.3, the lowest index among the ties) by
    # 0.05 * (3 * (0.8 - 0.2) + (1 - 0)) = 0.14, to 0.94, then stops (all on).
    col = np.array([[0.8, 0.8, 0.8, 0.8, 1.0]])
    B = strength_matrix(0.05, 5)
    for select in ("literal", "movable"):
        s0, settled0, it0 = stage2(col, B, 100, select, min_updates=0)
        assert np.array_equal(s0, col) and it0.tolist() == [0] and settled0[0]
        s1, settled1, it1 = stage2(col, B, 100, select, min_updates=1)
        assert s1[0].tolist() == pytest.approx([0.94, 0.8, 0.8, 0.8, 1.0])
        assert it1.tolist() == [1] and settled1[0]
    # a contradictory column: the do-while and the while loop agree after the first update
    mixed = np.array([[0.45, 0.8, 0.8, 0.8, 1.0]])
    a, _, ia = stage2(mixed, B, 100, "literal", min_updates=0)
    b, _, ib = stage2(mixed, B, 100, "literal", min_updates=1)
    assert np.array_equal(a, b) and ia.tolist() == ib.tolist() == [1]
    assert a[0, 0] == pytest.approx(0.59)
    with pytest.raises(ValueError, match="min_updates"):
        DIDParams(min_updates=-1)


def test_two_record_example_printed_q_rewards_the_dissenting_record_only_for_large_B():
    from assocopt.reproduce.xue1999.report import render_example, two_record_example
    # hand computation: record B's x moves by B * (3 * 0.6 + 1) = 2.8 B, clipped at 1
    hi, lo = two_record_example(0.2), two_record_example(0.05)
    assert (hi["q_A"], hi["q_B"], hi["choice"]) == (pytest.approx(4.2), pytest.approx(4.4), "B")
    assert (lo["q_A"], lo["q_B"], lo["choice"]) == (pytest.approx(4.2), pytest.approx(3.99), "A")
    for B in (0.12, 0.13):                      # the switch at B = 0.35 / 2.8 = 0.125
        assert two_record_example(B)["choice"] == ("B" if B > 0.125 else "A")
    dw = two_record_example(0.05, min_updates=1)
    assert (dw["q_A"], dw["choice"]) == (pytest.approx(4.34), "A")
    text = render_example()
    assert "q_B = 4.40 > q_A = 4.20" in text and "q_B = 3.99 < q_A = 4.20" in text
    assert "B > 0.125" in text


def test_strength_matrix_validation():
    B = strength_matrix(0.3, 3)
    assert np.array_equal(B, B.T) and not np.diag(B).any()
    with pytest.raises(ValueError, match="symmetric"):
        strength_matrix([[0, .1], [.2, 0]], 2)
    with pytest.raises(ValueError, match="diagonal"):
        strength_matrix([[.1, .1], [.1, 0]], 2)
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        DIDParams(B=1.5)
    with pytest.raises(ValueError, match="M_prime"):
        DIDParams(M_prime=0.5)
    with pytest.raises(ValueError, match="scale"):
        relative_errors([[1.0]], [[1.0]], error="scale")


def test_origin_reading_depends_on_the_origin_and_scale_reading_does_not():
    a0, A = np.array([[110.0]]), np.array([[100.0]])
    shift = 1e4
    for err, kw in (("scale", {"scale": [10.0]}), ("origin", {"floor": [1.0]})):
        d1 = relative_errors(a0, A, error=err, **kw)
        d2 = relative_errors(a0 + shift, A + shift, error=err, **kw)
        assert (d1 == d2).all() == (err == "scale")


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 6), st.integers(1, 5),
       st.floats(0, 1), st.integers(0, 40), st.sampled_from(["movable", "literal"]))
def test_states_stay_in_unit_interval_and_loop_is_capped(seed, m, n, b, cap, select):
    rng = np.random.default_rng(seed)
    S = rng.random((3, m, n))
    S[rng.random(S.shape) < 0.3] = rng.integers(0, 2)
    p = DIDParams(B=b, max_iter=cap, select=select)
    res = did_decide(S, p)
    assert np.all((res.states >= 0) & (res.states <= 1))   # s_off = 1 - s_on in [0, 1] too
    assert np.all(res.iterations <= cap * n)
    assert np.all(res.choice < n) and np.all(res.choice >= -1)
    for r in range(3):
        if res.choice[r] >= 0:
            assert dominance(res.states[r, :, res.choice[r]]).all()


# -------------------------------------------------------------- GNN and NN
@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(0, 7), st.integers(0, 7))
def test_gnn_never_gives_a_track_two_reports_and_is_optimal(seed, R, n):
    import itertools
    rng = np.random.default_rng(seed)
    C = rng.uniform(0, 20, (R, n))
    C[rng.random((R, n)) < 0.3] = np.inf
    a = gnn_assign(C, 10.0)
    used = a[a >= 0]
    assert len(set(used.tolist())) == len(used)
    assert all(C[r, a[r]] < 10.0 for r in range(R) if a[r] >= 0)
    if R <= 4 and n <= 4:                         # brute force over all matchings
        best = math.inf
        for perm in itertools.product(range(-1, n), repeat=R):
            t = [j for j in perm if j >= 0]
            if len(set(t)) == len(t):
                best = min(best, sum(C[r, j] if j >= 0 else 10.0 for r, j in enumerate(perm)))
        got = sum(C[r, a[r]] if a[r] >= 0 else 10.0 for r in range(R))
        assert got == pytest.approx(best)


def test_nearest_neighbour_each_track_its_cheapest_report():
    C = np.array([[1.0, 3.0, 12.0], [2.0, 1.0, np.inf]])
    assert nearest_neighbour(C, 10.0).tolist() == [0, 1, -1]
    assert nearest_neighbour(np.zeros((0, 2)), 5.0).tolist() == [-1, -1]
    with pytest.raises(ValueError, match="NaN"):
        gnn_assign([[np.nan]], 1.0)


def test_association_cost_is_mahalanobis_plus_iff():
    z = np.array([[1.0, 2.0, 0.0, 0.0]])
    x = np.zeros((1, 4))
    S = np.diag([1.0, 4.0, 1.0, 1.0])[None]
    C = association_costs(z, np.array([1]), x, S, np.array([0]), 3.0)
    assert C[0, 0] == pytest.approx(1.0 + 1.0 + 3.0)


# --------------------------------------------------------- scenario, tracker
def test_scenario_is_seeded_and_crossings_are_where_stated():
    sc = Xue1999()
    a, b = sc.simulate(np.random.default_rng(4)), sc.simulate(np.random.default_rng(4))
    assert all(np.array_equal(x.reports, y.reports) for x, y in zip(a, b))
    X = sc.truth()
    assert np.allclose(X[20, 0, :2], X[20, 1, :2]) and np.allclose(X[30, 2, :2], X[30, 3, :2])
    none = Xue1999(clutter_mean=0.0, p_d=1.0, noise_scale=1e-9).simulate(np.random.default_rng(0))
    for k, scan in enumerate(none):
        assert np.allclose(scan.reports, X[k, scan.source], atol=1e-5)
    with pytest.raises(ValueError, match="p_d"):
        Xue1999(p_d=2.0)


def test_clutter_and_iff_statistics():
    sc = Xue1999(clutter_mean=20.0, p_iff=0.3, p_d=1.0)
    scans = sc.simulate(np.random.default_rng(2))
    n_clutter = np.mean([(s.source < 0).sum() for s in scans])
    assert 17 < n_clutter < 23
    flips = np.concatenate([s.iff[s.source >= 0] != np.array(sc.iff)[s.source[s.source >= 0]]
                            for s in scans])
    assert 0.2 < flips.mean() < 0.4


@pytest.mark.parametrize("method", sorted(METHODS))
def test_every_method_tracks_an_easy_scene(method):
    sc = Xue1999(clutter_mean=0.0, p_d=1.0, noise_scale=0.3, p_iff=0.0)
    met = run_metrics(run_tracker(sc.simulate(np.random.default_rng(0)), method, sc), sc)
    assert met["false_tracks"] == 0
    assert 0 <= met["decision_precision"] <= 1
    if method in ("gnn", "nn", "did-q0"):
        assert met["correct_rate"] > 0.95 and met["held_at_end"] == 1.0
        assert met["decision_precision"] > 0.95


def test_tuned_method_names_set_B_and_M_prime():
    from assocopt.tracking.scenarios.xue1999_tracker import split_method, tuned_name
    name = tuned_name("did-printed", 0.05, 3)
    assert name == "did-printed@B=0.05,Mp=3"
    assert split_method(name) == ("did-printed", {"did_B": 0.05, "did_M_prime": 3.0})
    assert split_method("gnn") == ("gnn", {})
    for bad in ("gnn@B=0.1,Mp=3", "did-bogus", "did-printed@B=x"):
        with pytest.raises(ValueError, match="unknown method"):
            split_method(bad)
    sc = Xue1999(n_scans=8, clutter_mean=5.0)
    scans = sc.simulate(np.random.default_rng(3))
    from assocopt.tracking.scenarios.xue1999_tracker import TrackerParams
    a = run_metrics(run_tracker(scans, tuned_name("did-zm", 0.05, 3), sc), sc)
    b = run_metrics(run_tracker(scans, "did-zm", sc, TrackerParams(did_B=0.05,
                                                                   did_M_prime=3.0)), sc)
    assert a == b


def test_labels_say_as_printed_only_for_eq10_with_the_literal_selection():
    from assocopt.reproduce.xue1999 import LABELS, label
    assert set(LABELS) == set(METHODS)
    printed = {m for m, o in METHODS.items() if o["rule"] == "did" and
               (o["error"], o["select"], o["score"], o["conflict"], o["unresolved"]) ==
               ("origin", "literal", "final", "q_final", "reject")}
    assert printed == {"did-printed", "did-dowhile"}
    for m, o in METHODS.items():
        lab = LABELS[m]
        assert ("as printed" in lab) == (m in printed), m
        if o["rule"] != "did":
            continue
        assert ("z-score" in lab) == (o["error"] == "scale"), m
        assert ("movable" in lab) == (o["select"] == "movable"), m
        assert ("q from stage 1" in lab) == (o["score"] == "initial"), m
        assert ("do-while" in lab) == (o["min_updates"] == 1), m
        assert ("conflict" in lab) == (o["conflict"] != "q_final"), m
        assert ("not from the paper" in lab) == (o["conflict"] != "q_final"), m
        assert ("majority" in lab) == (o["unresolved"] == "majority"), m
        changed = (o["error"] == "scale" or o["select"] == "movable" or o["score"] == "initial"
                   or o["unresolved"] == "majority")
        assert ("(ours)" in lab) == changed, m
    assert label("did-printed@B=0.05,Mp=3") == LABELS["did-printed"] + ", at B = 0.05, M′ = 3"


def test_conflict_rules_on_two_reports_choosing_one_track():
    from assocopt.tracking.scenarios.xue1999_tracker import RunLog, _settle_conflicts
    # reports 0 and 1 both choose track 0; report 0 has the larger final q, report 1 the
    # larger stage-1 q; report 2 chooses track 1 alone; report 3 is new
    choice = np.array([0, 0, 1, -1])
    score = np.array([4.5, 4.0, 3.0, np.nan])
    s0 = np.zeros((4, 2, 2))
    s0[0, :, 0] = [0.6, 0.6]
    s0[1, :, 0] = [0.9, 0.9]
    s0[2, :, 1] = [0.7, 0.7]
    expect = {"q_final": ([(0, 0), (2, 1)], [False, False, False, True]),
              "q_initial": ([(1, 0), (2, 1)], [False, False, False, True]),
              "new_track": ([(0, 0), (2, 1)], [False, True, False, True])}
    for rule, (pairs, init) in expect.items():
        log = RunLog()
        got, initiate = _settle_conflicts(choice, score, s0, rule, log)
        assert got == pairs and initiate.tolist() == init, rule
        assert log.did_stats["conflicts"] == 1
    with pytest.raises(ValueError, match="conflict"):
        _settle_conflicts(choice, score, s0, "bogus", RunLog())


def test_decision_precision_counts_a_swap_once():
    from assocopt.tracking.scenarios.xue1999_tracker import RunLog
    sc = Xue1999(n_scans=6)
    log = RunLog()
    # one confirmed track: target 0 for three scans, then (one bad decision) target 1
    log.owner, log.confirmed = {7: 0}, {7: True}
    log.sources = {7: [0, 0, 0, 1, 1, 1]}
    log.path = {7: [(k, 0.0, 0.0) for k in range(6)]}
    log.scans = [(np.array([0, 1]), [[7], []], [] if k == 0 else [0], set())
                 for k in range(6)]
    met = run_metrics(log, sc)
    assert met["decision_precision"] == pytest.approx(4 / 5)       # 5 decisions, 1 wrong
    assert met["swaps"] == 1.0
    log.sources = {7: [0, -1, 0, 0]}                 # clutter taken: two wrong decisions
    assert run_metrics(log, sc)["decision_precision"] == pytest.approx(1 / 3)


def test_gnn_tracker_gives_no_track_two_reports_in_a_scan():
    sc = Xue1999(clutter_mean=20.0, noise_scale=2.0)
    log = run_tracker(sc.simulate(np.random.default_rng(7)), "gnn", sc)
    for source, went, _, new in log.scans:
        assoc = [t for w in went for t in w if t not in new]
        assert len(assoc) == len(set(assoc))


# ------------------------------------------------------------- reproduction
SMALL = {"n_scans": 12, "clutter_mean": 5.0}


def test_pinned_small_seeded_run():
    from assocopt.experiments import trial_seed
    from assocopt.reproduce import xue1999 as repro
    exp = repro.experiments(1, 0, SMALL, parts=("main",))[0]
    s = exp.settings[0]
    res = repro.trial(s, exp.methods, trial_seed(0, s, 0))
    # did-zm, did-zscore, did-movable and did-q0 were "did", "did-literal", "did-origin"
    # and "did-q0" before the printed reading was added: same numbers
    pinned = {"did-printed": (7 / 22, 0, 0, 0.25, 1.0, 13 / 15),
              "did-dowhile": (4 / 11, 0, 0, 0.5, 1.0, 16 / 17),
              "did-conflict-q0": (17 / 44, 0, 0, 0.5, 1.0, 16 / 17),
              "did-conflict-new": (15 / 44, 0, 0, 0.25, 1.0, 7 / 8),
              "did-zm": (35 / 44, 0, 1, 0.5, 2 / 97, 34 / 45),
              "did-zscore": (8 / 11, 0, 0, 0.5, 1.0, 32 / 37),
              "did-movable": (31 / 44, 0, 0, 1.0, 3 / 97, 5 / 6),
              "did-q0": (1.0, 0, 0, 1.0, 2 / 97, 44 / 47),
              "gnn": (1.0, 0, 0, 1.0, None, 1.0), "nn": (1.0, 0, 0, 1.0, None, 1.0)}
    for m, (rate, swaps, false, held, nonconv, prec) in pinned.items():
        r = res[m]
        assert r["correct_rate"] == pytest.approx(rate), m
        assert r["decision_precision"] == pytest.approx(prec), m
        assert (r["swaps"], r["false_tracks"], r["held_at_end"]) == (swaps, false, held), m
        assert r.get("nonconverged_rate") == (None if nonconv is None else pytest.approx(nonconv))


def test_reproduction_writes_summary_figures_and_resumes(tmp_path):
    from assocopt.reproduce import xue1999 as repro
    opts = {**SMALL, "noise_grid": (1.0, 2.0), "clutter_grid": (0.0,), "sweep_divisor": 1,
            "main_methods": ("did-printed", "gnn"), "sweep_methods": ("did-printed", "nn"),
            "tune_methods": ("did-printed", "did-q0"), "tune_B": (0.05, 0.2),
            "tune_M_prime": (3.0, 6.0), "tune_divisor": 1}
    printed = []
    s = repro.run(2, 1, 3, tmp_path, options=opts, echo=printed.append)
    data = json.loads((tmp_path / "summary.json").read_text())
    assert data["paper"] == "xue1999" and data["runs"] == 2 and data["tune_runs"] == 2
    assert {r["experiment"] for r in data["records"]} == {"tune", "main", "sweep"}
    assert all(r["runs"] == 2 for r in data["records"] if r["metric"] == "correct_rate")
    assert "did_scale" in data["parameters"]["ours"]["ours"]
    # the tuning grid: every method at every pair; the best of each joins main and sweep
    tune = {r["method"] for r in data["records"] if r["experiment"] == "tune"}
    assert len(tune) == 2 * 2 * 2
    assert data["tuned"] == repro.best_pairs(data["records"], opts)
    main = {r["method"] for r in data["records"] if r["experiment"] == "main"}
    sweep = {r["method"] for r in data["records"] if r["experiment"] == "sweep"}
    best = {m: b["method"] for m, b in data["tuned"].items()}
    at_best = {m + best["did-printed"][len("did-printed"):]
               for m in repro.DEFAULTS["at_printed_best"]}
    assert main == {"did-printed", "gnn", best["did-printed"], best["did-q0"]} | at_best
    assert sweep == {"did-printed", "nn", best["did-printed"]}
    rate = {r["method"]: r["value"] for r in data["records"]
            if r["experiment"] == "tune" and r["metric"] == "correct_rate"}
    for m, b in data["tuned"].items():
        grid = [v for n, v in rate.items() if n.startswith(m + "@")]
        assert b["correct_rate"] == max(grid) and b["range"] == [min(grid), max(grid)]
    for part in ("Tuning: best (B, M′)", "Base scene", "Sweep: correct association rate",
                 "Sweep: decision precision"):
        assert part in printed[0], part
    for f in s["figures"]:
        assert (tmp_path / f).stat().st_size > 0
    again = repro.run(2, 1, 3, tmp_path, options=opts, echo=lambda t: None)
    assert all(v["done"] == 0 for v in again["timing"].values())
    stable = lambda recs: sorted((json.dumps(r["setting"], sort_keys=True), r["method"],
                                  r["metric"], r["value"]) for r in recs if not r["volatile"])
    assert stable(again["records"]) == stable(s["records"])


@pytest.mark.slow
def test_reproduction_same_numbers_with_two_workers(tmp_path):
    from assocopt.reproduce import xue1999 as repro
    opts = {**SMALL, "n_scans": 8, "main_methods": ("did-printed", "gnn")}
    one = repro.run(3, 1, 5, tmp_path / "a", options=opts, parts=("main",), echo=lambda t: None)
    two = repro.run(3, 2, 5, tmp_path / "b", options=opts, parts=("main",), echo=lambda t: None)
    pick = lambda s: sorted((r["method"], r["metric"], r["value"]) for r in s["records"]
                            if not r["volatile"])
    assert pick(one) == pick(two)


def test_main_part_runs_a_method_once_when_its_best_is_the_printed_best():
    from assocopt.reproduce import xue1999 as repro
    tuned = {"did-printed": "did-printed@B=0.002,Mp=20",
             "did-conflict-q0": "did-conflict-q0@B=0.002,Mp=20"}
    exp = repro.experiments(2, 0, parts=("main",), tuned=tuned)[0]
    assert len(exp.methods) == len(set(exp.methods))
    assert "did-conflict-q0@B=0.002,Mp=20" in exp.methods


def _verdict_summary(rates):
    """A summary with main-part correct rates {method: (value, stderr)} and every
    method but GNN tuned (best pair on the tuning seeds = the same value)."""
    recs = [{"experiment": "main", "metric": "correct_rate", "method": m, "value": v,
             "runs": 100, "stderr": se, "setting": {"noise_scale": 1.0, "clutter_mean": 10.0}}
            for m, (v, se) in rates.items()]
    tuned = {m.split("@")[0]: {"method": m, "correct_rate": v, "B": 0.02, "M_prime": 6.0,
                               "range": [0.0, v]}
             for m, (v, _) in rates.items() if m != "gnn"}
    return {"records": recs, "tuned": tuned}


def test_below_gnn_needs_the_95_percent_intervals_apart():
    from assocopt.reproduce.xue1999.report import below_gnn, render_verdict
    s = _verdict_summary({"gnn": (0.99, 0.002), "did-printed@B=0.02,Mp=6": (0.98, 0.002),
                          "did-q0@B=0.02,Mp=6": (0.985, 0.002),
                          "did-zm@B=0.02,Mp=6": (0.999, 0.001)})
    # 0.98 + 1.96 (0.002 + 0.002) = 0.9878 < 0.99; 0.985 + 0.0078 > 0.99;
    # 0.999 - 1.96 (0.001 + 0.002) = 0.9931 > 0.99
    assert below_gnn(s) == {"did-printed": "below", "did-q0": "overlapping",
                            "did-zm": "above"}
    lines = render_verdict(s)
    assert "1 of 3 below GNN, 1 of 3 not apart from GNN, 1 of 3 above GNN" in lines[0]
    assert lines[-1].startswith("- best reading on the tuning seeds: DID, z-score error "
                                "+ movable selection (ours), at B = 0.02, M′ = 6 (0.999)")


def test_reproduction_rejects_unknown_options_and_methods():
    from assocopt.reproduce import xue1999 as repro
    with pytest.raises(ValueError, match="unknown xue1999 option"):
        repro.experiments(2, 0, {"bogus": 1})
    with pytest.raises(ValueError, match="unknown xue1999 method"):
        repro.experiments(2, 0, {"sweep_methods": ("jpda",)})
    with pytest.raises(ValueError, match="not a DID method"):
        repro.experiments(2, 0, {"tune_methods": ("gnn",)})
    with pytest.raises(ValueError, match="tune_divisor"):
        repro.experiments(2, 0, {"tune_divisor": 0})


# ------------------------------------------------------------- the page
PAGE = ROOT / "docs" / "papers" / "xue1999.md"
SUMMARY = ROOT / "docs" / "papers" / "xue1999" / "summary.json"


def test_page_tables_match_the_committed_summary():
    from assocopt.reproduce import xue1999 as repro
    summary = check_page_against_summary(repro, "xue1999", PAGE, SUMMARY)
    assert summary["runs"] == 200 and summary["seed"] == 0
    text = PAGE.read_text(encoding="utf-8")
    assert page_block(text, "example") == repro.render_example().strip()
    assert page_block(text, "run") == repro.render_run(summary).strip()
    # the tuning grid and its best pairs are in the summary, and the tuned methods were
    # re-run in the main comparison and the sweep
    assert summary["tuned"] == repro.best_pairs(summary["records"])
    assert set(summary["tuned"]) == set(repro.DEFAULTS["tune_methods"])
    tune = {r["method"] for r in summary["records"] if r["experiment"] == "tune"}
    assert len(tune) == (len(repro.DEFAULTS["tune_methods"]) * len(repro.DEFAULTS["tune_B"])
                         * len(repro.DEFAULTS["tune_M_prime"]))
    main = {r["method"] for r in summary["records"] if r["experiment"] == "main"}
    assert {b["method"] for b in summary["tuned"].values()} <= main
    # every DID reading the page shows is tuned, and its best B lies strictly inside the
    # B grid (an optimum on the edge may lie beyond it)
    assert set(summary["tuned"]) == {m for m in repro.METHODS if m.startswith("did-")}
    Bs = repro.DEFAULTS["tune_B"]
    for m, b in summary["tuned"].items():
        assert min(Bs) < b["B"] < max(Bs), m
    # the paper's own reading, tuned, leads, beside GNN
    head = page_block(text, "headline").splitlines()
    assert head[0].startswith("- tuned: " + repro.LABELS["did-printed"] + ", at B = ")
    assert head[1].startswith("- " + repro.LABELS["gnn"])


def test_page_text_says_what_the_committed_run_shows():
    """The claims the page's prose makes, checked against the committed summary."""
    from assocopt.reproduce import xue1999 as repro
    from assocopt.reproduce.xue1999.report import below_gnn
    summary = json.loads(SUMMARY.read_text())
    text = " ".join(PAGE.read_text(encoding="utf-8").split())
    main = {m: {k[0]: v[0] for k, v in repro.lookup(summary["records"], "main", m).items()}
            for m in ("correct_rate", "decision_precision", "false_tracks")}
    tuned = {m: b["method"] for m, b in summary["tuned"].items()}
    side = below_gnn(summary)
    # "below GNN" survives for the paper's own reading and every single change; the
    # combined corrections with q from stage 1 are level with GNN (intervals overlap)
    assert "\"below GNN\" survives for the paper's own reading" in text
    assert side["did-printed"] == "below"
    assert {m for m, w in side.items() if w != "below"} == {"did-q0"}
    assert side["did-q0"] == "overlapping" and side["did-zm"] == "below"
    assert 0 < main["correct_rate"]["gnn"] - main["correct_rate"][tuned["did-zm"]] < 0.05
    # the printed rule, tuned: about five in six, fewer precise decisions and more false
    # tracks than untuned; best at B = 0.002, M' = 20, shared by the do-while reading
    car, prec, false = (main[k][tuned["did-printed"]] for k in main)
    assert abs(car - 5 / 6) < 0.02
    assert prec < main["decision_precision"]["did-printed"]
    assert false > main["false_tracks"]["did-printed"] > main["false_tracks"]["gnn"]
    assert (summary["tuned"]["did-printed"]["B"], summary["tuned"]["did-printed"]["M_prime"]) \
        == (0.002, 20.0) and "B = 0.002, a tenth of the old grid's smallest value" in text
    assert tuned["did-dowhile"].split("@")[1] == tuned["did-printed"].split("@")[1]
    # the variants at the printed rule's best pair: same correct rate within the intervals
    ci = {k[0]: v for k, v in repro.lookup(summary["records"], "main", "correct_rate").items()}
    p = ci[tuned["did-printed"]]
    for m in repro.DEFAULTS["at_printed_best"]:
        assert tuned[m].split("@")[1] == tuned["did-printed"].split("@")[1], m
        v = ci[tuned[m]]
        assert abs(v[0] - p[0]) < 1.96 * (v[2] + p[2]), m
    # majority, tuned: about nine in ten; z-score alone, tuned: the most precise reading
    assert abs(main["correct_rate"][tuned["did-majority"]] - 0.9) < 0.02
    assert abs(main["correct_rate"][tuned["did-zscore"]] - 0.9) < 0.02
    precise = max(tuned, key=lambda m: main["decision_precision"][tuned[m]])
    assert precise == "did-zscore"
    # the combined corrections with q from stage 1: below GNN in precision, false tracks
    q0 = tuned["did-q0"]
    assert main["decision_precision"][q0] < main["decision_precision"]["gnn"] - 0.1
    assert main["false_tracks"][q0] > main["false_tracks"]["gnn"] + 1
    # the sweep: the printed rule below GNN and NN everywhere, tuned above untuned but
    # with more false tracks wherever there is clutter; q0 tuned >= GNN only at low noise
    car = repro.lookup(summary["records"], "sweep", "correct_rate")
    ft = repro.lookup(summary["records"], "sweep", "false_tracks")
    cells = {(f, c) for _, f, c in car}
    pt, qt = tuned["did-printed"], tuned["did-q0"]
    for f, c in cells:
        for m in ("did-printed", pt):
            assert car[(m, f, c)][0] < min(car[("gnn", f, c)][0], car[("nn", f, c)][0])
        assert car[(pt, f, c)][0] > car[("did-printed", f, c)][0]
        if c > 0:
            assert ft[(pt, f, c)][0] > ft[("did-printed", f, c)][0]
        at_or_above = car[(qt, f, c)][0] >= car[("gnn", f, c)][0]
        assert at_or_above == ((f, c) in {(0.5, 0.0), (0.5, 10.0), (0.5, 30.0), (1.0, 0.0)}), (f, c)
    # at the tuned pairs stage 2 rarely settles within the cap, the movable selection too
    nonconv = {k[0]: v[0] for k, v in
               repro.lookup(summary["records"], "main", "nonconverged_rate").items()}
    assert all(nonconv[tuned[m]] > 0.9 for m in tuned if m != "did-q0")
    assert nonconv[tuned["did-q0"]] < 0.9 and nonconv["did-movable"] < 0.1
    # every best pair strictly inside the M' grid as well
    Mps = repro.DEFAULTS["tune_M_prime"]
    assert all(min(Mps) < b["M_prime"] < max(Mps) for b in summary["tuned"].values())
