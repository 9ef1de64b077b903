"""The compiled branch and bound back end ``bnb`` and its kernels.

Exactness on random S-D problems (N = 3..5, with and without dummies, integer and
float costs) against brute force; every path out of the kernel (proof during the
ascent, by a probe, by the final search, node budget with and without fallback,
too large for dense matrices, infeasible); the Hungarian kernel against scipy; the
``auto`` choice.  The generic conformance suite (tests/test_conformance.py) and the
known optima (tests/test_known_optima.py) run ``bnb`` as well.  No timing asserts.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linear_sum_assignment

from assocopt import (AssignmentProblem, InvalidProblemError, ProblemTooLargeError,
                      Status, choose_solver, solve)
from assocopt.testing import assert_feasible, assert_optimal

from conftest import sd_problems

pytest.importorskip("numba", reason="the bnb back end needs numba")

from assocopt.solvers.bnb import backend as bnb  # noqa: E402
from assocopt.solvers.bnb import kernels as kern  # noqa: E402
from assocopt.solvers.kernels import relaxation as kern_relax  # noqa: E402


@given(sd_problems())
def test_equals_brute_force(p):
    assert_optimal(p, solve(p, "bnb"))


@settings(max_examples=40)
@given(sd_problems(), st.sampled_from([
    {"probe_every": 0}, {"recover_every": 0}, {"max_iter": 0}, {"max_iter": 1},
    {"deflect": 0.0, "patience": 1}, {"keep_axes": (0, 2)}, {"probe_nodes": 1},
    {"warm_start": False}, {"stall_tol": 0.5},
]))
def test_every_option_setting_stays_exact(p, opts):
    sol = solve(p, "bnb", **opts)
    assert_optimal(p, sol)
    assert "bnb" not in sol.info          # proven by the kernel, not the fallback


@settings(max_examples=30)
@given(sd_problems())
def test_node_budget_without_fallback_gives_valid_bound(p):
    ref = solve(p, "bruteforce")
    sol = solve(p, "bnb", max_nodes=1, probe_every=0, max_iter=1, recover_every=0,
                fallback=False)
    if sol.status is Status.OPTIMAL:
        assert_optimal(p, sol)
        return
    assert sol.status is Status.NODE_LIMIT, sol.message      # no time limit was given
    if sol.bound is not None:
        assert sol.bound <= ref.objective + 1e-9 * max(1.0, abs(ref.objective))
    if sol.selected is not None:
        assert_feasible(p, sol)


def test_node_budget_falls_back_to_lagrangian_exact():
    p = AssignmentProblem.dense(np.random.default_rng(3).random((7, 7, 7)))
    sol = solve(p, "bnb", max_nodes=1, probe_every=0, max_iter=1, recover_every=0)
    assert_optimal(p, sol)
    assert "lagrangian-exact" in sol.message and sol.info["bnb"]["nodes"] >= 1


@pytest.mark.parametrize("limit", ["MAX_DENSE", "MAX_KEPT"])
def test_too_large_for_dense_matrices(monkeypatch, limit):
    monkeypatch.setattr(bnb, limit, 7)
    p = AssignmentProblem.dense(np.random.default_rng(1).random((4, 4, 4)))
    sol = solve(p, "bnb")
    assert_optimal(p, sol)
    assert limit in sol.message
    with pytest.raises(ProblemTooLargeError, match="dense"):
        solve(p, "bnb", fallback=False)


def test_auto_leaves_large_sparse_problems_to_lagrangian_exact():
    # 300 x 300 x 3 with 1,500 candidates: few candidates, but a 600 x 600 Hungarian
    rng = np.random.default_rng(0)
    n = 300
    singles = np.zeros((2 * n + 3, 3), np.int64)
    singles[:n, 0] = singles[n:2 * n, 1] = np.arange(1, n + 1)
    singles[2 * n:, 2] = [1, 2, 3]
    pairs = np.stack([rng.integers(1, n + 1, 900), rng.integers(1, n + 1, 900),
                      rng.integers(0, 4, 900)], axis=1)
    T = np.unique(np.concatenate([singles, pairs]), axis=0)
    p = AssignmentProblem.sparse((n, n, 3), T, rng.normal(size=len(T)))
    assert choose_solver(p) == "lagrangian-exact"


def test_infeasible_problems():
    # the kept axes cannot be matched: both rows of axis 0 need row 1 of axis 1
    p = AssignmentProblem.sparse((2, 2, 2), [[1, 1, 1], [2, 1, 2]], [1.0, 2.0])
    assert solve(p, "bnb").status is Status.INFEASIBLE
    # every index has a candidate, the kept-axes matching exists, no exact cover does
    T = [[1, 1, 1], [2, 2, 1], [1, 2, 2], [2, 1, 2]]
    p = AssignmentProblem.sparse((2, 2, 2), T, [1.0, 1.0, 1.0, 1.0])
    assert solve(p, "highs").status is Status.INFEASIBLE
    assert solve(p, "bnb").status is Status.INFEASIBLE


def test_deterministic_and_records_parameters():
    p = AssignmentProblem.dense(np.random.default_rng(2).random((8, 8, 8)))
    a, b = solve(p, "bnb"), solve(p, "bnb")
    assert np.array_equal(a.selected, b.selected)
    assert a.info["iterations"] == b.info["iterations"] and a.info["nodes"] == b.info["nodes"]
    assert set(bnb.DEFAULTS) <= set(a.info["parameters"])
    assert a.info["parameters"]["keep_axes"] == [0, 1]


def test_integer_costs_are_detected():
    p = AssignmentProblem.dense(np.random.default_rng(4).integers(0, 50, (6, 6, 6)))
    sol = solve(p, "bnb")
    assert sol.info["integer_costs"] is True and sol.bound == sol.objective
    assert_optimal(p, sol)


@pytest.mark.parametrize("opts, match", [
    ({"bogus": 1}, "bogus"), ({"max_nodes": 0}, "max_nodes"), ({"patience": 0}, "patience"),
    ({"step0": 0.0}, "step0"), ({"deflect": 1.0}, "deflect"), ({"max_iter": -1}, "max_iter"),
    ({"keep_axes": (1, 1)}, "keep_axes"), ({"keep_axes": (0, 7)}, "keep_axes"),
    ({"stall_tol": 1.0}, "stall_tol"),
])
def test_bad_options_are_named(opts, match):
    p = AssignmentProblem.dense(np.ones((3, 3, 3)))
    with pytest.raises(InvalidProblemError, match=match):
        solve(p, "bnb", **opts)


def test_lp_relaxation_is_refused():
    with pytest.raises(Exception, match="LP"):
        solve(AssignmentProblem.dense(np.ones((2, 2, 2))), "bnb", relax="lp")


def test_auto_picks_bnb_for_small_sd():
    small = AssignmentProblem.dense(np.random.default_rng(0).random((5, 5, 5)))
    assert choose_solver(small) == "bnb"
    sol = solve(small)
    assert sol.solver == "bnb"
    assert_optimal(small, sol)


def test_auto_without_numba_uses_lagrangian_exact(monkeypatch):
    import assocopt.solving.choice as api
    monkeypatch.setattr(api, "_numba_installed", lambda: False)
    assert choose_solver(AssignmentProblem.dense(np.ones((3, 3, 3)))) == "lagrangian-exact"


# ------------------------------------------------------------------- kernels
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 9), st.sampled_from([0.0, 0.3]))
def test_hungarian_matches_scipy_with_feasible_duals(seed, n, forbid):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A[rng.random((n, n)) < forbid] = np.inf
    np.fill_diagonal(A, rng.normal(size=n))          # a finite matching exists
    ok, col, u, v, cost = kern.hungarian(A)
    r, c = linear_sum_assignment(np.where(np.isfinite(A), A, 1e12))
    assert ok
    assert cost == pytest.approx(A[r, c].sum(), abs=1e-9)
    assert sorted(col.tolist()) == list(range(n))
    assert A[np.arange(n), col].sum() == pytest.approx(cost, abs=1e-9)
    finite = np.isfinite(A)
    slack = A - u[:, None] - v[None, :]
    assert (slack[finite] >= -1e-9).all()                         # dual feasible
    assert np.allclose(slack[np.arange(n), col], 0.0, atol=1e-9)   # tight on the matching
    assert u.sum() + v.sum() == pytest.approx(cost, abs=1e-9)


@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 9), st.sampled_from([0.0, 0.3]))
def test_hungarian_warm_start_from_any_potentials(seed, n, forbid):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A[rng.random((n, n)) < forbid] = np.inf
    np.fill_diagonal(A, rng.normal(size=n))
    cold = kern.hungarian(A)
    ok, col, u, v, cost = kern.hungarian_warm(A, rng.normal(scale=3.0, size=n))
    assert ok and cost == pytest.approx(cold[4], abs=1e-9)
    assert A[np.arange(n), col].sum() == pytest.approx(cost, abs=1e-9)
    slack = A - u[:, None] - v[None, :]
    assert (slack[np.isfinite(A)] >= -1e-9).all()
    assert np.allclose(slack[np.arange(n), col], 0.0, atol=1e-9)


def test_hungarian_reports_no_matching():
    A = np.array([[1.0, np.inf], [2.0, np.inf]])
    assert kern.hungarian(A)[0] is False


@given(st.integers(0, 2 ** 32 - 1), st.integers(0, 400),
       st.sampled_from(["uniform", "few values", "mostly zero", "all equal", "huge"]))
def test_stable_order_is_a_stable_sort(seed, m, kind):
    """The bucket sort of the search's candidate lists equals numpy's stable sort."""
    rng = np.random.default_rng(seed)
    v = {"uniform": rng.random(m + 5), "few values": rng.integers(0, 4, m + 5) * 0.5,
         "mostly zero": np.where(rng.random(m + 5) < 0.7, 0.0, rng.random(m + 5) ** 8 * 1e6),
         "all equal": np.full(m + 5, 2.5),
         "huge": rng.choice([-1e300, 0.0, 1e300], m + 5)}[kind]
    keep = np.sort(rng.choice(m + 5, size=m, replace=False)).astype(np.int64)
    assert kern_relax.stable_order(v, keep).tolist() == \
        keep[np.argsort(v[keep], kind="stable")].tolist()


@given(sd_problems(), st.integers(0, 2 ** 32 - 1), st.floats(0.0, 3.0))
def test_sort_lists_sorts_each_row_by_reduced_cost(p, seed, slack):
    """Every row's list keeps the candidates under ``slack``, cheapest first, ties by
    candidate (the search's order), as a per-row stable sort gives: the compiled
    kernel (one bucket sort) and its plain twin (a numpy sort per row) alike."""
    T = np.ascontiguousarray(p.tuples, np.int64)
    G, ptr, lst, *_ = kern_relax.prepare(T, p.row_offsets, np.asarray(p.sizes, np.int64),
                                         np.ascontiguousarray(p.costs, np.float64), 0, 1)
    rp = np.round(np.random.default_rng(seed).random(p.n_candidates) * 3, 1)
    from assocopt.solvers.kernels import tiers
    for sort_lists in (kern_relax.sort_lists, tiers.plain("relaxation.sort_lists")):
        sptr, slst = sort_lists(ptr, lst, rp, slack)    # compiled, and as plain Python
        for e in range(len(ptr) - 1):
            row = [k for k in lst[ptr[e]:ptr[e + 1]] if rp[k] < slack]
            assert slst[sptr[e]:sptr[e + 1]].tolist() == sorted(row, key=lambda k: (rp[k], k))


@given(sd_problems(), st.integers(0, 2 ** 32 - 1))
def test_reduced_cost_bound_is_valid_for_any_dual(p, seed):
    """base + sum of max(r, 0) over the optimum never exceeds the optimum."""
    ref = solve(p, "bruteforce")
    if ref.status is not Status.OPTIMAL:
        return
    inp = bnb.BnbInput.build(p)
    y = np.random.default_rng(seed).normal(size=len(inp.axis_of))
    rp = np.empty(p.n_candidates)
    base = kern.reduced(inp.G, inp.c, y, rp, inp.ptr, inp.lst, inp.axis_of)
    assert base + rp[ref.selected].sum() <= ref.objective + 1e-9 * max(1, abs(ref.objective))


def test_cli_says_when_it_compiles(monkeypatch, capsys):
    from pathlib import Path
    from assocopt.cli import main
    # a one-shot default solve of a stored instance this small goes to HiGHS (no
    # kernels to load): bnb asked for by name
    example = Path(__file__).resolve().parents[1] / "instances" / "sd-bearing-3s.json"
    monkeypatch.setenv("ASSOCOPT_JIT", "compiled")      # small: else run interpreted
    monkeypatch.setattr(kern, "cached", lambda: False)
    assert main(["solve", str(example), "--solver", "bnb"]) == 0
    err = capsys.readouterr().err
    assert err.startswith("assocopt: compiling the numba kernels") and err.count("\n") == 1
    monkeypatch.setattr(kern, "cached", lambda: True)
    assert main(["solve", str(example), "--solver", "bnb"]) == 0
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(kern, "cached", lambda: False)
    assert main(["solve", str(example), "--solver", "highs"]) == 0
    assert capsys.readouterr().err == ""


def test_cli_prints_how_long_compilation_took(monkeypatch, capsys):
    """A solve that compiled kernels (times["compile"] > 0) ends with one stderr line
    giving the time, whether or not the cache check announced it beforehand."""
    from pathlib import Path

    import assocopt.solving.api
    from assocopt.cli import main
    example = Path(__file__).resolve().parents[1] / "instances" / "sd-bearing-3s.json"
    real = assocopt.solving.api.solve

    def compiled(*args, **kwargs):
        sol = real(*args, **kwargs)
        sol.times["compile"] = 12.34
        return sol
    monkeypatch.setattr(assocopt.solving.api, "solve", compiled)
    monkeypatch.setenv("ASSOCOPT_JIT", "compiled")
    monkeypatch.setattr(kern, "cached", lambda: True)
    assert main(["solve", str(example), "--solver", "bnb"]) == 0
    assert capsys.readouterr().err == ("assocopt: compiled the numba kernels in 12.3 s "
                                       "(first run only; cached afterwards)\n")
    monkeypatch.setattr(kern, "cached", lambda: False)
    assert main(["solve", str(example), "--solver", "bnb"]) == 0
    assert capsys.readouterr().err == ("assocopt: compiling the numba kernels (first run "
                                       "only, about 15-30 s; cached afterwards) ... done in "
                                       "12.3 s\n")


def test_compile_and_cache_load_are_reported_apart(monkeypatch):
    """Kernel compilation / cache loading during a solve appears as times["compile"] /
    times["cache_load"] (and info fields), and is not counted in build or solve."""
    from assocopt.solvers import kernels

    monkeypatch.setenv("ASSOCOPT_JIT", "compiled")
    p = AssignmentProblem.dense(np.random.default_rng(3).random((4, 4, 4)))
    solve(p, "bnb")                              # kernels in memory now
    warm = solve(p, "bnb")
    assert "compile" not in warm.times and "compile_time" not in warm.info
    # pretend the kernels are not in memory: ensure() compiles / loads again
    calls = []

    def slow_ensure(kernel, *args):
        calls.append(kernel)
        kernels._SPENT["cache_load"] += 0.5      # as if loading took half a second
    monkeypatch.setattr(kernels, "ensure", slow_ensure)   # pick() compiles through it
    sol = solve(p, "bnb")
    assert {kern.prepare, kern.solve} <= set(calls)
    assert sol.times["cache_load"] == pytest.approx(0.5 * len(calls))
    assert sol.info["cache_load_time"] == sol.times["cache_load"]
    assert sol.times["compile"] == 0.0
    assert sol.times["build"] < 0.5 and sol.times["solve"] < 0.5


def test_ensure_times_a_fresh_specialisation():
    """ensure() adds exactly one specialisation and books its time as compile or
    cache load; a second call for the same types does nothing."""
    from numba import njit

    from assocopt.solvers import kernels

    @njit(cache=False)
    def twice(x):
        return 2 * x
    before = sum(kernels.spent())
    kern.ensure(twice, 3.0)
    assert len(twice.overloads) == 1
    mid = sum(kernels.spent())
    assert mid > before                          # compiled (no cache): counted
    kern.ensure(twice, 4.0)
    assert sum(kernels.spent()) == mid and len(twice.overloads) == 1
    assert twice(4.0) == 8.0 and len(twice.overloads) == 1


def test_a_bnb_solve_loads_only_the_kernels_it_calls():
    """In a fresh process, a bnb solve gives ``prepare`` and ``solve`` one
    specialisation each (loaded from the disk cache, or compiled with their callees on
    a first run), though the cache may hold others (the window search calls
    ``prepare`` with other types)."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    code = ("import json, numpy as np\n"
            "from assocopt import AssignmentProblem, solve\n"
            "from assocopt.solvers.bnb import kernels as k\n"
            "p = AssignmentProblem.dense(np.random.default_rng(1).random((4, 4, 4)))\n"
            "sol = solve(p, 'bnb')\n"
            "names = ['prepare', 'solve']\n"
            "print(json.dumps({n: len(getattr(k, n).overloads) for n in names}))\n")
    env = dict(os.environ, PYTHONPATH=str(root), ASSOCOPT_JIT="compiled")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, timeout=600).stdout
    loaded = json.loads(out.splitlines()[-1])
    assert loaded == {"prepare": 1, "solve": 1}


# ---------------------------------------------------------- N = 3 primal recovery
@st.composite
def _recovery_inputs(draw):
    """Gated N = 3 candidates in which every third-axis index has its single, and a
    relaxed solution's pairs (distinct kept-axes pairs, not both dummies)."""
    na, nb, nc = (draw(st.integers(1, 3)) for _ in range(3))
    tuples = [(0, 0, t) for t in range(1, nc + 1)]
    pairs = [(i, j) for i in range(na + 1) for j in range(nb + 1) if i or j]
    for i, j in pairs:
        for t in range(nc + 1):
            if draw(st.booleans()):
                tuples.append((i, j, t))
    T = np.array(tuples, np.int64)
    c = np.array(draw(st.lists(st.integers(-9, 9), min_size=len(T), max_size=len(T))),
                 float)
    have = sorted({(int(i), int(j)) for i, j, _ in T if i or j})
    chosen_pairs = draw(st.lists(st.sampled_from(have), unique=True, max_size=4)) \
        if have else []
    chosen = np.zeros(len(T), np.int8)
    for i, j in chosen_pairs:
        chosen[np.flatnonzero((T[:, 0] == i) & (T[:, 1] == j))[0]] = 1
    return T, c, chosen, (na, nb, nc)


def _recovery_brute(T, c, chosen, nc):
    """Least cost of attaching the third axis to the chosen pairs (or None)."""
    import itertools
    cost = {tuple(int(v) for v in t): float(x) for t, x in zip(T, c)}
    pairs = [(int(T[k, 0]), int(T[k, 1])) for k in np.flatnonzero(chosen)]
    best = None
    for pick in itertools.product(range(nc + 1), repeat=len(pairs)):
        used = [t for t in pick if t]
        if len(used) != len(set(used)):
            continue
        keys = [p + (t,) for p, t in zip(pairs, pick)] + \
            [(0, 0, t) for t in range(1, nc + 1) if t not in used]
        if all(k in cost for k in keys):
            v = sum(cost[k] for k in keys)
            best = v if best is None else min(best, v)
    return best


@settings(max_examples=60, deadline=None)
@given(_recovery_inputs())
def test_recover3_sparse_equals_dense_and_brute_force(case):
    """The sparse recovery LAP (gated: every index has its single) finds the same
    least cost as the dense Hungarian and as enumeration, with a valid selection."""
    from assocopt.solvers.kernels.driver import recover3
    T, c, chosen, (na, nb, nc) = case
    idx = np.full((na + 1) * (nb + 1) * (nc + 1), -1, np.int64)
    idx[(T[:, 0] * (nb + 1) + T[:, 1]) * (nc + 1) + T[:, 2]] = np.arange(len(T))
    ref = _recovery_brute(T, c, chosen, nc)
    got = []
    for sparse in (True, False):
        sel = np.empty(len(T) + 1, np.int64)
        n, cost = recover3(c, T[:, 0].copy(), T[:, 1].copy(), chosen, idx, nb, nc, sel,
                           sparse)
        if ref is None:
            assert n == -1
            continue
        assert n > 0 and cost == pytest.approx(ref)
        picked = sel[:n]
        assert c[picked].sum() == pytest.approx(cost)
        assert sorted(T[picked, 2][T[picked, 2] > 0].tolist()) == list(range(1, nc + 1))
        got.append(cost)
    if got:
        assert got[0] == pytest.approx(got[1])


def _search_args(p: AssignmentProblem, seed: int, ub: float, budget: int) -> tuple:
    """The search's arguments on ``p``: reduced costs and bound of random duals (a
    loose bound, so that the search branches and backtracks)."""
    T = np.ascontiguousarray(p.tuples, np.int64)
    c = np.ascontiguousarray(p.costs, np.float64)
    G, ptr, lst, _, axis_of, int_costs, _ = kern_relax.prepare(
        T, p.row_offsets, np.asarray(p.sizes, np.int64), c, 0, 1)
    y = np.random.default_rng(seed).normal(-0.3, 0.3, len(axis_of))
    rp = np.empty(p.n_candidates)
    base = kern_relax.reduced(G, c, y, rp, ptr, lst, axis_of)
    sptr, slst = kern_relax.sort_lists(ptr, lst, rp, np.inf)
    return (G, c, rp, base, sptr, slst, axis_of, p.ndim, bool(int_costs), 1e-9, ub,
            np.full(p.n_rows + 1, -1, np.int64), -1, budget, np.zeros(1, np.int64),
            -np.inf)


def _scattered(seed: int, n: int, k: int) -> AssignmentProblem:
    """N = 4, ``n`` indices an axis (4n rows: one or two bit words), ``k`` random
    tuples plus every single-index one (so that a cover exists)."""
    rng = np.random.default_rng(seed)
    T = rng.integers(0, n + 1, size=(k, 4))
    singles = np.zeros((4 * n, 4), np.int64)
    for s in range(4):
        singles[s * n:(s + 1) * n, s] = np.arange(1, n + 1)
    T = np.unique(np.concatenate([T[(T > 0).sum(axis=1) >= 2], singles]), axis=0)
    c = np.where((T > 0).sum(axis=1) == 1, 0.0, rng.normal(-1.0, 1.0, len(T)))
    return AssignmentProblem.sparse((n,) * 4, T, c)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("n", [5, 15, 30])
@pytest.mark.parametrize("budget", [30, 1000, 100_000])
def test_bit_word_search_visits_the_same_nodes_as_the_counting_one(seed, n, budget):
    """Up to 126 rows the search keeps the covered rows as bit words; it must return
    exactly what the counting search returns (outcome, incumbent, its cost, nodes),
    on one word (20, 60 rows) and two (120), with a node budget that ends it or not
    and with or without an incumbent to beat; compiled, and as plain Python (on the
    smaller budgets: the plain twins take about 0.1 ms a node)."""
    from assocopt.solvers.kernels import search, tiers
    p = _scattered(seed, n, 12 * n)
    fns = [search._dfs_bits, search._dfs_counts]
    if budget <= 1000:
        plain = tiers._twin("search")          # the module loaded as plain Python
        fns += [plain._dfs_bits, plain._dfs_counts]
    for ub in (np.inf, -0.5 * n):
        answers = []
        for fn in fns:
            args = _search_args(p, seed, ub, budget)
            out, u, n_sel, nodes = fn(*args)
            answers.append((out, u, sorted(args[11][:n_sel].tolist()), nodes))
        assert all(a == answers[0] for a in answers[1:])
        assert answers[0][3] > 0
        assert search.dfs(*_search_args(p, seed, ub, budget))[3] == answers[0][3]


@pytest.mark.parametrize("seed", range(8))
def test_greedy_cover_is_an_exact_cover_taken_in_key_order(seed):
    """``greedy_cover`` (bnb's first incumbent at N >= 4): with every single-index
    candidate present it always covers; its cover is exact, costs what it says, and
    each candidate it skipped clashes with one taken before it in key order; without
    the singles it may fail, and then says so."""
    from assocopt.solvers.kernels.greedy import greedy_cover
    p = _scattered(seed, 6, 60)
    G = kern_relax.prepare(np.ascontiguousarray(p.tuples, np.int64), p.row_offsets,
                           np.asarray(p.sizes, np.int64), p.costs, 0, 1)[0]
    key = np.random.default_rng(seed).normal(size=p.n_candidates)
    sel = np.full(p.n_rows + 1, -1, np.int64)
    n, cost = greedy_cover(G, p.costs, key, p.n_rows, sel)
    chosen = sel[:n]
    assert n > 0 and p.violations(np.sort(chosen)) is None
    assert cost == pytest.approx(p.costs[chosen].sum())
    rank = np.argsort(np.argsort(key, kind="stable"), kind="stable")
    rows = [set(G[k][G[k] >= 0]) for k in range(p.n_candidates)]
    for k in set(range(p.n_candidates)) - set(chosen.tolist()):
        if rank[k] < max(rank[chosen]):
            assert any(rows[k] & rows[j] for j in chosen if rank[j] < rank[k])
    multi = np.flatnonzero((p.tuples > 0).sum(axis=1) >= 2)   # no singles: a clash
    q = AssignmentProblem.sparse(p.sizes, p.tuples[multi], p.costs[multi])
    Gq = kern_relax.prepare(np.ascontiguousarray(q.tuples, np.int64), q.row_offsets,
                            np.asarray(q.sizes, np.int64), q.costs, 0, 1)[0]
    n, cost = greedy_cover(Gq, q.costs, q.costs, q.n_rows, sel)
    assert (n == -1 and cost == np.inf) or q.violations(np.sort(sel[:n])) is None
