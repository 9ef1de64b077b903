"""The compiled gated relaxation (:mod:`assocopt.solvers.kernels.sparse_relax`, wired by
:mod:`assocopt.solvers.lagrangian.compiled_sparse`) against the numpy code it
replaces: the same ``L(u)``, subgradient, chosen groups, relaxed selection and
recovered solution at successive multipliers (integer costs: many ties, which both
must break alike), the plain-Python twins against the compiled kernels, and whole
``lagrangian-exact`` solves with the tracking options against brute force / HiGHS.
No wall-clock assertions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assocopt import AssignmentProblem, solve
from assocopt.testing import assert_optimal, random_problem

pytest.importorskip("numba")

EVAL, RECOVER = "sparse_relax.sparse_eval", "sparse_relax.sparse_recover"


def _problem(seed: int, N: int) -> AssignmentProblem:
    """A random gated S-D problem with dummies, ``N`` axes (mostly integer costs)."""
    rng = np.random.default_rng(seed)
    hi = {3: 7, 4: 5, 5: 4, 6: 3}[N]
    sizes = tuple(int(v) for v in rng.integers(2, hi + 1, size=N))
    keep = {3: 0.5, 4: 0.25, 5: 0.08, 6: 0.04}[N]
    return random_problem(rng, "sd", sizes=sizes, integer=seed % 3 != 0, keep=keep)


def _pair(p: AssignmentProblem):
    """The relaxation with the compiled route and the same one on numpy's."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.lagrangian.relaxation import _Relaxation
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiers, "_MODE", ["compiled"])       # small: else numpy's route
        fast = _Relaxation(p.sizes, p.tuples, p.costs, p.kept_axes(None), "sparse")
        slow = _Relaxation(p.sizes, p.tuples, p.costs, p.kept_axes(None), "sparse")
    slow.kern = None
    return fast, slow


def _same_eval(a, b) -> None:
    assert a.value == b.value
    for x, y in ((a.selected, b.selected), (a.chosen, b.chosen),
                 (a.subgradient, b.subgradient), (a.rc, b.rc), (a.gmin, b.gmin),
                 (a.assignment.col_of_row, b.assignment.col_of_row),
                 (a.assignment.row_of_col, b.assignment.row_of_col)):
        assert np.array_equal(x, y)
    assert a.free_value == b.free_value


def _walk(fast, slow, seed: int, steps: int = 10) -> int:
    """Evaluate and recover at ``steps`` successive multipliers on both routes;
    returns how many recoveries found a solution."""
    rng = np.random.default_rng(seed)
    u = fast.initial_multipliers()
    found = 0
    for _ in range(steps):
        a, b = fast.evaluate(u), slow.evaluate(u)
        _same_eval(a, b)
        for x, y in zip(fast.fixing_bounds(u), slow.fixing_bounds(u)):   # fixing_duals
            assert np.array_equal(x, y)
        ra, rb = fast.recover(u, a.chosen), slow.recover(u, b.chosen)
        assert (ra is None) == (rb is None)
        if ra is not None:
            found += 1
            assert np.array_equal(ra, rb)
        u = u + np.round(rng.normal(0.0, 1.0, len(u)), 1 if seed % 2 else 6)
        u[fast.u_off] = 0.0
    return found


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("N", [3, 4, 5, 6])
def test_compiled_route_equals_numpy(seed, N):
    p = _problem(seed, N)
    fast, slow = _pair(p)
    slow.uniform = False          # uniform groups too: against the general numpy code
    assert fast.kern is not None
    _walk(fast, slow, seed)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("N", [3, 4, 5])
def test_uniform_groups_take_the_compiled_route(seed, N):
    """Every kept-axes pair holding the same tails (all tuples of a small grid, dummies
    included): the compiled route runs there too, equal to the numpy code."""
    rng = np.random.default_rng(seed)
    sizes = tuple(int(v) for v in rng.integers(1, 3, size=N))
    grids = np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1)[1:]
    c = np.round(rng.normal(0.0, 3.0, len(T)), 0 if seed % 2 else 3)
    p = AssignmentProblem.sparse(sizes, T, c)
    fast, slow = _pair(p)
    assert fast.uniform and fast.kern is not None
    slow.uniform = False
    _walk(fast, slow, seed)
    sol = solve(p, "lagrangian-exact", lap="sparse", local_search=False)
    assert_optimal(p, sol)


@pytest.mark.parametrize("N", [3, 4, 5, 6])
def test_recoveries_compared(N):
    """Over a few problems some recoveries succeed (the comparison is not vacuous)."""
    assert sum(_walk(*_pair(_problem(50 + s, N)), s) for s in range(6)) > 0


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), N=st.integers(3, 6))
def test_compiled_route_equals_numpy_drawn(seed, N):
    fast, slow = _pair(_problem(seed, N))
    slow.uniform = False
    if fast.kern is not None:
        _walk(fast, slow, seed, steps=4)


def test_tracking_scan_equal():
    """A gated tracking scan (N = 4, the tracker's miss and false-alarm tuples)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from tracking_scans import ScanSpec, build_problem
    p, _ = build_problem(ScanSpec(4, 25, spacing=1.0, clutter=0.2, pd=0.9, seed=3))
    fast, slow = _pair(p)
    assert fast.kern is not None
    assert _walk(fast, slow, 1, steps=15) > 0


@pytest.mark.parametrize("seed", range(4))
def test_twin_equals_compiled(seed):
    """The plain-Python twins (the interpreted route) give the compiled answers."""
    from assocopt.solvers.kernels import tiers
    fast, _ = _pair(_problem(seed, 4))
    k = fast.kern
    u = fast.initial_multipliers() + np.random.default_rng(seed).normal(0, 1, fast.u_len)
    u[fast.u_off] = 0.0
    args = (k.c, k.U, k.u_off, u, k.nf) + k.groups + k.lap
    out_c, out_p = tiers.compiled(EVAL)(*args), tiers.plain(EVAL)(*args)
    assert out_c[0] == out_p[0] == 0
    for x, y in zip(out_c[1:], out_p[1:]):
        assert np.array_equal(x, y)
    rargs = (k.c, k.U, k.u_off, k.sizes, u, k.nf) + k.groups + (out_c[3],)
    rc_, rp = tiers.compiled(RECOVER)(*rargs), tiers.plain(RECOVER)(*rargs)
    assert rc_[0] == rp[0] and np.array_equal(rc_[1], rp[1])
    fargs = (out_c[1], out_c[2], out_c[7], out_c[8]) + k.lap[1:] + k.fix  # rc, gmin, cor, roc
    fix = "fixing_duals.sparse_fixing"
    for x, y in zip(tiers.compiled(fix)(*fargs), tiers.plain(fix)(*fargs)):
        assert np.array_equal(x, y)


def test_lap_without_misses_left_to_numpy():
    """A LAP with no finite miss cost: infeasible when rectangular, else status 2
    (numpy hands it to scipy)."""
    from assocopt.solvers.kernels import tiers
    twin = tiers._twin("sparse_relax")
    inf2, inf3 = np.full(2, np.inf), np.full(3, np.inf)
    e = np.array([0, 1], np.int64)
    assert twin._with_misses(2, 3, e, e, np.ones(2), inf2, inf3)[0] == 1
    assert twin._with_misses(2, 2, e, e, np.ones(2), inf2, inf2)[0] == 2
    from assocopt.solvers.twod.lap import assign_with_misses
    rm, cm = np.array([0.5, 9.0]), np.array([0.2, 9.0])
    st_, cor, roc = twin._with_misses(2, 2, e, e, np.ones(2), rm, cm)
    ref = assign_with_misses(2, 2, e, e, np.ones(2), rm, cm, method="sparse")
    assert st_ == 0 and cor.tolist() == ref.col_of_row.tolist() == [-1, 1]
    assert roc.tolist() == ref.row_of_col.tolist()


def test_routes():
    """The kernels run only where they repeat the numpy code exactly: ``lap="sparse"``,
    not a grid, numba's route chosen (interpreted mode and small problems: numpy)."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.lagrangian.relaxation import _Relaxation
    p = _problem(1, 4)
    args = (p.sizes, p.tuples, p.costs, p.kept_axes(None))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiers, "_MODE", ["compiled"])
        assert _Relaxation(*args, "auto").kern is None
        assert _Relaxation(*args, "sparse").kern is not None
        g = AssignmentProblem.dense(np.random.default_rng(0).random((4, 4, 4)))
        assert _Relaxation(g.sizes, g.tuples, g.costs, (0, 1), "sparse").kern is None
        mp.setattr(tiers, "_MODE", ["interpreted"])
        assert _Relaxation(*args, "sparse").kern is None


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("N", [3, 4, 5])
def test_solves_stay_optimal(seed, N):
    """``lagrangian-exact`` with the tracking options, compiled route, is optimal."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solving.decompose import TRACKING_OPTIONS
    p = _problem(100 + seed, N)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiers, "_MODE", ["compiled"])
        sol = solve(p, "lagrangian-exact", **TRACKING_OPTIONS)
    assert_optimal(p, sol)


def test_bnb_cap_follows_the_route(monkeypatch):
    """``auto`` gives ``bnb`` fewer gated candidates where the relaxation runs
    compiled (there ``lagrangian-exact`` overtakes it sooner)."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solving import choice
    monkeypatch.setattr(tiers, "_MODE", ["compiled"])
    assert choice.bnb_cap(np.array([True, False])).tolist() == \
        [choice.BNB_MAX_GATED_COMPILED, choice.BNB_MAX_CANDIDATES]
    assert choice.bnb_cap(np.array([True, False]), 5).tolist() == \
        [choice.BNB_MAX_GATED_WIDE, choice.BNB_MAX_CANDIDATES]
    monkeypatch.setattr(tiers, "_MODE", ["interpreted"])
    assert choice.bnb_cap(np.array([True, False])).tolist() == \
        [choice.BNB_MAX_GATED, choice.BNB_MAX_CANDIDATES]


_LAYOUT = ("pos", "T", "c", "nf", "g_start", "g_count", "gkey", "pair_g", "pr", "pc",
           "rm_g", "rm_i", "cm_g", "cm_j", "g_row", "g_col", "G", "has_miss", "uniform")


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), N=st.integers(3, 6))
def test_compiled_layout_equals_numpy(seed, N):
    """The candidate layout and starting multipliers of the compiled route
    (:mod:`assocopt.solvers.kernels.groups`) equal the numpy code's, dtypes included,
    and the plain twins give the compiled answers."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.lagrangian.relaxation import _Relaxation
    p = _problem(seed, N)
    args = (p.sizes, p.tuples, p.costs, p.kept_axes(None), "sparse")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tiers, "_MODE", ["compiled"])
        a = _Relaxation(*args)
        ua = a.initial_multipliers()
        mp.setattr(tiers, "_MODE", ["interpreted"])
        b = _Relaxation(*args)
        ub = b.initial_multipliers()
    for name in _LAYOUT:
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.dtype == y.dtype and np.array_equal(x, y), name
    assert all(np.array_equal(x, y) for x, y in zip(a.uidx, b.uidx))
    assert np.array_equal(ua, ub)
    a0, b0 = p.kept_axes(None)
    largs = (np.ascontiguousarray(p.tuples), p.costs, a0, b0, p.sizes[a0], p.sizes[b0],
             np.asarray(a.relaxed, np.int64), a.u_off)
    for x, y in zip(tiers.compiled("groups.layout")(*largs),
                    tiers.plain("groups.layout")(*largs)):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("seed", range(4))
def test_kernel_sums_are_numpys_to_the_last_bit(seed):
    """The kernels' sum (:func:`assocopt.solvers.kernels.sums.np_sum`) repeats numpy's
    pairwise order, so ``L(u)`` is the same float on both routes: every length up to
    300 (the blocks of 8 and 128 and their halving) and a few long arrays, values
    spread over six decades, compiled and as plain Python."""
    pytest.importorskip("numba")
    from assocopt.solvers.kernels import sums, tiers
    plain = tiers._twin("sums")
    rng = np.random.default_rng(seed)
    lengths = list(range(0, 301)) + [1000, 4099, 65_537]
    for n in lengths:
        a = rng.normal(size=n) * 10.0 ** rng.uniform(-3, 3, n)
        assert sums.np_sum(a) == float(np.sum(a))
        if n <= 1000:
            assert plain.np_sum(a) == float(np.sum(a))


def _both_routes(fn):
    """``fn()`` with the ascent's loop compiled, then in Python (the evaluation
    compiled in both)."""
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.lagrangian import sparse_ascent
    out, runs = [], []
    real = sparse_ascent.sparse_ascent

    def counted(*args):
        runs.append(1)
        return real(*args)
    for kernel in (True, False):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(tiers, "_MODE", ["compiled"])
            mp.setattr(sparse_ascent, "sparse_ascent", counted)
            if not kernel:
                mp.setattr(sparse_ascent, "applies", lambda *a: False)
            before = len(runs)
            out.append(fn())
            assert (len(runs) > before) == kernel    # the kernel ran, or it did not
    return out


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("N", [3, 4, 5])
def test_compiled_ascent_equals_the_python_loop(seed, N):
    """The ascent run by its kernel leaves what the Python loop leaves, to the bit:
    multipliers, bound, incumbent, iterations, stop and step size (a plain ascent and
    an exact one with the stall rule), and whole ``lagrangian-exact`` solves with
    their probes and windows give the same answer after as many iterations."""
    from assocopt.solvers.lagrangian.ascent import _ascent, _State
    from assocopt.solvers.lagrangian.relaxation import _Relaxation
    from assocopt.solving.decompose import TRACKING_OPTIONS
    p = _problem(200 + seed, N)
    params = {"max_iter": 40, "recover_every": 3, "gap_tol": 0.0, "stall_iter": 6,
              "stall_tol": 0.01, "patience": 3, "step_decay": 0.5, "step_min": 1e-4,
              "deflect": 0.3}

    def ascent(exact):
        def run():
            rel = _Relaxation(p.sizes, p.tuples, p.costs, p.kept_axes(None), "sparse")
            assert rel.kern is not None
            st = _State(costs=p.costs, integer=p.integer_costs, theta=1.5)
            u = _ascent(rel, np.arange(p.n_candidates)[rel.pos],
                        rel.initial_multipliers(), st, params, None, exact)
            return (u.tolist(), st.ub, st.bound, st.iterations, st.stop, st.theta,
                    None if st.incumbent is None else st.incumbent.tolist())
        return run
    for exact in (False, True):
        a, b = _both_routes(ascent(exact))
        assert a == b
    a, b = _both_routes(lambda: solve(p, "lagrangian-exact", **TRACKING_OPTIONS))
    assert a.status == b.status and a.objective == b.objective and a.bound == b.bound
    assert a.info["iterations"] == b.info["iterations"]
    assert np.array_equal(a.selected, b.selected)
