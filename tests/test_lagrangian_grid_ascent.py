"""The compiled ascent of ``lagrangian-exact`` on dense square 3-D grids
(:mod:`assocopt.solvers.lagrangian.compiled_ascent`, kernels in
:mod:`assocopt.solvers.kernels.grid_ascent`) against the Python loop with the
numpy route, against the kernels' plain-Python twins, and against brute force; the
grid kernels (sorted evaluation, fixing bounds, local search) against their numpy
counterparts.  No wall-clock assertions."""

from __future__ import annotations

import itertools
import sys

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from assocopt import AssignmentProblem, Status, solve
from assocopt.testing import assert_optimal

pytest.importorskip("numba")


@pytest.fixture
def compiled(monkeypatch):
    """Every kernel compiled (small grids would take the numpy route by default)."""
    from assocopt.solvers.kernels import tiers
    monkeypatch.setattr(tiers, "_MODE", ["compiled"])


def _grid(n: int, seed: int, integer: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.integers(0, 25, (n, n, n)).astype(float) if integer else rng.random((n, n, n))


def _brute(C: np.ndarray) -> float:
    """min over permutations p, q of sum_i C[i, p(i), q(i)]: scipy's LAP per p."""
    n = C.shape[0]
    best = np.inf
    for p in itertools.permutations(range(n)):
        M = C[np.arange(n), list(p), :]
        r, c = linear_sum_assignment(M)
        best = min(best, M[r, c].sum())
    return float(best)


def _relaxation(C: np.ndarray):
    from assocopt.solvers.lagrangian.relaxation import _Relaxation
    p = AssignmentProblem.dense(C)
    return _Relaxation(p.sizes, p.tuples, p.costs, (0, 1), "auto")


@pytest.mark.parametrize("seed", range(12))
def test_compiled_ascent_equals_brute_force(seed, compiled):
    n = 4 + seed % 3
    C = _grid(n, seed, integer=seed % 2 == 0)
    p = AssignmentProblem.dense(C)
    sol = solve(p, "lagrangian-exact")
    assert sol.info["parameters"]["step0"] == 0.5          # the grid's defaults ran
    assert sol.info["parameters"]["recover_every"] == 3
    assert sol.info["parameters"]["patience"] == 7 and sol.info["parameters"]["stall_tol"] == 0.1
    assert_optimal(p, sol)
    assert sol.objective == pytest.approx(_brute(C), abs=1e-9)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("mode", ["lagrangian", "lagrangian-exact"])
def test_compiled_ascent_equals_the_python_loop(seed, mode, compiled, monkeypatch):
    """Same options (given explicitly): the compiled ascent and the Python loop
    reach bounds within floating-point round-off of each other (the two follow the
    same iterations; ties in the 2-D assignments may go other ways), and the exact
    mode proves the same optimum."""
    from assocopt.solvers.lagrangian import backend
    n = (7, 12, 15)[seed % 3]
    p = AssignmentProblem.dense(_grid(n, 100 + seed, integer=seed % 2 == 1))
    opts = {"step0": 0.5, "recover_every": 2, "max_iter": 60}
    fast = solve(p, mode, return_history=True, **opts)
    monkeypatch.setattr(backend, "_COMPILED_ASCENT", False)
    slow = solve(p, mode, return_history=True, **opts)
    for s in (fast, slow):
        h = s.info["history"]
        assert len(h["bound"]) == len(h["best_bound"]) == len(h["objective"])
        assert np.all(np.diff(h["best_bound"]) >= 0)
        assert {"parameters", "iterations", "stop", "proof", "ascent_stop",
                "phase_times", "history"} <= set(s.info)
    assert fast.info["history"]["bound"][0] == pytest.approx(
        slow.info["history"]["bound"][0], abs=1e-9)
    if mode == "lagrangian-exact":
        assert_optimal(p, fast)
        assert fast.objective == pytest.approx(slow.objective, abs=1e-9)
    else:
        opt = solve(p, "highs").objective
        for s in (fast, slow):
            assert s.bound <= opt + 1e-7 and s.objective >= opt - 1e-7


@pytest.mark.parametrize("seed", range(4))
def test_plain_twin_of_the_ascent_kernel_agrees(seed, compiled, monkeypatch):
    """The kernels run as plain Python (the tier rule's twin route) give the
    compiled kernels' answers: the same history, to round-off, and the same optimum."""
    from assocopt.solvers import kernels
    from assocopt.solvers.kernels import tiers
    p = AssignmentProblem.dense(_grid(6 + seed, 200 + seed, integer=seed % 2 == 0))
    ref = solve(p, "lagrangian-exact", return_history=True, max_iter=40)
    real = kernels.pick

    def plain(kernel, *args, work):
        name = tiers.key(kernel)
        return tiers.plain(name) if name.startswith("grid_ascent.") else \
            real(kernel, *args, work=work)

    monkeypatch.setattr(kernels, "pick", plain)
    twin = solve(p, "lagrangian-exact", return_history=True, max_iter=40)
    assert_optimal(p, twin)
    assert twin.objective == pytest.approx(ref.objective, abs=1e-9)
    a, b = ref.info["history"]["best_bound"], twin.info["history"]["best_bound"]
    assert len(a) == len(b) and np.allclose(a, b, atol=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_sorted_evaluation_equals_grid_eval(seed):
    from assocopt.solvers.kernels.grid import grid_eval
    from assocopt.solvers.kernels.grid_ascent import grid_eval_sorted
    from assocopt.solvers.lagrangian.compiled_ascent import sorted_rows
    n = 3 + 4 * seed
    rel = _relaxation(_grid(n, seed, integer=seed % 2 == 0))
    rng = np.random.default_rng(seed)
    Cs, Is = sorted_rows(rel)
    for _ in range(5):
        w = rng.normal(0.0, 5.0, n)
        if seed % 3 == 0:
            w = np.round(w)                    # ties between relaxed indices
        a = grid_eval_sorted(Cs, Is, w, n, np.empty(0))
        b = grid_eval(rel.Cg, w, n, np.empty(0))
        assert a[0] and b[0]
        assert a[1] == pytest.approx(b[1], abs=1e-9)
        assert np.array_equal(a[3], b[3]) and np.array_equal(a[4], b[4])


@pytest.mark.parametrize("seed", range(6))
def test_grid_fixing_equals_the_numpy_bounds(seed, compiled):
    """Same duals (the shortest-path sweeps) and reduced costs: lb equal to round-off."""
    from assocopt.solvers.lagrangian.fixing import fixing_bounds
    n = (1, 2, 5, 9, 14, 20)[seed]
    rel = _relaxation(_grid(n, 300 + seed, integer=seed % 2 == 0))
    rng = np.random.default_rng(seed)
    u = rel.initial_multipliers()
    for _ in range(4):
        lb, red, base = fixing_bounds(rel, u)
        lb0, red0, base0 = rel.fixing_bounds(u)
        assert base == pytest.approx(base0, abs=1e-9)
        assert np.allclose(lb, lb0, atol=1e-9) and np.allclose(red, red0, atol=1e-9)
        u = u + rng.normal(0.0, 1.0, len(u))
        u[0] = 0.0


@pytest.mark.parametrize("seed", range(6))
def test_grid_local_search_reaches_an_axis_wise_optimum(seed):
    """Feasible, never worse, and no single axis re-assignment improves it."""
    from assocopt.solvers.kernels.grid_ascent import grid_local_search
    n = 3 + 3 * seed
    C = _grid(n, 400 + seed, integer=seed % 2 == 0)
    Cg = np.ascontiguousarray(C.reshape(n * n, n))
    rng = np.random.default_rng(seed)
    start = (np.arange(n) * n + rng.permutation(n)) * n + rng.permutation(n)
    out = grid_local_search(Cg, n, start, 20, 1e-9)
    tri = np.stack([out // (n * n), (out // n) % n, out % n], 1)
    for s in range(3):
        assert sorted(tri[:, s]) == list(range(n))
    cost = C[tri[:, 0], tri[:, 1], tri[:, 2]].sum()
    assert cost <= Cg.flat[start].sum() + 1e-9
    for s in range(3):
        M = np.empty((n, n))
        for x in range(n):
            t = tri.copy()
            t[:, s] = x
            M[:, x] = C[t[:, 0], t[:, 1], t[:, 2]]
        r, c = linear_sum_assignment(M)
        assert M[r, c].sum() >= cost - 1e-9


@pytest.mark.parametrize("name", ["ap3.5.1", "ap3.20.1", "ap3.20.2",
                                  "balas-n12-instance01", "balas-n16-instance01"])
def test_public_instances_proven_at_the_recorded_optimum(name, ap_instances, compiled):
    sys.path.insert(0, str(ap_instances))
    from load import known_value, load
    sub = "grundel_ap3" if name.startswith("ap3") else "balas_saltzman/split"
    path = str(ap_instances / sub / f"{name}.txt")
    C, _ = load(path)
    p = AssignmentProblem.dense(C.astype(float))
    sol = solve(p, "lagrangian-exact")
    assert sol.status is Status.OPTIMAL
    assert sol.objective == float(known_value(path))
    assert_optimal(p, sol)


def test_auto_sends_square_grids_above_the_grid_cap_to_lagrangian_exact():
    """Dense square 3-D grids above ``BNB_MAX_GRID`` candidates go to the compiled
    ascent; at or below it, and non-square problems up to ``BNB_MAX_CANDIDATES``,
    to ``bnb`` as before."""
    from assocopt.solving.choice import BNB_MAX_GRID, choose_solver
    rng = np.random.default_rng(0)
    n = int(np.floor(BNB_MAX_GRID ** (1 / 3)))
    assert choose_solver(AssignmentProblem.dense(rng.random((n, n, n)))) == "bnb"
    assert choose_solver(AssignmentProblem.dense(rng.random((n + 1,) * 3))) == \
        "lagrangian-exact"
    full = AssignmentProblem.dense(rng.random((n + 1,) * 3))          # one triple less
    holed = AssignmentProblem.sparse(full.sizes, full.tuples[1:], full.costs[1:])
    assert choose_solver(holed) == "bnb"


@pytest.mark.parametrize("integer", [True, False])
@pytest.mark.parametrize("ub", [7.0, 40.0, np.inf])
def test_fixing_order_gives_every_window_as_a_prefix(integer, ub):
    """Each window ``{k : bound_k < T}`` (bounds rounded up for integer costs) is the
    first ``searchsorted(bounds, T)`` entries of the order, for every threshold up
    to the incumbent."""
    from assocopt.solvers.lagrangian.fixing import fixing_order
    rng = np.random.default_rng(5)
    lb = rng.normal(10.0, 6.0, 500)
    lb[:20] = np.round(lb[:20])                      # bounds on whole units, too
    lo = float(np.ceil(lb.min() + 2.0)) if integer else lb.min() + 2.0
    bounds, order = fixing_order(lb, lo, ub, integer)
    assert sorted(order.tolist()) == list(range(len(lb)))
    assert (np.diff(bounds[bounds < ub]) >= 0).all()
    key = np.ceil(lb - 1e-6) if integer else lb
    for T in np.arange(lo + 1.0, min(ub, lo + 30.0) + 1e-9, 1.0 if integer else 0.37):
        n = int(np.searchsorted(bounds, T, "left"))
        assert set(order[:n].tolist()) == set(np.flatnonzero(key < T).tolist())
