"""The compiled paths of ``lagrangian-exact`` against the plain ones: the dense-grid
relaxation (axial 3-AP: :mod:`assocopt.solvers.kernels.grid`) against numpy and
scipy's LAP, and the window policy that lets the compiled search give up on a window
for a larger one to decide (:class:`assocopt.solvers.lagrangian.policy._Skipper`)
against brute force.  No wall-clock assertions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assocopt import AssignmentProblem, Status, solve
from assocopt.testing import assert_optimal

from conftest import sd_problems

pytest.importorskip("numba")


def _relaxations(C: np.ndarray):
    from assocopt.solvers.lagrangian import relaxation as R
    p = AssignmentProblem.dense(C)
    from assocopt.solvers.kernels import tiers
    args = (p.sizes, p.tuples, p.costs, (0, 1), "auto")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiers, "_MODE", ["compiled"])      # small grids: else numpy's route
        fast = R._Relaxation(*args)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(R, "_numba_installed", lambda *work: False)
        slow = R._Relaxation(*args)
    return fast, slow


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n", [1, 2, 5, 12])
def test_grid_kernels_equal_numpy(seed, n):
    """Same L(u) and subgradient norm (ties may pick other pairs of equal value), a
    selection of that value, and a recovery as cheap as scipy's LAP on the same
    chosen pairs, at successive multipliers (warm potentials carried over)."""
    rng = np.random.default_rng(seed)
    C = rng.integers(0, 30, (n, n, n)).astype(float) if seed % 2 else rng.random((n, n, n))
    fast, slow = _relaxations(C)
    assert fast.compiled and not slow.compiled
    u = fast.initial_multipliers()
    for _ in range(8):
        a, b = fast.evaluate(u), slow.evaluate(u)
        assert a.value == pytest.approx(b.value, abs=1e-9)
        rc = fast.reduced_costs(u)
        assert rc[a.selected].sum() + u.sum() == pytest.approx(a.value, abs=1e-9)
        ra, rb = fast.recover(u, a.chosen), slow.recover(u, a.chosen)
        assert ra is not None and rb is not None
        assert np.array_equal(ra, np.sort(ra))
        assert fast.c[ra].sum() == pytest.approx(slow.c[rb].sum(), abs=1e-9)
        u = u + rng.normal(0.0, 1.0, len(u)) * (fast.evaluate(u).subgradient != 0)


def _leave_windows(mp: pytest.MonkeyPatch, nodes: int, growth: float) -> None:
    """Give-up budget ``nodes``, successor growth ``growth``, no search in the ascent's
    fixing probes (else they settle small problems before any window)."""
    from assocopt.solvers.lagrangian import backend as lb, policy as lw
    mp.setattr(lb, "_SKIP_NODES", nodes)
    mp.setattr(lw, "_SKIP_GROWTH", growth)
    mp.setattr(lb, "_PROBE_SEARCH_MAX", 0)
    mp.setattr(lb, "_PROBE_SEARCH_SMALL", 0)


def test_windows_left_to_larger_ones_equal_highs():
    """Dense integer 3-AP, n = 4..7, short ascent: every window eligible and given up
    at once, so the first comes back after the second; same optimum as HiGHS, and
    the path was taken."""
    seen = set()
    for seed in range(24):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(4, 8))
        p = AssignmentProblem.dense(rng.integers(0, 20, (n, n, n)).astype(float))
        with pytest.MonkeyPatch.context() as mp:
            _leave_windows(mp, 1, 0.0)
            sol = solve(p, "lagrangian-exact", max_iter=5)
        assert_optimal(p, sol, reference=solve(p, "highs").objective)
        results = [w.get("result") for w in sol.info.get("windows", [])]
        seen.add(tuple(results[:3]))
    assert ("gave_up", "gave_up", "none_below_cap") in seen
    assert ("gave_up", "gave_up", "optimal") in seen


@given(sd_problems(dummies=False), st.sampled_from([(1, 0.0), (1, 2.0), (50, 0.0)]))
@settings(max_examples=40, deadline=None)
def test_windows_left_to_larger_ones_equal_brute_force(p, policy):
    """With the give-up budget cut to ``nodes`` and every first window eligible
    (growth 0), or only those whose successor is twice as large, the windows left to
    larger ones, the first one solved after all, give brute force's optimum."""
    nodes, growth = policy
    with pytest.MonkeyPatch.context() as mp:
        _leave_windows(mp, nodes, growth)
        sol = solve(p, "lagrangian-exact", max_iter=3)
    ref = solve(p, "bruteforce")
    if ref.status is Status.INFEASIBLE:
        assert sol.status is Status.INFEASIBLE
        return
    assert_optimal(p, sol)
    assert sol.objective == pytest.approx(ref.objective, abs=1e-7 * max(1, abs(ref.objective)))


def test_skipper_goes_back_to_the_first_window():
    """Two windows given up: the first threshold comes back, then nothing is left."""
    from assocopt.solvers.lagrangian.policy import _Skipper
    s = _Skipper()
    lb = np.arange(100, dtype=float)
    assert not s.may_skip(False, True, lb, 10, 10.0)        # next window: 11, not 20
    lb = np.sort(np.concatenate([lb, np.full(50, 10.0)]))
    assert not s.may_skip(False, False, lb, 10, 10.0)       # real costs: never
    assert not s.may_skip(True, True, lb, 10, 10.0)         # the last window: never
    assert s.may_skip(False, True, lb, 10, 10.0)            # next holds 61 >= 2 * 10
    s.gave_up(10.0)
    assert s.threshold(10.0, True, 50.0) == 11.0           # one above the one left
    assert s.may_skip(True, True, lb, 11, 11.0)            # the second may give up too
    s.gave_up(11.0)
    assert s.threshold(12.0, True, 50.0) == 10.0           # back to the first
    assert not s.may_skip(False, True, lb, 10, 10.0)
    assert s.threshold(11.0, True, 50.0) == 11.0


@pytest.mark.parametrize("seed", range(4))
def test_windows_solved_by_components_equal_highs(seed):
    """Gated scans closer than the gate (one component), a short ascent so that the
    windows are large, the first search cut to one node: the windows split and are
    solved component by component (the path was taken), with HiGHS's optimum."""
    from benchmarks.tracking_scans import ScanSpec, build_problem
    from assocopt.solvers.lagrangian import policy as lw
    p, _ = build_problem(ScanSpec(N=4, n=30, spacing=0.8, seed=seed))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(lw, "_SPLIT_MIN", 2)
        mp.setattr("assocopt.solvers.lagrangian.backend._SPLIT_MIN", 2)
        mp.setattr("assocopt.solvers.lagrangian.backend._OPEN_NODES", 1)   # search first
        sol = solve(p, "lagrangian-exact", max_iter=4, decompose=False, local_search=False)
    assert_optimal(p, sol, reference=solve(p, "highs").objective)
    engines = {w.get("solver") for w in sol.info.get("windows", [])}
    assert "components" in engines, sol.info.get("windows")


def test_connected_or_nested_windows_are_left_to_the_engines():
    from assocopt.solvers.lagrangian import policy as lw
    from assocopt.solvers.lagrangian.ascent import _State
    p = AssignmentProblem.dense(np.arange(27.0).reshape(3, 3, 3))   # one component
    st = _State(costs=p.costs, integer=True)
    from assocopt.solvers.base import SolveOptions
    assert lw._by_components(p, np.arange(27), st, SolveOptions(), None) is None
    token = lw._NESTED.set(True)
    try:
        q = AssignmentProblem.sparse((2, 2, 2), [[1, 1, 1], [2, 2, 2]], [1.0, 2.0])
        assert lw._by_components(q, np.arange(2), _State(costs=q.costs, integer=True),
                                 SolveOptions(), None) is None
    finally:
        lw._NESTED.reset(token)


def test_small_grids_take_numpy_by_default(monkeypatch):
    """By the default rule a dense grid of at most the kernel's limit in entries takes
    the numpy route (kernels.tiers: compiling would not pay), a larger one the kernel."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.lagrangian import relaxation as R
    monkeypatch.delenv("ASSOCOPT_JIT", raising=False)
    monkeypatch.setattr(tiers, "_MODE", [None])
    monkeypatch.setattr(tiers, "_SPENT", {})
    monkeypatch.setattr(tiers, "loaded", lambda name: None)   # as in a fresh process
    for n, compiled in ((5, False), (12, True)):
        p = AssignmentProblem.dense(np.random.default_rng(n).random((n, n, n)))
        rel = R._Relaxation(p.sizes, p.tuples, p.costs, (0, 1), "auto")
        assert rel.compiled is compiled, n


@settings(max_examples=60, deadline=None)
@given(sd_problems(), st.sampled_from([0.0, 2.0, 1e9]), st.booleans())
def test_window_search_stops_at_a_proven_floor(p, above, compiled):
    """The window search with a lower bound proven elsewhere (``floor``): at the true
    optimum it returns an optimal cover; at any floor the cover it returns is a real
    one, at most the floor when it stopped early (so a wrong floor shows)."""
    from assocopt.solvers.lagrangian.window import _compiled_search, _cover_search
    ref = solve(p, "bruteforce")
    if ref.status is not Status.OPTIMAL:
        return
    pos = np.arange(p.n_candidates)
    red = np.zeros(p.n_candidates)                   # base 0: only the costs bound
    base = min(0.0, float(p.costs.min())) * p.n_rows
    floor = ref.objective + above
    if compiled:
        sel, complete = _compiled_search(p, pos, red, base, np.inf, p.integer_costs,
                                         100_000, floor)
    else:
        sel, complete = _cover_search(p, pos, red, base, np.inf, 100_000, floor=floor)
    assert complete and sel is not None
    assert p.violations(sel) is None
    z = p.objective_of(sel)
    assert z >= ref.objective - 1e-9
    if above == 0.0:
        assert z == pytest.approx(ref.objective, abs=1e-9)
    elif above == 1e9 and p.n_candidates > 1:
        assert z <= floor                              # the first cover found ends it


@settings(max_examples=60, deadline=None)
@given(sd_problems(dummies=True), st.integers(0, 2 ** 32 - 1), st.sampled_from([0, 1, 2]))
def test_window_search_with_forced_candidates_is_exact(p, seed, where):
    """The compiled window search takes the candidates forced below its limit before
    it branches: with any valid fixing bounds (``red >= 0``, ``base`` the optimum of
    ``c - red``) it still finds the optimum when that is below the cap, and nothing
    below the cap when it is not."""
    ref = solve(p, "bruteforce")
    if ref.status is not Status.OPTIMAL:
        return
    from assocopt.solvers.lagrangian.window import _compiled_search
    rng = np.random.default_rng(seed)
    red = rng.random(p.n_candidates) * rng.choice([0.0, 1.0, 3.0])
    q = AssignmentProblem.sparse(p.sizes, p.tuples, p.costs - red)
    base = solve(q, "bruteforce").objective
    cap = [np.inf, ref.objective + 0.05, ref.objective][where]
    sel, complete = _compiled_search(p, np.arange(p.n_candidates), red, base, cap,
                                     False, 100_000)
    assert complete
    if ref.objective < cap - 1e-9 * max(1.0, abs(ref.objective)):
        assert sel is not None and p.violations(sel) is None
        assert p.objective_of(sel) == pytest.approx(ref.objective, abs=1e-9)
    else:
        assert sel is None or p.objective_of(sel) >= cap - 1e-9


def test_force_window_takes_chains_and_finds_dead_rows():
    """Unit propagation: a row with one candidate forces it, which drops its rivals
    and forces the next; a row left with none means no cover below the limit."""
    from assocopt.solvers.kernels.forcing import force_window
    sizes = np.array([2, 2], np.int64)
    off = np.array([0, 2], np.int64)
    # rows a1 a2 b1 b2; (1,1) is a1's only candidate -> drops (0,1): b1 done; then
    # a2 has (2,2) and (2,0), b2 has (2,2) and (0,2): nothing more is forced
    T = np.array([[1, 1], [0, 1], [2, 2], [2, 0], [0, 2]], np.int64)
    c = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    status, forced, rest, T2, sizes2, c0, _ = force_window(T, c, off, sizes, np.zeros(5),
                                                          1.0)
    assert status == 0 and forced.tolist() == [0] and c0 == 1.0
    assert rest.tolist() == [2, 3, 4] and sizes2.tolist() == [1, 1]
    assert T2.tolist() == [[1, 1], [1, 0], [0, 1]]
    # (2,0) and (0,2) above the limit: a2 and b2 keep only (2,2), forced too
    rp = np.array([0.0, 0.0, 0.0, 5.0, 5.0])
    status, forced, rest, _, _, c0, _ = force_window(T, c, off, sizes, rp, 1.0)
    assert status == 0 and sorted(forced.tolist()) == [0, 2] and len(rest) == 0
    assert c0 == 4.0
    # (2,2) above it as well: b2's (0,2) is gone and so is every candidate of a2's
    rp = np.array([0.0, 0.0, 5.0, 5.0, 0.0])
    assert force_window(T, c, off, sizes, rp, 1.0)[0] == 1
