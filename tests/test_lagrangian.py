"""Lagrangian relaxation back ends (``lagrangian``, ``lagrangian-exact``), the 2-D LAP
helpers they run on, and the optional ``lapjv`` back end.

Properties on random S-D problems (N = 3..5, with and without dummies): every
reported bound is a valid lower bound (also ``L(u)`` at random multipliers), the
exact mode equals brute force, ``OPTIMAL`` is only claimed with a proof.  Known
optima of the shared 3-AP instances: n <= 10 here, all 120 behind ``-m slow``.
No wall-clock assertions.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assocopt import (AssignmentProblem, InvalidProblemError, SolverNotInstalledError,
                      Status, choose_solver, solve)
from assocopt.solvers import lagrangian as lg
from assocopt.solvers import registered
from assocopt.solvers.twod.lap import (LapInfeasibleError, assign_with_misses,
                                  assignment_duals, lapx_available, linear_assignment)
from assocopt.testing import assert_feasible, assert_optimal, random_problem, random_scans

from conftest import AP_INSTANCES, sd_problems

TOL = 1e-7


def _optimum(p: AssignmentProblem) -> float | None:
    ref = solve(p, "bruteforce")
    return ref.objective if ref.status is Status.OPTIMAL else None


# ------------------------------------------------------------------- properties
@given(sd_problems())
def test_bound_below_optimum_below_objective(p):
    sol = solve(p, "lagrangian")
    opt = _optimum(p)
    if opt is None:                      # infeasible: never a solution
        assert not sol.has_solution
        return
    assert sol.status in (Status.OPTIMAL, Status.FEASIBLE), sol.message
    assert_feasible(p, sol)
    assert sol.bound is not None
    assert sol.bound <= opt + TOL * max(1.0, abs(opt))
    assert opt <= sol.objective + TOL * max(1.0, abs(opt))
    if sol.status is Status.OPTIMAL:
        assert sol.objective == pytest.approx(opt, rel=1e-9, abs=1e-9)
        assert sol.info["proof"]


@given(sd_problems(), st.integers(0, 2 ** 32 - 1), st.sampled_from([0.1, 1.0, 10.0]))
def test_bound_valid_for_any_multipliers(p, seed, scale):
    opt = _optimum(p)
    if opt is None:
        return
    rng = np.random.default_rng(seed)
    keep = tuple(sorted(rng.choice(p.ndim, size=2, replace=False).tolist()))
    u = {s: rng.normal(size=p.sizes[s]) * scale for s in range(p.ndim) if s not in keep}
    L = lg.lagrangian_bound(p, u, keep_axes=keep)
    assert L <= opt + TOL * max(1.0, abs(opt), scale * p.n_rows)


@given(sd_problems())
def test_exact_mode_equals_brute_force(p):
    sol = solve(p, "lagrangian-exact")
    opt = _optimum(p)
    if opt is None:
        assert sol.status is Status.INFEASIBLE, sol.message
        return
    assert_optimal(p, sol)


@settings(max_examples=15)
@given(sd_problems(dummies=True),
       st.sampled_from([{"window_solver": "highs"}, {"window_solver": "cpsat"},
                        {"reduce": False}, {"lap": "sparse"}, {"keep_axes": (0, 2)},
                        {"local_search": False, "recover_every": 3}]))
def test_exact_mode_with_options_equals_brute_force(p, opts):
    if opts.get("window_solver") == "cpsat" and not np.all(p.costs == np.round(p.costs)):
        opts = {}
    sol = solve(p, "lagrangian-exact", **opts)
    opt = _optimum(p)
    if opt is None:
        assert sol.status is Status.INFEASIBLE
        return
    assert_optimal(p, sol)


@settings(max_examples=25)
@given(sd_problems(), st.sampled_from(["no numba", "tiny compiled budget"]),
       st.sampled_from(["auto", "highs", "cpsat"]))
def test_exact_mode_window_engines_equal_brute_force(p, how, window_solver):
    """Windows settled by the Python search (numba absent) or passed on to CP-SAT /
    HiGHS (compiled search out of nodes) give the same optimum."""
    from assocopt.solvers.lagrangian import backend as lb_backend
    if window_solver == "cpsat" and not np.all(p.costs == np.round(p.costs)):
        window_solver = "auto"
    with pytest.MonkeyPatch.context() as mp:
        if how == "no numba":
            mp.setattr(lb_backend, "_has_numba", lambda: False)
        else:
            mp.setattr(lb_backend, "_COMPILED_NODES", 1)
        sol = solve(p, "lagrangian-exact", window_solver=window_solver)
    opt = _optimum(p)
    if opt is None:
        assert sol.status is Status.INFEASIBLE
        return
    assert_optimal(p, sol)


@given(sd_problems(dummies=True))
def test_dominance_keeps_the_optimum(p):
    drop = lg.dominated(p.sizes, p.tuples, p.costs)
    assert not drop[(p.tuples > 0).sum(axis=1) == 1].any()   # singletons always stay
    opt = _optimum(p)
    if opt is None or drop.all():
        return
    q = AssignmentProblem.sparse(p.sizes, p.tuples[~drop], p.costs[~drop])
    assert _optimum(q) == pytest.approx(opt, rel=1e-9, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(sd_problems(dummies=True), st.integers(0, 2 ** 32 - 1))
def test_dominance_compiled_equals_numpy(p, seed):
    """The numba kernel and the numpy reference drop the same candidates, also on
    costs with ties (rounded: ``>=`` decides) and on denser draws."""
    pytest.importorskip("numba")
    rng = np.random.default_rng(seed)
    for c in (p.costs, np.round(p.costs), rng.integers(-3, 3, p.n_candidates) * 1.0):
        a = lg.dominated(p.sizes, p.tuples, c, compiled=False)
        b = lg.dominated(p.sizes, p.tuples, c, compiled=True)
        assert a.tolist() == b.tolist()


def test_dominance_compiled_keys_overflow():
    """Axis sizes whose tuple keys overflow int64: both versions fall back to the
    single-index split alone, and agree."""
    pytest.importorskip("numba")
    sizes = (700,) * 7                       # 701^7 > 2^62
    T = np.array([[1, 1, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0, 0],
                  [1, 1, 1, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0, 0], [2, 0, 0, 0, 0, 0, 700]])
    c = np.array([5.0, 2.0, 3.0, 4.0, 1.0, -1.0])
    a = lg.dominated(sizes, T, c, compiled=False)
    b = lg.dominated(sizes, T, c, compiled=True)
    assert a.tolist() == b.tolist() == [True, False, False, False, False, False]


@pytest.mark.parametrize("N", [61, 62])
def test_dominance_compiled_keys_at_the_int64_limit(N):
    """2^61 keys fit, 2^62 do not: the compiled steps before the rule draw the line
    where the numpy reference's ``_radix`` does (the reference itself loops over the
    2^(N-1) splits of the axes: too many to run here)."""
    pytest.importorskip("numba")
    assert lg.reduction._radix((1,) * N)[1] == (N == 61)
    sizes = (1,) * N
    T = np.zeros((N + 2, N), np.int64)
    T[np.arange(N), np.arange(N)] = 1                    # the single-index candidates
    T[N, :2] = 1                                         # a pair: dominated by a split
    T[N + 1, :3] = 1                                     # a triple: only by the pair
    c = np.concatenate([np.full(N, 2.0), [1.0, 3.5]])
    a = lg.dominated(sizes, T, c, compiled=True)
    # the pair (1 < 2 + 2) stays; the triple (3.5 < 6 by singles) falls to the split
    # pair + single (1 + 2) only where keys fit
    assert not a[N] and a[N + 1] == (N == 61)


def test_dominance_example():
    T = np.array([[1, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1], [0, 0, 1]])
    c = np.array([5.0, 2.0, 3.0, 6.0, 1.0])
    # (1,1,0) costs 5 >= 2 + 3; (1,1,1) costs 6 >= 2 + 3 + 1
    assert lg.dominated((1, 1, 1), T, c).tolist() == [True, False, False, True, False]


# ------------------------------------------------------------------- statuses
def _rand3(n: int, seed: int = 0) -> AssignmentProblem:
    return AssignmentProblem.dense(np.random.default_rng(seed).random((n, n, n)))


def test_relaxation_infeasible_is_reported_infeasible():
    # axes 0 and 1 (kept) cannot be matched: 2 rows of axis 0 need row 1 of axis 1
    T = [[1, 1, 1], [2, 1, 2]]
    p = AssignmentProblem.sparse((2, 1, 2), T, [1.0, 1.0])
    for name in ("lagrangian", "lagrangian-exact"):
        sol = solve(p, name, keep_axes=(0, 1))
        assert sol.status is Status.INFEASIBLE, sol.message
        assert sol.tuples is None
        assert "relaxed 2-D problem" in sol.message


def test_infeasible_with_feasible_relaxation_exact_mode():
    # every index is covered and the kept-axes relaxation is feasible, but no two
    # candidates are disjoint and together cover everything
    T = [[1, 1, 1], [2, 2, 1], [1, 2, 2], [2, 1, 2]]
    p = AssignmentProblem.sparse((2, 2, 2), T, [1.0, 2.0, 3.0, 4.0])
    assert solve(p, "bruteforce").status is Status.INFEASIBLE
    sol = solve(p, "lagrangian-exact")
    assert sol.status is Status.INFEASIBLE, sol.message
    plain = solve(p, "lagrangian", max_iter=20)
    assert plain.status is Status.TIME_LIMIT and not plain.has_solution


def test_two_axes_are_solved_exactly():
    p = random_problem(np.random.default_rng(3), "miss", sizes=(4, 3))
    sol = solve(p, "lagrangian")
    assert_optimal(p, sol)
    assert sol.info["iterations"] == 1


def test_time_limit_gives_incumbent_and_bound():
    p = _rand3(12, seed=5)
    sol = solve(p, "lagrangian-exact", time_limit=1e-9)
    assert sol.status is Status.TIME_LIMIT, sol.message
    assert sol.has_solution and sol.bound is not None
    assert sol.bound <= sol.objective
    assert sol.info["stop"] == "time_limit"


def test_history_is_recorded_and_bounds_are_valid():
    p = _rand3(6, seed=2)
    opt = solve(p, "highs").objective
    sol = solve(p, "lagrangian", return_history=True, max_iter=50, gap_tol=0.0)
    h = sol.info["history"]
    assert len(h["bound"]) == len(h["best_bound"]) == len(h["objective"]) == \
        sol.info["iterations"]
    assert max(h["bound"]) <= opt + TOL
    assert np.all(np.diff(h["best_bound"]) >= 0)
    assert sol.info["parameters"]["max_iter"] == 50
    assert "history" not in solve(p, "lagrangian").info


def test_plain_mode_stops_on_iterations_with_feasible_status():
    p = _rand3(10, seed=1)
    sol = solve(p, "lagrangian", max_iter=3, gap_tol=0.0)
    assert sol.info["iterations"] <= 3
    if sol.status is not Status.OPTIMAL:
        assert sol.status is Status.FEASIBLE and sol.gap is not None


def test_integer_costs_report_the_rounded_bound():
    # integer costs: the optimum is an integer, so ceil(bound) is a valid bound
    rng = np.random.default_rng(11)
    p = AssignmentProblem.dense(rng.integers(1, 30, size=(8, 8, 8)).astype(float))
    sol = solve(p, "lagrangian-exact")
    assert_optimal(p, sol)
    assert sol.bound == sol.objective and sol.info["integer_costs"]
    plain = solve(p, "lagrangian", max_iter=5)
    assert plain.bound == math.floor(plain.bound)


def test_heuristic_gate_is_never_optimal_and_has_no_bound():
    rng = np.random.default_rng(4)
    p = random_problem(rng, "sd", sizes=(3, 3, 3), keep=1.0)
    sol = solve(p, "lagrangian-exact", gate=0.0)
    assert sol.status in (Status.FEASIBLE, Status.ERROR)
    assert sol.bound is None
    if sol.status is Status.FEASIBLE:
        assert_feasible(p, sol)
        assert "gated_bound" in sol.info


def test_memory_follows_candidates_not_sizes():
    # n^N = 3000^4 ~ 8e13 tuples: only the 1,500 candidates may be materialised
    rng = np.random.default_rng(0)
    n, N, K = 3000, 4, 1500
    T = rng.integers(0, n + 1, size=(K, N))
    T = T[(T > 0).sum(axis=1) >= 2]
    singles = np.zeros((N * n, N), np.int64)
    singles[np.arange(N * n), np.repeat(np.arange(N), n)] = np.tile(np.arange(1, n + 1), N)
    T = np.unique(np.concatenate([T, singles]), axis=0)
    c = np.where((T > 0).sum(axis=1) == 1, 0.0, rng.normal(-1.0, 1.0, size=len(T)))
    p = AssignmentProblem.sparse((n,) * N, T, c)
    sol = solve(p, "lagrangian-exact")
    ref = solve(p, "highs")
    assert sol.status is Status.OPTIMAL, sol.message
    assert sol.objective == pytest.approx(ref.objective, rel=1e-9, abs=1e-9)


# ------------------------------------------------------------------- options
def test_unknown_option_is_named():
    p = _rand3(3)
    with pytest.raises(InvalidProblemError, match="bogus"):
        solve(p, "lagrangian", bogus=1)
    with pytest.raises(InvalidProblemError, match="window_solver"):
        solve(p, "lagrangian", window_solver="highs")   # exact mode only


@pytest.mark.parametrize("opts, match", [
    ({"max_iter": -1}, "max_iter"), ({"max_iter": 2.5}, "max_iter"),
    ({"gap_tol": -0.1}, "gap_tol"), ({"step0": 3.0}, "step0"), ({"step0": 0.0}, "step0"),
    ({"step_decay": 1.5}, "step_decay"), ({"patience": 0}, "patience"),
    ({"deflect": 1.0}, "deflect"), ({"lap": "hungarian"}, "lap"),
    ({"keep_axes": (0, 0)}, "keep_axes"), ({"keep_axes": (0, 5)}, "keep_axes"),
    ({"gate": "x"}, "gate"), ({"reduce": 1}, "reduce"),
    ({"return_history": "yes"}, "return_history"),
])
def test_bad_option_values(opts, match):
    with pytest.raises(InvalidProblemError, match=match):
        solve(_rand3(3), "lagrangian-exact", **opts)


def test_parameters_are_recorded():
    sol = solve(_rand3(4), "lagrangian-exact", step0=0.5)
    par = sol.info["parameters"]
    assert par["step0"] == 0.5 and par["keep_axes"] == [0, 1]
    assert {"max_iter", "gap_tol", "patience", "window_solver"} <= set(par)


def test_auto_picks_lagrangian_exact_for_large_three_or_more_axes(monkeypatch):
    import assocopt.solving.choice as api
    monkeypatch.setattr(api, "BNB_MAX_CANDIDATES", 10)
    monkeypatch.setattr(api, "BNB_MAX_GRID", 10)                # dense square grids
    assert choose_solver(_rand3(3)) == "lagrangian-exact"       # 27 candidates
    assert choose_solver(AssignmentProblem.dense(np.ones((3, 3)))) == "scipy-lsa"
    assert choose_solver(_rand3(3), relax="lp") == "highs"
    p = _rand3(5, seed=9)
    sol = solve(p)
    assert sol.solver == "lagrangian-exact"
    assert_optimal(p, sol)


# ------------------------------------------------------------------- 2-D helpers
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 7), st.integers(1, 7),
       st.sampled_from([0.0, 0.5]))
def test_assign_with_misses_dense_and_sparse_agree(seed, n1, n2, forbid):
    rng = np.random.default_rng(seed)
    C = rng.normal(size=(n1, n2))
    C[rng.random(C.shape) < forbid] = np.inf
    rm = np.where(rng.random(n1) < 0.2, np.inf, rng.random(n1) * 2)
    cm = np.where(rng.random(n2) < 0.2, np.inf, rng.random(n2) * 2)
    r, c = np.nonzero(np.isfinite(C))
    w = C[r, c]

    def value(a):
        m = a.col_of_row >= 0
        return (C[np.flatnonzero(m), a.col_of_row[m]].sum() + rm[~m].sum()
                + cm[a.row_of_col < 0].sum())
    results = []
    for method in ("scipy", "sparse"):
        try:
            results.append(value(assign_with_misses(n1, n2, r, c, w, rm, cm, method=method)))
        except LapInfeasibleError:
            results.append(None)
    if results[0] is None:
        assert results[1] is None
    else:
        assert results[1] == pytest.approx(results[0], rel=1e-9, abs=1e-9)


@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 9))
def test_assignment_duals_are_feasible_and_tight(seed, n):
    rng = np.random.default_rng(seed)
    C = rng.integers(0, 10, size=(n, n)).astype(float)
    r, c = linear_assignment(C, "scipy")
    match = np.empty(n, np.int64)
    match[r] = c
    rows, cols = np.nonzero(np.ones((n, n)))
    alpha, beta = assignment_duals(n, rows, cols, C[rows, cols], match)
    assert (C - alpha[:, None] - beta[None, :] >= -1e-9).all()
    assert alpha.sum() + beta.sum() == pytest.approx(C[r, c].sum(), abs=1e-9)


def test_linear_assignment_infeasible_raises():
    with pytest.raises(LapInfeasibleError):
        linear_assignment(np.array([[1.0, np.inf], [2.0, np.inf]]), "scipy")


@pytest.mark.skipif(not lapx_available(), reason="lapx not installed")
def test_lapx_equals_scipy():
    rng = np.random.default_rng(0)
    for n, m in ((40, 40), (40, 60), (60, 40)):
        C = rng.random((n, m))
        r1, c1 = linear_assignment(C, "scipy")
        r2, c2 = linear_assignment(C, "lapx")
        assert C[r2, c2].sum() == pytest.approx(C[r1, c1].sum(), rel=1e-12)


@pytest.mark.skipif(lapx_available(), reason="lapx installed")
def test_lap_option_lapx_without_the_package_names_it():
    with pytest.raises(SolverNotInstalledError, match="lapx"):
        solve(_rand3(3), "lagrangian", lap="lapx")


def test_lapjv_backend_names_the_missing_package(monkeypatch):
    from assocopt.solvers.twod.lapjv import LapjvBackend
    monkeypatch.setattr(LapjvBackend, "module", "lap_not_installed_here")
    with pytest.raises(SolverNotInstalledError, match="lapx"):
        solve(AssignmentProblem.dense(np.ones((2, 2))), "lapjv")


@pytest.mark.skipif(not lapx_available(), reason="lapx not installed")
@pytest.mark.parametrize("method", ["auto", "sparse"])
def test_lapjv_backend_matches_scipy_lsa(method):
    rng = np.random.default_rng(1)
    for kind in ("square", "rect", "miss"):
        for _ in range(10):
            p = random_problem(rng, kind, forbid=0.3)
            assert_optimal(p, solve(p, "lapjv", method=method))


# ------------------------------------------------------------------- shared instances
def _instances(max_n: int | None, min_n: int = 0):
    if not AP_INSTANCES.is_dir():
        return []
    out = []
    for path in sorted((AP_INSTANCES / "grundel_ap3").glob("ap3.*.txt")) + \
            sorted((AP_INSTANCES / "balas_saltzman" / "split").glob("balas-n*.txt")):
        n = int(path.name.split(".")[1]) if path.name.startswith("ap3") else \
            int(path.name.split("-")[1][1:])
        if n >= min_n and (max_n is None or n <= max_n):
            out.append(pytest.param(path, id=path.stem))
    return out


def _check_instance(path):
    sys.path.insert(0, str(AP_INSTANCES))
    from load import known_value, load
    C, _ = load(str(path))
    p = AssignmentProblem.dense(C.astype(float))
    sol = solve(p, "lagrangian-exact")
    assert sol.status is Status.OPTIMAL, sol.message
    assert_feasible(p, sol)
    assert sol.objective == known_value(str(path))
    assert sol.bound == sol.objective


@pytest.mark.parametrize("path", _instances(10) or [pytest.param(None, id="absent")])
def test_known_optima_small(path, ap_instances):
    _check_instance(path)


@pytest.mark.slow
@pytest.mark.parametrize("path", _instances(None, min_n=11) or
                         [pytest.param(None, id="absent")])
def test_known_optima_all(path, ap_instances):
    _check_instance(path)


def test_plain_mode_gap_on_tracking_like_instances():
    """Regression on the issue's promise for S-D with dummies (not a timing test)."""
    rng = np.random.default_rng(7)
    for N in (3, 4):
        p = _tracking(rng, N, n_targets=8)
        sol = solve(p, "lagrangian", max_iter=100)
        assert sol.has_solution
        assert sol.gap is not None and sol.gap <= 0.01, (N, sol.gap, sol.message)
        opt = solve(p, "highs").objective
        tol = 1e-7 * max(1.0, abs(opt))
        assert sol.bound <= opt + tol and opt <= sol.objective + tol


def _tracking(rng, N, n_targets, pd=0.9, clutter=1.0, sigma=0.02, gate=0.12):
    """Sensors measuring 2-D target positions with misses and false alarms; tuples
    gated on mutual distance; negative log-likelihood-ratio costs."""
    meas = random_scans(rng, N, n_targets, pd=pd, clutter=clutter, sigma=sigma)
    sizes = tuple(len(z) for z in meas)
    parts = np.zeros((1, 0), np.int64)
    for s in range(N):
        ext = [np.concatenate([parts, np.zeros((len(parts), 1), np.int64)], axis=1)]
        for i in range(sizes[s]):
            ok = np.ones(len(parts), bool)
            for t in range(s):
                idx = parts[:, t]
                real = idx > 0
                d = np.full(len(parts), 0.0)
                d[real] = np.linalg.norm(meas[t][idx[real] - 1] - meas[s][i], axis=1)
                ok &= d <= gate
            col = np.full((ok.sum(), 1), i + 1)
            ext.append(np.concatenate([parts[ok], col], axis=1))
        parts = np.concatenate(ext)
    T = parts[(parts > 0).any(axis=1)]
    nreal = (T > 0).sum(axis=1)
    cost = np.zeros(len(T))
    for k in np.flatnonzero(nreal >= 2):
        z = np.array([meas[s][T[k, s] - 1] for s in range(N) if T[k, s]])
        resid = ((z - z.mean(axis=0)) ** 2).sum() / sigma ** 2
        cost[k] = 0.5 * resid - nreal[k] * math.log(pd / (2 * math.pi * sigma ** 2 * clutter)) \
            - (N - nreal[k]) * math.log(1 - pd)
    return AssignmentProblem.sparse(sizes, T, cost)


@pytest.mark.parametrize("window_solver", ["cpsat", "highs"])
def test_window_results_use_one_vocabulary_whichever_engine_ran(monkeypatch, window_solver):
    """The window search reports what each window settled in the engines' common
    terms (not HiGHS's status names when CP-SAT ran); HiGHS's own status, when HiGHS
    ran, is kept apart as ``native``."""
    if window_solver == "cpsat" and not registered()["ortools-cpsat"].is_available():
        pytest.skip("ortools not installed")
    from assocopt.solvers.lagrangian import backend as lag_backend
    from assocopt.solvers.lagrangian.window import Outcome

    monkeypatch.setattr(lag_backend, "_has_numba", lambda: False)   # no compiled search
    monkeypatch.setattr(lag_backend, "_SEARCH_MAX", 0)              # no Python search
    p = AssignmentProblem.dense(np.random.default_rng(0).integers(0, 20, (8, 8, 8))
                                .astype(float))
    sol = solve(p, "lagrangian-exact", window_solver=window_solver, max_iter=5)
    assert_optimal(p, sol)
    ran = [w for w in sol.info["windows"] if "solver" in w]
    assert ran, "no window reached an engine"
    outcomes = {o.value for o in Outcome}
    for w in ran:
        assert w["solver"] == window_solver and w["result"] in outcomes, w
        assert ("native" in w) == (window_solver == "highs"), w
        if window_solver == "highs":
            assert w["native"].startswith("k")
