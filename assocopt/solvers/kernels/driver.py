"""The ``bnb`` driver: subgradient ascent with N = 3 primal recovery (at N >= 4 a
greedy cover, :mod:`.greedy`, as the first incumbent) and periodic searches
(:func:`.search.dfs`), then the final search; one compiled call per problem."""

from __future__ import annotations

import numpy as np
from .jit import njit

from .greedy import greedy_cover
from .hungarian import hungarian
from .recovery import recover3_sparse
from .relaxation import (evaluate, full_reduced, improve_limit, raise_rows, reduced,
                         sort_lists)
from .search import COMPLETE, dfs

INF = np.inf


@njit(cache=True)
def tuple_index(G, pa, pb, pc, na, nb, nc):
    """Dense lookup ``(i_a, i_b, i_c) -> candidate`` for N = 3 (-1: none)."""
    idx = np.full((na + 1) * (nb + 1) * (nc + 1), -1, np.int64)
    for k in range(pa.shape[0]):
        idx[(pa[k] * (nb + 1) + pb[k]) * (nc + 1) + pc[k]] = k
    return idx


@njit(cache=True)
def recover3(c, pa, pb, chosen, idx, nb, nc, sel, sparse=True):
    """Primal recovery for N = 3 (Pattipati et al.): keep the relaxed solution's
    kept-axes pairs, attach the third axis by a 2-D assignment with misses (pair
    alone, or the index alone).  Fills ``sel``; returns ``(n, cost)``, ``n = -1`` if
    that assignment is infeasible.  ``sparse``: when every third-axis index has its
    single-index candidate, solve it as a sparse LAP (:mod:`.recovery`; the same
    optimum) instead of the dense Hungarian."""
    W = nc + 1
    npair = 0
    base_of = np.empty(chosen.shape[0], np.int64)
    for k in range(chosen.shape[0]):
        if chosen[k] and (pa[k] > 0 or pb[k] > 0):
            base_of[npair] = (pa[k] * (nb + 1) + pb[k]) * W
            npair += 1
    plain = True
    for g in range(npair):
        if idx[base_of[g]] >= 0:
            plain = False
            break
    if plain:
        for t in range(1, nc + 1):
            if idx[t] >= 0:
                plain = False
                break
    if plain and npair != nc:
        return -1, INF
    if not plain:
        gated = True                      # every index has its single: sparse LAP
        for t in range(1, nc + 1):
            if idx[t] < 0:
                gated = False
                break
        if gated and sparse:
            return recover3_sparse(c, base_of, npair, idx, nc, sel)
    S = nc if plain else npair + nc
    A = np.full((S, S), INF)
    for g in range(npair):
        for t in range(nc):
            k = idx[base_of[g] + t + 1]
            if k >= 0:
                A[g, t] = c[k]
    if not plain:
        for g in range(npair):
            k = idx[base_of[g]]
            if k >= 0:
                A[g, nc + g] = c[k]
        for t in range(nc):
            k = idx[t + 1]
            if k >= 0:
                A[npair + t, t] = c[k]
            for g in range(npair):
                A[npair + t, nc + g] = 0.0
    ok, col, u, v, cost = hungarian(A)
    if not ok:
        return -1, INF
    n = 0
    for g in range(npair):
        t = col[g]
        sel[n] = idx[base_of[g] + t + 1] if t < nc else idx[base_of[g]]
        n += 1
    if not plain:
        for t in range(nc):
            if col[npair + t] < nc:
                sel[n] = idx[col[npair + t] + 1]
                n += 1
    return n, cost


from .outcomes import INFEASIBLE, PROVEN, STOPPED  # noqa: E402  (solve()'s outcomes)


@njit(cache=True, nogil=True)
def solve(G, pa, pb, c, relaxed, a, b, off_a, off_b, na, nb, plain, axis_of, ptr, lst,
          int_costs, tol, y0, max_iter, probe_every, probe_budget, budget,
          lam0, patience, lam_min, deflect, recover_every, n3, off_c, n_c, warm_start,
          stall_tol, stop):
    """Subgradient ascent on ``L(y)`` with periodic DFS probes, then a final DFS.

    ``stop`` is a one-element array another thread may set non-zero (time limit,
    Ctrl-C): the ascent checks it every iteration, the searches every 1024 nodes,
    and the call returns ``STOPPED`` with its incumbent and bound.  Compiled with
    ``nogil`` so that the caller can run it in a thread and keep the clock.

    Returns ``(outcome, best_sel, best_len, ub, bound, iterations, nodes)``.
    """
    K, N = G.shape
    E = ptr.shape[0] - 1
    y = y0.copy()
    r = np.empty(K)
    rp = np.empty(K)
    yfull = np.zeros(E)
    ybest = np.zeros(E)
    chosen = np.zeros(K, np.int8)
    rfull = np.empty(K)
    g = np.zeros(E)
    dvec = np.zeros(E)
    vwarm = np.zeros(na if plain else na + nb)
    best_sel = np.full(E + 1, -1, np.int64)
    best_len = -1
    ub = INF
    best_L = -INF
    L_probe = -INF
    lam = lam0
    since = 0
    nodes = 0
    it = 0
    nc = 0
    if n3:
        pc = np.zeros(K, np.int64)
        for k in range(K):
            e = G[k, relaxed[0]]
            pc[k] = 0 if e < 0 else e - off_c + 1
        nc = n_c
        idx3 = tuple_index(G, pa, pb, pc, na, nb, nc)
    else:
        idx3 = np.empty(0, np.int64)
    tmp_sel = np.empty(E + 1, np.int64)
    for it in range(1, max_iter + 1):
        if stop[0] != 0:
            return STOPPED, best_sel, best_len, ub, best_L, it, nodes
        ok, L = evaluate(G, pa, pb, c, relaxed, off_a, off_b, y, na, nb, plain, r,
                         yfull, chosen, vwarm, warm_start and it > 1)
        if not ok:
            return INFEASIBLE, best_sel, best_len, ub, INF, it, nodes
        g[:] = 0.0
        for t in range(relaxed.shape[0]):
            s = relaxed[t]
            for k in range(K):
                e = G[k, s]
                if chosen[k] and e >= 0:
                    g[e] -= 1.0
        norm2 = 0.0
        for e in range(E):
            if axis_of[e] != a and axis_of[e] != b:
                g[e] += 1.0
                norm2 += g[e] * g[e]
        # greedy raise of the relaxed rows: a bound >= L(y) at the cost of two passes
        neg = full_reduced(G, c, yfull, rfull)
        raise_rows(ptr, lst, axis_of, a, b, yfull, rfull)
        B = yfull.sum() + neg
        if B > L:
            L = B
        if L > best_L:
            best_L = L
            ybest[:] = yfull
            since = 0
        else:
            since += 1
            if since >= patience:
                lam *= 0.5
                since = 0
        if norm2 == 0.0:                  # relaxed solution covers every row once
            cost = 0.0
            n = 0
            for k in range(K):
                if chosen[k]:
                    best_sel[n] = k
                    n += 1
                    cost += c[k]
            if cost < ub:
                ub = cost
                best_len = n
            return PROVEN, best_sel, best_len, ub, max(best_L, cost), it, nodes
        if n3 and recover_every > 0 and (it - 1) % recover_every == 0:
            m, cost = recover3(c, pa, pb, chosen, idx3, nb, nc, tmp_sel)
            if m > 0 and (ub == INF or cost < ub - 1e-12 * max(1.0, abs(ub))):
                ub = cost
                best_sel[:m] = tmp_sel[:m]
                best_len = m
        if it == 1 and ub == INF:         # no recovery: a greedy cover to start from
            m, cost = greedy_cover(G, c, c, E, tmp_sel)
            if m > 0:
                ub = cost
                best_sel[:m] = tmp_sel[:m]
                best_len = m
        if best_L >= improve_limit(ub, int_costs, tol):
            return PROVEN, best_sel, best_len, ub, best_L, it, nodes
        if probe_every > 0 and (it - 1) % probe_every == 0:
            if it > 1 and ub < INF and best_L - L_probe < stall_tol * (ub - best_L):
                break                     # the bound has stopped moving: search now
            L_probe = best_L
            base = reduced(G, c, ybest, rp, ptr, lst, axis_of)
            sptr, slst = sort_lists(ptr, lst, rp,
                                    improve_limit(ub, int_costs, tol) - base)
            out, ub, best_len, nn = dfs(G, c, rp, base, sptr, slst, axis_of, N,
                                        int_costs, tol, ub, best_sel, best_len,
                                        probe_budget, stop, -INF)
            nodes += nn
            if out == COMPLETE:
                return PROVEN, best_sel, best_len, ub, best_L, it, nodes
        if lam < lam_min:
            break
        target = ub if ub < INF else best_L + 0.05 * max(abs(best_L), 1.0)
        nd2 = 0.0
        for e in range(E):                # deflected direction (Camerini et al.)
            dvec[e] = g[e] + deflect * dvec[e]
            nd2 += dvec[e] * dvec[e]
        if nd2 <= 0.0:                    # the deflection cancelled g: restart from g
            for e in range(E):
                dvec[e] = g[e]
            nd2 = norm2
        step = lam * (target - L) / nd2
        for e in range(E):
            y[e] += step * dvec[e]
    base = reduced(G, c, ybest, rp, ptr, lst, axis_of)
    sptr, slst = sort_lists(ptr, lst, rp, improve_limit(ub, int_costs, tol) - base)
    out, ub, best_len, nn = dfs(G, c, rp, base, sptr, slst, axis_of, N, int_costs, tol,
                                ub, best_sel, best_len, budget, stop, -INF)
    nodes += nn
    if out == COMPLETE:
        return PROVEN, best_sel, best_len, ub, best_L, it, nodes
    return STOPPED, best_sel, best_len, ub, best_L, it, nodes
