"""Connected components (assocopt.solving.decompose) and the batched bnb kernel.

Problems are drawn as several independent blocks side by side (disjoint index
ranges), with isolated indices (a real index whose only candidate is its singleton)
and blocks made of singletons only; decomposed and whole solves must agree on status
and objective, and every answer is feasible (``assert_optimal`` checks it against
brute force).  The batch kernel is checked component by component against the
``bruteforce`` back end.  No timing asserts.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from assocopt import AssignmentProblem, Status, solve
from assocopt.problems.indexing import OPT_TOL
from assocopt.solving.decompose import local_tuples, split
from assocopt.testing import assert_optimal


@st.composite
def blocks(draw, N: int | None = None, feasible: bool = True):
    """``(sizes, tuples, costs)`` of one block: a random subset of its tuples, every
    index covered; ``feasible``: every singleton is a candidate."""
    N = N or draw(st.integers(3, 4))
    sizes = tuple(draw(st.integers(0, 2)) for _ in range(N))
    if sum(sizes) == 0:
        sizes = (1,) + sizes[1:]
    grids = np.meshgrid(*[np.arange(n + 1) for n in sizes], indexing="ij")
    T = np.stack([g.ravel() for g in grids], axis=1)[1:]          # no all-dummy
    single = (T > 0).sum(axis=1) == 1
    keep = np.array(draw(st.lists(st.booleans(), min_size=len(T), max_size=len(T))))
    keep |= single if feasible else np.zeros(len(T), bool)
    T = T[keep]
    for s, n in enumerate(sizes):                  # cover every index at least once
        for i in range(1, n + 1):
            if not (T[:, s] == i).any():
                t = np.zeros((1, N), np.int64)
                t[0, s] = i
                T = np.concatenate([T, t])
    costs = np.array(draw(st.lists(st.integers(-6, 6), min_size=len(T),
                                   max_size=len(T))), float) / 2
    return sizes, T, costs


@st.composite
def side_by_side(draw, feasible: bool | None = None):
    """Several blocks in disjoint index ranges, plus isolated indices and
    singleton-only blocks, in a shuffled order of candidates."""
    N = draw(st.integers(3, 4))
    parts = draw(st.lists(blocks(N, feasible if feasible is not None else
                                 draw(st.booleans())), min_size=1, max_size=4))
    n_iso = draw(st.integers(0, 3))
    for _ in range(n_iso):                          # isolated index: singleton alone
        s = draw(st.integers(0, N - 1))
        sizes = tuple(1 if t == s else 0 for t in range(N))
        T = np.zeros((1, N), np.int64)
        T[0, s] = 1
        parts.append((sizes, T, np.array([float(draw(st.integers(-3, 3)))])))
    sizes = np.zeros(N, np.int64)
    Ts, cs = [], []
    for sz, T, c in parts:
        Ts.append(np.where(T > 0, T + sizes, 0))
        cs.append(c)
        sizes += np.asarray(sz)
    T, c = np.concatenate(Ts), np.concatenate(cs)
    perm = np.array(draw(st.permutations(range(len(T)))), np.int64)
    return AssignmentProblem.sparse(tuple(int(v) for v in sizes), T[perm], c[perm])


def _agree(a, b, p):
    assert a.status is b.status, (a, b)
    if a.status is Status.OPTIMAL:
        assert abs(a.objective - b.objective) <= 1e-9 * max(1.0, abs(b.objective))
        # each component is proven to OPT_TOL * max(1, |its objective|); the whole's gap
        # is their sum, at most OPT_TOL * (components + sum of |chosen costs|)
        parts = max(1, (a.info.get("decomposition") or {}).get("components", 1))
        scale = parts + float(np.abs(p.costs[a.selected]).sum())
        assert abs(a.bound - a.objective) <= OPT_TOL * max(scale, abs(a.objective))


def _reference(p):
    """The whole problem by brute force (HiGHS past brute force's node cap)."""
    whole = solve(p, "bruteforce", decompose=False)
    if whole.status is Status.NODE_LIMIT:
        whole = solve(p, "highs", decompose=False)
    return whole


@settings(max_examples=60)
@given(side_by_side())
def test_decomposed_equals_whole(p):
    whole = _reference(p)
    for solver in ("highs", "auto", "bruteforce", "lagrangian-exact"):
        sol = solve(p, solver, decompose=True)
        _agree(sol, whole, p)
        if sol.status is Status.OPTIMAL:
            assert_optimal(p, sol)
            assert sol.info["decomposition"]["components"] >= 1


@settings(max_examples=30)
@given(side_by_side(feasible=True))
def test_components_counted(p):
    sp = split(p)
    # brute force over the component graph: candidates sharing a row are connected
    R = p.entry_rows
    lab = np.arange(p.n_rows)
    changed = True
    while changed:
        changed = False
        for r in R:
            rr = r[r >= 0]
            m = lab[rr].min()
            for x in rr:
                if lab[x] != m:
                    lab[lab == lab[x]] = m
                    changed = True
    assert sp.n == len(np.unique(lab))
    same = sp.of_row[:, None] == sp.of_row[None, :]
    assert (same == (lab[:, None] == lab[None, :])).all()
    T, sizes = local_tuples(p, sp.of_row, sp.n)
    assert (sizes.sum(axis=0) == np.asarray(p.sizes)).all()
    for c in range(sp.n):                      # local indices: 1..n_cs on each axis
        cand = sp.order[sp.ptr[c]:sp.ptr[c + 1]]
        for s in range(p.ndim):
            used = np.unique(T[cand, s][T[cand, s] > 0])
            assert (used == np.arange(1, sizes[c, s] + 1)).all()


@settings(max_examples=30, deadline=None)
@given(side_by_side())
def test_split_kernel_equals_numpy_route(p):
    """The union-find kernel (compiled, and as its plain twin) gives the numpy route's
    split, labels and candidate order included; so does the relabelling kernel."""
    pytest.importorskip("numba")
    from assocopt.problems.components import split_rows
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.kernels.components import split_rows as compiled
    R = np.ascontiguousarray(p.entry_rows, np.int64)
    want = split_rows(R, p.n_rows)
    for fn in (compiled, tiers.plain("components.split_rows")):
        got = fn(p.tuples, p.row_offsets, p.n_rows)
        assert got[0] == want[0]
        for a, b in zip(got[1:], want[1:]):
            assert np.array_equal(a, b)
    from assocopt.solvers.kernels.components import local_rows
    T, sizes = local_tuples(p, want[1], want[0])
    axis = np.repeat(np.arange(p.ndim), p.sizes).astype(np.int64)
    for fn in (local_rows, tiers.plain("components.local_rows")):
        T2, sizes2 = fn(p.tuples, p.row_offsets, want[1], want[0], axis)
        assert np.array_equal(T, T2) and np.array_equal(sizes, sizes2)


@settings(max_examples=30, deadline=None)
@given(side_by_side())
def test_scan_split_and_gather_kernels_equal_numpy_routes(p):
    """``split(..., scan=True)`` and :func:`gather`: the kernels (compiled, and as
    plain twins) give the numpy routes' arrays; the local indices and axis sizes are
    those of :func:`local_tuples`, the dummy flags those of the tuples."""
    pytest.importorskip("numba")
    from assocopt.problems.components import component_tuples, gather
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.kernels.components import gather_parts, scan_parts
    want = split(p, scan=True)
    axis = np.repeat(np.arange(p.ndim), p.sizes).astype(np.int64)
    fields = ("n", "of_row", "of_cand", "order", "ptr", "trivial", "local", "csizes",
              "gated")
    for fn in (scan_parts, tiers.plain("components.scan_parts")):
        got = fn(p.tuples, p.row_offsets, p.n_rows, axis)
        for name, a in zip(fields, got):
            assert np.array_equal(a, getattr(want, name)), name
    T, sizes = local_tuples(p, want.of_row, want.n)
    assert np.array_equal(want.csizes, sizes)
    assert np.array_equal(component_tuples(p, want, np.arange(p.n_candidates)), T)
    has_dummy = (p.tuples == 0).any(axis=1)
    assert np.array_equal(want.gated, [has_dummy[want.of_cand == c].any()
                                       for c in range(want.n)])
    comps = np.arange(want.n, dtype=np.int64)[::-2].copy()      # any order, a subset
    Tb, cb, kp, cand_b = gather(p, want, comps)
    cand = np.concatenate([want.order[want.ptr[c]:want.ptr[c + 1]] for c in comps]
                          + [np.zeros(0, np.int64)])
    assert np.array_equal(Tb, T[cand]) and np.array_equal(cb, p.costs[cand])
    assert np.array_equal(np.diff(kp), want.sizes[comps])
    assert np.array_equal(cand_b, cand)
    args = (p.tuples, p.costs, p.row_offsets, want.local, want.order, want.ptr, comps)
    for fn in (gather_parts, tiers.plain("components.gather_parts")):
        for a, b in zip(fn(*args), (Tb, cb, kp, cand)):
            assert np.array_equal(a, b)


@settings(max_examples=40, deadline=None)
@given(side_by_side(), st.booleans(), st.integers(1, 40), st.integers(1, 40),
       st.integers(2, 12), st.integers(4, 60))
def test_plan_kernel_equals_numpy_route(p, bnb_rule, cap_gated, cap_plain, max_kept,
                                        max_dense):
    """:func:`plan`: the kernel ``plan_parts`` (compiled, and as its plain twin) picks
    the components the numpy route picks, by both rules, and gathers the same arrays."""
    pytest.importorskip("numba")
    from assocopt.problems.components import plan
    from assocopt.solvers.kernels import tiers
    from assocopt.solvers.kernels.components import plan_parts
    sp = split(p, scan=True)
    rule = (bnb_rule, cap_gated, cap_plain, max_kept, max_dense)
    want = plan(p, sp, *rule)
    assert sorted(np.concatenate(want[:2]).tolist()) == np.flatnonzero(~sp.trivial).tolist()
    args = (p.tuples, p.costs, p.row_offsets, sp.local, sp.order, sp.ptr, sp.csizes,
            sp.gated, sp.trivial) + rule
    for fn in (plan_parts, tiers.plain("components.plan_parts")):
        for a, b in zip(fn(*args), want):
            assert np.array_equal(a, b)


def test_split_routes_by_the_tier_rule(monkeypatch):
    """``split(p, routed)``: the numpy route (charged to the kernel's budget) while
    interpreted, the kernel once compiled; the same split either way."""
    pytest.importorskip("numba")
    from assocopt.solvers.kernels import routed, tiers
    T = np.array([[1, 1, 0], [2, 0, 1], [0, 2, 1], [3, 0, 0]])
    p = AssignmentProblem.sparse((3, 2, 1), T, np.arange(4.0))
    monkeypatch.setattr(tiers, "_SPENT", {})
    tiers.set_mode("interpreted")
    try:
        a = split(p, routed)
        assert tiers.interpreted_seconds().get("components.split_rows", 0) > 0
        tiers.set_mode("compiled")
        b = split(p, routed)
    finally:
        tiers.set_mode(None)
    assert a.n == b.n == 3
    assert np.array_equal(a.order, b.order) and np.array_equal(a.of_row, b.of_row)


def test_singletons_only_settled_without_solver():
    T = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [2, 0, 0]])
    p = AssignmentProblem.sparse((2, 1, 1), T, [1.0, -2.0, 0.5, 3.0])
    sol = solve(p, "highs", decompose=True)
    assert sol.status is Status.OPTIMAL and sol.objective == 2.5
    d = sol.info["decomposition"]
    assert d["components"] == 4 and d["settled"] == 4 and d["largest"] == 1


def test_decompose_false_and_time_limit():
    rng = np.random.default_rng(1)
    T = np.array([[i, j, k] for i in range(3) for j in range(3) for k in range(3)
                  if (i, j, k) != (0, 0, 0)])
    p1 = AssignmentProblem.sparse((2, 2, 2), T, rng.normal(size=len(T)))
    # two copies side by side: two components
    T2 = np.concatenate([T, np.where(T > 0, T + 2, 0)])
    p = AssignmentProblem.sparse((4, 4, 4), T2, np.tile(p1.costs, 2))
    whole = solve(p, "highs", decompose=False)
    assert "decomposition" not in whole.info
    for solver in ("highs", "auto", "scipy"):
        sol = solve(p, solver, decompose=True, time_limit=30.0)
        _agree(sol, whole, p)
        assert sol.info["decomposition"]["components"] == 2
    assert abs(whole.objective - 2 * solve(p1, "highs").objective) < 1e-9


def test_infeasible_component_makes_whole_infeasible():
    # block 1: index 1 of axis 0 must pair with index 1 of axis 1, which has no
    # singleton and whose only other candidate clashes: infeasible
    T = np.array([[1, 1, 0], [0, 1, 1], [0, 0, 1], [2, 0, 0]])
    p = AssignmentProblem.sparse((2, 1, 1), T, [1.0, 1.0, 1.0, 0.0])
    for solver in ("highs", "auto", "bruteforce"):
        a = solve(p, solver, decompose=True)
        b = solve(p, solver, decompose=False)
        assert a.status is b.status


def _batch_of(parts: list) -> tuple[np.ndarray, ...]:
    """``(T, c, kp, sizes)`` of the batch kernel: the parts one after the other."""
    kp = np.cumsum([0] + [len(T) for _, T, _ in parts])
    return (np.concatenate([T for _, T, _ in parts]),
            np.concatenate([c for _, _, c in parts]), kp,
            np.array([sizes for sizes, _, _ in parts]))


@settings(max_examples=40)
@given(st.lists(blocks(3), min_size=1, max_size=5))
def test_batch_kernel_equals_brute_force(parts):
    pytest.importorskip("numba")
    from assocopt.solvers.bnb.batch import run_batch
    from assocopt.solvers.kernels.driver import INFEASIBLE, PROVEN
    batch = _batch_of(parts)
    kp = batch[2]
    (outcome, ub, lb, chosen), _ = run_batch(*batch)
    for i, (sizes, T, c) in enumerate(parts):
        ref = solve(AssignmentProblem.sparse(sizes, T, c), "bruteforce")
        if ref.status is Status.INFEASIBLE:
            assert outcome[i] == INFEASIBLE or not np.isfinite(ub[i])
            continue
        assert outcome[i] == PROVEN
        assert abs(ub[i] - ref.objective) <= 1e-9 * max(1.0, abs(ref.objective))
        sel = np.flatnonzero(chosen[kp[i]:kp[i + 1]])
        assert abs(c[sel].sum() - ref.objective) <= 1e-9 * max(1.0, abs(ref.objective))
        p = AssignmentProblem.sparse(sizes, T, c)
        assert p.violations(sel) is None
        assert lb[i] <= ub[i] + 1e-9


@settings(max_examples=25)
@given(st.lists(blocks(3), min_size=2, max_size=6), st.sampled_from(
    [(0, 10 ** 9), (10 ** 9, 0), (10 ** 9, 10 ** 9), (6, 0), (0, 0)]),
    st.booleans())
def test_batch_split_between_threads_gives_the_same_answers(parts, limits, deadline):
    """The batch runs its small components in the calling thread until its work cap,
    the rest in a worker thread (and all there under a deadline): wherever that split
    falls, every component gets the answer it gets alone, written in its own place."""
    pytest.importorskip("numba")
    import time

    from assocopt.solvers.bnb import batch as bb
    args = _batch_of(parts)
    kp = args[2]
    alone = [bb.run_batch(T, c, np.array([0, len(T)]), np.array([sizes]))[0]
             for sizes, T, c in parts]
    cand, work = limits
    saved = bb.INLINE_CANDIDATES, bb.INLINE_WORK
    bb.INLINE_CANDIDATES, bb.INLINE_WORK = cand, work
    try:
        (outcome, ub, lb, chosen), by_clock = bb.run_batch(
            *args, deadline=time.perf_counter() + 600 if deadline else None)
    finally:
        bb.INLINE_CANDIDATES, bb.INLINE_WORK = saved
    assert not by_clock
    for i, (o, u, b, ch) in enumerate(alone):
        assert (outcome[i], ub[i], lb[i]) == (o[0], u[0], b[0])
        assert chosen[kp[i]:kp[i + 1]].tolist() == ch.tolist()


def test_time_limit_is_shared_and_a_stopped_component_stops_the_whole():
    T = np.array([[i, j, k] for i in range(3) for j in range(3) for k in range(3)
                  if (i, j, k) != (0, 0, 0)])
    T2 = np.concatenate([T, np.where(T > 0, T + 2, 0)])
    c = np.random.default_rng(3).normal(size=len(T2))
    p = AssignmentProblem.sparse((4, 4, 4), T2, c)
    sol = solve(p, "highs", decompose=True, time_limit=1e-9)
    assert sol.status is Status.TIME_LIMIT and sol.selected is None
    assert sol.info["decomposition"]["components"] == 2


def test_maximize_decomposed():
    T = np.array([[1, 1, 0], [1, 0, 0], [0, 1, 0], [2, 0, 2], [2, 0, 0], [0, 0, 2],
                  [0, 0, 1], [0, 2, 0]])
    p = AssignmentProblem.sparse((2, 2, 2), T, [3.0, 1.0, 1.0, -1.0, 0.5, 0.25, 0.0, 0.0],
                                 maximize=True)
    for solver in ("highs", "auto"):
        a = solve(p, solver, decompose=True)
        b = solve(p, "bruteforce", decompose=False)
        assert a.objective == b.objective == 3.75 and a.bound == 3.75


@settings(max_examples=30)
@given(side_by_side())
def test_batch_budget_spent_components_are_solved_again(p):
    """bnb's batch with a node budget of 1: the components it cannot prove go to
    bnb alone (and its fallback), and the whole is still exact."""
    pytest.importorskip("numba")
    whole = _reference(p)
    sol = solve(p, "bnb", decompose=True, max_nodes=1, max_iter=1, probe_every=0,
                recover_every=0)
    _agree(sol, whole, p)
    if sol.status is Status.OPTIMAL:
        assert_optimal(p, sol)


@settings(max_examples=20)
@given(side_by_side(feasible=True))
def test_auto_sends_large_gated_components_to_lagrangian_exact(p):
    """With ``BNB_MAX_GATED`` lowered, components with dummies above it go to
    ``lagrangian-exact`` (the others stay in the batch), and the whole is exact."""
    pytest.importorskip("numba")
    import assocopt.solving.choice as choice
    sp = split(p)
    todo = np.flatnonzero(~sp.trivial)
    if not len(todo):
        return
    cap = int(np.median(sp.sizes[todo]))
    mp = pytest.MonkeyPatch()
    with mp.context() as m:
        m.setattr(choice, "BNB_MAX_GATED", cap)
        sol = solve(p, "auto", decompose=True)
    whole = _reference(p)
    _agree(sol, whole, p)
    if sol.status is not Status.OPTIMAL:
        return
    assert_optimal(p, sol)
    if sp.n == 1:
        return
    used = sol.info["decomposition"]["solvers"]
    big = int((sp.sizes[todo] > cap).sum())        # every block here has dummies
    assert used.get("lagrangian-exact", 0) == big
    assert used.get("bnb", 0) == len(todo) - big


def test_auto_batch_runs_bnb_at_its_own_defaults(monkeypatch):
    """A problem whose whole ``auto`` choice is lagrangian-exact (kept axes too large
    for bnb) but whose components suit bnb: the batch gets bnb's defaults, not the
    lagrangian-exact options ``auto`` parsed for the whole (max_iter 500, step0 1, ...)."""
    pytest.importorskip("numba")
    import assocopt.solvers.bnb.batch as bb
    from assocopt.solving.choice import choose_solver
    rng = np.random.default_rng(4)
    grid = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), -1).reshape(-1, 3)[1:]
    T = np.concatenate([np.where(grid > 0, grid + 2 * i, 0) for i in range(60)])
    p = AssignmentProblem.sparse((120, 120, 120), T, rng.normal(size=len(T)))
    assert choose_solver(p) == "lagrangian-exact"
    seen = []
    real = bb.run_batch

    def spy(T, c, kp, sizes, params=None, deadline=None):
        seen.append(dict(params or {}))
        return real(T, c, kp, sizes, params, deadline)

    monkeypatch.setattr(bb, "run_batch", spy)
    sol = solve(p)
    assert sol.info["decomposition"]["batched"] == 60
    assert seen and all(set(s) <= set(bb.DEFAULTS) and all(
        s[k] == bb.DEFAULTS[k] for k in s) for s in seen)
    assert_optimal(p, sol)


@pytest.mark.parametrize("solver, options, want", [
    ("auto", {}, "batch"), ("bnb", {}, "bnb"), ("bnb", {"probe_every": 7}, 7)])
def test_the_batch_searches_every_batch_probe_every_iterations_under_auto(
        monkeypatch, solver, options, want):
    """``auto``'s batch runs short searches every ``BATCH_PROBE_EVERY`` iterations;
    ``solver="bnb"`` keeps bnb's own ``probe_every`` (its default, or the one given)."""
    pytest.importorskip("numba")
    import assocopt.solvers.bnb.batch as bb
    want = {"batch": bb.BATCH_PROBE_EVERY,
            "bnb": bb.DEFAULTS["probe_every"]}.get(want, want)
    assert bb.BATCH_PROBE_EVERY != bb.DEFAULTS["probe_every"]
    seen = []
    real = bb.run_tiered

    def spy(name, args, stop, **kw):
        seen.append(args[6])                     # probe_every, as the kernel takes it
        return real(name, args, stop, **kw)
    monkeypatch.setattr(bb, "run_tiered", spy)
    grid = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), -1).reshape(-1, 3)[1:]
    T = np.concatenate([np.where(grid > 0, grid + 2 * i, 0) for i in range(20)])
    costs = np.random.default_rng(2).normal(size=len(T))
    p = AssignmentProblem.sparse((40, 40, 40), T, costs)
    sol = solve(p, solver, decompose=True, **options)
    assert sol.info["decomposition"]["batched"] == 20
    assert seen and set(seen) == {want}
    assert_optimal(p, sol)
