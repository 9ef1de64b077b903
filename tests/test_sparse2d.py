"""The sparse gated 2-D engine (compiled shortest augmenting paths) against brute force,
dense scipy and scipy's LAPJVsp, on every form it solves."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.optimize import linear_sum_assignment

from assocopt import AssignmentProblem, Status, solve
from assocopt.solvers.twod import sparse as sparse2d
from assocopt.solvers.twod.lap import LapInfeasibleError
from assocopt.solvers.twod.sparse import assign_sparse_edges
from conftest import draw_misses


@st.composite
def gated_cases(draw):
    """A small gated problem in blocks (several components), some rows or columns
    without candidates, rows whose candidates are all forbidden, misses of every
    kind (all finite, some forbidden, none)."""
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    blocks = draw(st.integers(1, 3))
    n1 = n2 = 0
    rows, cols = [], []
    for _ in range(blocks):
        a, b = draw(st.integers(0, 3)), draw(st.integers(0, 3))
        k = draw(st.integers(1, 3))
        for i in range(a):
            if b and rng.random() < 0.85:        # else an isolated row
                js = rng.choice(b, size=min(k, b), replace=False)
                rows += [n1 + i] * len(js)
                cols += (n2 + js).tolist()
        n1, n2 = n1 + a, n2 + b
    rows, cols = np.array(rows, np.int64), np.array(cols, np.int64)
    w = rng.integers(-4, 10, size=len(rows)).astype(float)
    if len(w):
        w[rng.random(len(w)) < draw(st.sampled_from([0.0, 0.25]))] = np.inf

    return (n1, n2, rows, cols, w, draw_misses(draw, rng, n1, np.full(n1, np.inf)),
            draw_misses(draw, rng, n2, np.full(n2, np.inf)))


def _problem(n1, n2, rows, cols, w, rm, cm) -> AssignmentProblem:
    fr, fc = np.flatnonzero(np.isfinite(rm)), np.flatnonzero(np.isfinite(cm))
    T = np.concatenate([np.stack([rows + 1, cols + 1], axis=1),
                        np.stack([fr + 1, 0 * fr], axis=1),
                        np.stack([0 * fc, fc + 1], axis=1)]).astype(np.int64)
    return AssignmentProblem.sparse((n1, n2), T.reshape(-1, 2),
                                    np.concatenate([w, rm[fr], cm[fc]]))


def _objective(edge, cols, w, rm, cm) -> float:
    on = edge >= 0
    used = np.zeros(len(cm), bool)
    used[cols[edge[on]]] = True
    return float(w[edge[on]].sum() + rm[~on].sum() + cm[~used].sum())


@settings(max_examples=300, deadline=None)
@given(gated_cases())
def test_engine_matches_brute_force(case):
    n1, n2, rows, cols, w, rm, cm = case
    finite = np.isfinite(w)           # the engine is given candidates: inf pairs dropped
    rows, cols, w = rows[finite], cols[finite], w[finite]
    p = _problem(n1, n2, rows, cols, w, rm, cm)
    ref = solve(p, "bruteforce")
    try:
        edge, how = assign_sparse_edges(n1, n2, rows, cols, w, rm, cm)
    except LapInfeasibleError:
        assert ref.status is Status.INFEASIBLE
        return
    assert ref.status is Status.OPTIMAL, how
    assert edge.shape == (n1,)
    on = edge >= 0
    assert np.array_equal(rows[edge[on]], np.flatnonzero(on))       # the row's own edge
    assert len(set(cols[edge[on]].tolist())) == int(on.sum())        # columns once
    assert np.isfinite(rm[~on]).all()                                # misses allowed
    assert _objective(edge, cols, w, rm, cm) == pytest.approx(ref.objective, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(gated_cases(), st.booleans())
def test_solve_on_the_sparse_path_matches_brute_force(case, scipy_fallback):
    """Through :func:`assocopt.solve` (split, positions, the re-check), with the sparse
    path forced for tiny problems; also with scipy's LAPJVsp in place of the kernel."""
    n1, n2, rows, cols, w, rm, cm = case
    p = _problem(n1, n2, rows, cols, w, rm, cm)
    ref = solve(p, "bruteforce")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sparse2d, "SPARSE_MIN_ENTRIES", -1)
        mp.setattr(sparse2d, "SPARSE_DENSITY", 0)
        if scipy_fallback:
            mp.setattr(sparse2d, "_KERNEL", [None])
        sol = solve(p)
    if ref.status is Status.INFEASIBLE:
        assert sol.status is Status.INFEASIBLE, sol.message
        return
    assert sol.status is Status.OPTIMAL, sol.message
    mode = sol.info.get("lsa_mode")
    if n1 * n2:                       # else no matrix to prefer the sparse path over
        assert mode.startswith("sparse"), mode
    assert p.violations(sol.selected) is None
    assert sol.objective == pytest.approx(ref.objective, abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 7), st.integers(1, 7), st.integers(0, 2**31 - 1),
       st.sampled_from([0.3, 0.6, 1.0]))
def test_kernel_matches_dense_scipy(nr, nc, seed, density):
    """The compiled LAP on its own: every row assigned, against linear_sum_assignment
    on the dense matrix (inf where no edge), infeasible exactly when scipy says so."""
    from assocopt.solvers.kernels.sparse_lap import lap_edges

    rng = np.random.default_rng(seed)
    M = rng.normal(size=(nr, nc)) * 10
    M[rng.random(M.shape) > density] = np.inf
    r, c = np.nonzero(np.isfinite(M))
    edge, bad = lap_edges(nr, nc, r, c, M[r, c])
    try:
        ri, ci = linear_sum_assignment(M)
        ok = len(ri) == nr and np.isfinite(M[ri, ci]).all()
    except ValueError:
        ok = False
    if not ok:
        assert bad >= 0
        return
    assert bad == -1
    assert np.array_equal(r[edge], np.arange(nr)) and len(set(c[edge].tolist())) == nr
    assert M[r[edge], c[edge]].sum() == pytest.approx(M[ri, ci].sum(), abs=1e-9)


def _mwfbm_objective(p: AssignmentProblem) -> float:
    import scipy.sparse as sp
    from scipy.sparse.csgraph import min_weight_full_bipartite_matching
    from assocopt.solvers.twod.lap import augmented_edges

    n1, n2 = p.sizes
    rows, cols, w, _, rm, cm, _, _ = sparse2d.split_candidates(p)
    ar, ac, aw = augmented_edges(n1, n2, rows, cols, w, rm, cm)
    shift = 1.0 - min(0.0, float(aw.min()))
    G = sp.csr_matrix((aw + shift, (ar, ac)), shape=(n1 + n2, n1 + n2))
    r, c = min_weight_full_bipartite_matching(G)
    return float(np.asarray(G[r, c]).sum() - shift * (n1 + n2))


@pytest.mark.parametrize("n, k, cols", [(3000, 5, None), (2000, 12, 2500), (2500, 3, 1800)])
def test_gated_scans_match_scipy_lapjvsp(n, k, cols):
    from assocopt.workflow.generate import gated_2d

    p = gated_2d(n, k, seed=1, n_cols=cols)
    sol = solve(p)
    assert sol.status is Status.OPTIMAL and sol.info["lsa_mode"].startswith("sparse")
    ref = _mwfbm_objective(p)
    assert sol.objective == pytest.approx(ref, rel=1e-9, abs=1e-9)


def _diagonal_scan(n: int):
    """A gated scan plus the pairs ``(i, i)``: feasible whatever misses are forbidden."""
    from assocopt.workflow.generate import gated_2d

    rows, cols, w, _, rm, cm, _, _ = sparse2d.split_candidates(gated_2d(n, 4, seed=2))
    off = rows != cols
    d = np.arange(n)
    return (np.concatenate([rows[off], d]), np.concatenate([cols[off], d]),
            np.concatenate([w[off], np.full(n, 5.0)]), rm, cm)


def test_each_form_matches_scipy_lapjvsp():
    n = 1500
    rows, cols, w, rm, cm = _diagonal_scan(n)
    some = np.arange(n) % 3 == 0
    never = np.full(n, np.inf)
    forms = [("sparse-reduced", rm, cm), ("sparse-reduced", np.where(some, np.inf, rm), cm),
             ("sparse-reduced", never, cm), ("sparse-reduced-T", rm, never),
             ("sparse-reduced-T", rm, np.where(some, np.inf, cm)),
             ("sparse-augmented", np.where(some, np.inf, rm), np.where(~some, np.inf, cm)),
             ("sparse", never, never)]
    for want, rm_, cm_ in forms:
        p = _problem(n, n, rows, cols, w, rm_, cm_)
        sol = solve(p)
        assert sol.status is Status.OPTIMAL and sol.info["lsa_mode"] == want, sol.message
        assert sol.objective == pytest.approx(_mwfbm_objective(p), rel=1e-9)


def test_infeasible_scan_is_reported():
    """Two rows that must be assigned, both gated only to column 0: every index has a
    candidate (no uncovered-index shortcut), yet no assignment exists."""
    n = 1500
    rows, cols, w, rm, cm = _diagonal_scan(n)
    keep = rows >= 2
    rows = np.concatenate([rows[keep], [0, 1]])
    cols = np.concatenate([cols[keep], [0, 0]])
    w = np.concatenate([w[keep], [1.0, 2.0]])
    rm = rm.copy()
    rm[:2] = np.inf
    sol = solve(_problem(n, n, rows, cols, w, rm, cm))
    assert sol.status is Status.INFEASIBLE and "must be assigned" in sol.message, \
        sol.message


@pytest.mark.parametrize("nr, nc, density, levels, seed", [
    (60, 60, 0.2, 3, 0), (80, 120, 0.1, 2, 1), (150, 150, 0.05, 1000, 2),
    (100, 140, 0.5, 1, 3), (120, 120, 1.0, 4, 4)])
def test_kernel_matches_dense_scipy_with_ties(nr, nc, density, levels, seed):
    """Larger problems with many equal costs (the tie branches of the row reduction),
    negative costs and a full-density case, against linear_sum_assignment."""
    from assocopt.solvers.kernels.sparse_lap import lap_edges

    rng = np.random.default_rng(seed)
    M = rng.integers(-levels // 2, levels, size=(nr, nc)).astype(float)
    M[rng.random(M.shape) > density] = np.inf
    M[np.arange(nr), rng.permutation(nc)[:nr]] = 5.0 * levels    # always feasible
    r, c = np.nonzero(np.isfinite(M))
    edge, bad = lap_edges(nr, nc, r, c, M[r, c])
    ri, ci = linear_sum_assignment(M)
    assert bad == -1
    assert np.array_equal(r[edge], np.arange(nr)) and len(set(c[edge].tolist())) == nr
    assert M[r[edge], c[edge]].sum() == M[ri, ci].sum()
