"""Compiled kernels of the ``bnb`` back end (numba, nopython): a dense Hungarian
method with duals, the Lagrangian relaxation to a 2-D assignment with misses, and a
depth-first exact-cover branch and bound on reduced costs.

Importing this module imports numba; :mod:`assocopt.solvers.bnb` does so only inside
``solve``.  Functions are compiled on first use and cached on disk (``cache=True``).

Notation (as in :mod:`assocopt.solvers.lagrangian`): ``K`` candidates, ``N`` axes,
``G[k, s]`` the global row of the real index of candidate ``k`` on axis ``s`` (-1 for
the dummy), ``E`` real indices in all.  Axes ``a, b`` are kept, the others relaxed
with multipliers ``y[e]``.  For *any* ``y`` and any exact cover ``X``:

    cost(X) = sum_e y[e] + sum_{k in X} r[k],   r[k] = c[k] - sum_{e in k} y[e],

so ``base + sum_{k in X} max(r[k], 0)`` with ``base = sum(y) + sum_k min(r[k], 0)``
bounds every solution from below: the bound is valid whatever the multipliers, and
the ascent only makes it tight.
"""

from __future__ import annotations

import numpy as np
from numba import njit

INF = np.inf

# DFS outcomes
COMPLETE = 0       # search exhausted: the incumbent (if any) is optimal
BUDGET = 1         # node budget spent


@njit(cache=True)
def hungarian(A):
    """Min-cost perfect matching of the square matrix ``A`` (``inf`` = forbidden).

    Shortest augmenting paths with potentials.  Returns ``(ok, col_of_row, u, v,
    cost)`` with ``u[i] + v[j] <= A[i, j]`` for all finite entries, equality on the
    matching, and ``cost = sum(u) + sum(v)``; ``ok`` is False if no finite perfect
    matching exists.
    """
    return hungarian_warm(A, np.empty(0))


@njit(cache=True)
def hungarian_warm(A, v0):
    """:func:`hungarian` started from column potentials ``v0`` (length n; empty: cold).

    Warm start (for the nearly unchanged matrices of successive subgradient
    iterations): row potentials ``u[i] = min_j A[i, j] - v0[j]`` make the start dual
    feasible, every row whose tight column is still free is matched at once, and only
    the others are augmented.
    """
    n = A.shape[0]
    u = np.zeros(n + 1)
    v = np.zeros(n + 1)
    p = np.zeros(n + 1, np.int64)        # p[j]: row (1-based) matched to column j
    way = np.zeros(n + 1, np.int64)
    minv = np.empty(n + 1)
    used = np.empty(n + 1, np.bool_)
    done = np.zeros(n + 1, np.bool_)
    if v0.shape[0] == n:
        for j in range(1, n + 1):
            v[j] = v0[j - 1]
        for i in range(1, n + 1):
            m = INF
            jm = -1
            for j in range(1, n + 1):
                val = A[i - 1, j - 1] - v[j]
                if val < m:
                    m = val
                    jm = j
            if jm < 0:
                return False, np.zeros(n, np.int64), u[1:], v[1:], INF
            u[i] = m
            if p[jm] == 0:
                p[jm] = i
                done[i] = True
    for i in range(1, n + 1):
        if done[i]:
            continue
        p[0] = i
        j0 = 0
        minv[:] = INF
        used[:] = False
        while True:
            used[j0] = True
            i0 = p[j0]
            delta = INF
            j1 = -1
            ui0 = u[i0]
            for j in range(1, n + 1):
                if not used[j]:
                    cur = A[i0 - 1, j - 1] - ui0 - v[j]
                    if cur < minv[j]:
                        minv[j] = cur
                        way[j] = j0
                    if minv[j] < delta:
                        delta = minv[j]
                        j1 = j
            if j1 < 0 or delta == INF:
                return False, np.zeros(n, np.int64), u[1:], v[1:], INF
            for j in range(n + 1):
                if used[j]:
                    u[p[j]] += delta
                    v[j] -= delta
                else:
                    minv[j] -= delta
            j0 = j1
            if p[j0] == 0:
                break
        while True:
            j1 = way[j0]
            p[j0] = p[j1]
            j0 = j1
            if j0 == 0:
                break
    col = np.empty(n, np.int64)
    cost = 0.0
    for j in range(1, n + 1):
        col[p[j] - 1] = j - 1
        cost += A[p[j] - 1, j - 1]
    return True, col, u[1:], v[1:], cost



@njit(cache=True)
def prepare(T, off, sizes, c, a, b):
    """The kernels' arrays from the tuple array, in one pass (a counting sort).

    Returns ``(G, ptr, lst, y0, axis_of, int_costs, plain)``: global rows, the CSR
    lists of candidates per row (in candidate order), starting multipliers (each
    relaxed row's least per-index cost share; 0 on kept rows), the axis of each row,
    whether all costs are integers, and whether the kept axes need no misses.
    """
    K, N = T.shape
    E = 0
    for s in range(N):
        E += sizes[s]
    G = np.empty((K, N), np.int64)
    ptr = np.zeros(E + 1, np.int64)
    axis_of = np.empty(E, np.int64)
    for s in range(N):
        for i in range(sizes[s]):
            axis_of[off[s] + i] = s
    y0 = np.full(E, INF)
    int_costs = True
    plain = sizes[a] == sizes[b]
    for k in range(K):
        nreal = 0
        for s in range(N):
            t = T[k, s]
            if t > 0:
                e = off[s] + t - 1
                G[k, s] = e
                ptr[e + 1] += 1
                nreal += 1
            else:
                G[k, s] = -1
        share = c[k] / max(nreal, 1)
        for s in range(N):
            e = G[k, s]
            if e >= 0 and share < y0[e]:
                y0[e] = share
        if c[k] != np.round(c[k]) or abs(c[k]) >= 2.0 ** 52:
            int_costs = False
        if (T[k, a] == 0) != (T[k, b] == 0):
            plain = False
    for e in range(E):
        ptr[e + 1] += ptr[e]
        s = axis_of[e]
        if s == a or s == b or y0[e] == INF:
            y0[e] = 0.0
    fill = ptr[:-1].copy()
    lst = np.empty(ptr[E], np.int64)
    for k in range(K):
        for s in range(N):
            e = G[k, s]
            if e >= 0:
                lst[fill[e]] = k
                fill[e] += 1
    return G, ptr, lst, y0, axis_of, int_costs, plain


@njit(cache=True)
def evaluate(G, pa, pb, c, relaxed, off_a, off_b, y, na, nb, plain, r, yfull, chosen,
             vwarm, warm):
    """``L(y)`` of the relaxation that keeps axes ``a, b`` (``y`` is 0 on their rows).

    Fills ``r`` (reduced costs w.r.t. the relaxed multipliers), ``yfull`` (``y`` on the
    relaxed rows, the LAP duals on the kept rows) and ``chosen`` (1 for the
    candidates of the relaxed solution).  Returns ``(ok, L)``; ``ok`` False: the kept
    axes alone admit no assignment, so the problem is infeasible.
    """
    K = c.shape[0]
    W = nb + 1
    Cm = np.full((na + 1) * W, INF)
    Am = np.full((na + 1) * W, -1)
    neg = 0.0
    for k in range(K):
        rk = c[k]
        for t in range(relaxed.shape[0]):
            e = G[k, relaxed[t]]
            if e >= 0:
                rk -= y[e]
        r[k] = rk
        chosen[k] = 0
        q = pa[k] * W + pb[k]
        if q == 0:                       # dummy on both kept axes: free to take
            if rk < 0.0:
                neg += rk
                chosen[k] = 1
        elif rk < Cm[q]:
            Cm[q] = rk
            Am[q] = k
    S = na if plain else na + nb
    A = np.full((S, S), INF)
    for i in range(na):
        for j in range(nb):
            A[i, j] = Cm[(i + 1) * W + j + 1]
    if not plain:                        # misses: private dummy column / row each
        for i in range(na):
            A[i, nb + i] = Cm[(i + 1) * W]
        for j in range(nb):
            A[na + j, j] = Cm[j + 1]
            for i in range(na):
                A[na + j, nb + i] = 0.0
    ok, col, u, v, cost = hungarian_warm(A, vwarm if warm else vwarm[:0])
    if not ok:
        return False, -INF
    vwarm[:] = v                         # the next iteration starts from these
    yfull[:] = y
    for i in range(na):
        yfull[off_a + i] = u[i] if plain else u[i] + v[nb + i]
        j = col[i]
        k = Am[(i + 1) * W + j + 1] if j < nb else Am[(i + 1) * W]
        chosen[k] = 1
    for j in range(nb):
        # in the augmented matrix v[nb+i] + u[na+j] <= 0, so y_a[i] + y_b[j] <= C[i, j]
        yfull[off_b + j] = v[j] if plain else v[j] + u[na + j]
        if not plain and col[na + j] < nb:
            chosen[Am[col[na + j] + 1]] = 1
    return True, y.sum() + cost + neg


@njit(cache=True)
def improve_limit(ub, int_costs, tol):
    """Bounds at or above this cannot lead to a solution better than ``ub``."""
    if ub == INF:
        return INF
    if int_costs:
        return ub - 1.0 + max(1e-6, tol * abs(ub))
    return ub - tol * max(1.0, abs(ub))


@njit(cache=True)
def full_reduced(G, c, yfull, r):
    """``r = c - sum of yfull over each candidate's rows``; returns ``sum_k min(r, 0)``."""
    K, N = G.shape
    neg = 0.0
    for k in range(K):
        rk = c[k]
        for s in range(N):
            e = G[k, s]
            if e >= 0:
                rk -= yfull[e]
        r[k] = rk
        if rk < 0.0:
            neg += rk
    return neg


@njit(cache=True)
def raise_rows(ptr, lst, axis_of, skip_a, skip_b, yfull, r):
    """Greedy dual ascent: raise each row's dual by its least reduced cost when all
    its candidates have ``r >= 0`` (the bound grows by exactly that amount and every
    ``r`` stays >= 0).  Rows of axes ``skip_a, skip_b`` are left alone (-1: none)."""
    gain = 0.0
    for e in range(ptr.shape[0] - 1):
        s = axis_of[e]
        if s == skip_a or s == skip_b:
            continue
        m = INF
        for p in range(ptr[e], ptr[e + 1]):
            v = r[lst[p]]
            if v < m:
                m = v
        if m > 0.0 and m < INF:
            yfull[e] += m
            gain += m
            for p in range(ptr[e], ptr[e + 1]):
                r[lst[p]] -= m
    return gain


@njit(cache=True)
def reduced(G, c, yfull, rp, ptr, lst, axis_of):
    """Raise ``yfull`` on every row (in place), then ``rp = max(r, 0)``; returns
    ``base = sum(yfull) + sum_k min(r, 0)``."""
    neg = full_reduced(G, c, yfull, rp)
    raise_rows(ptr, lst, axis_of, -1, -1, yfull, rp)
    for k in range(rp.shape[0]):
        if rp[k] < 0.0:
            rp[k] = 0.0
    return yfull.sum() + neg


@njit(cache=True)
def sort_lists(ptr, lst, rp, slack):
    """Each row's candidates with ``rp < slack`` (reduced-cost fixing: the others
    cannot be in a solution better than the incumbent), sorted by ``rp`` (stable:
    deterministic).  Returns the new ``(ptr, lst)``."""
    E = ptr.shape[0] - 1
    ptr2 = np.zeros(E + 1, np.int64)
    out = np.empty(lst.shape[0], np.int64)
    n = 0
    for e in range(E):
        start = n
        for p in range(ptr[e], ptr[e + 1]):
            k = lst[p]
            if rp[k] < slack:
                out[n] = k
                n += 1
        if n - start > 1:
            seg = out[start:n].copy()
            order = np.argsort(rp[seg], kind="mergesort")
            out[start:n] = seg[order]
        ptr2[e + 1] = n
    return ptr2, out[:n]


@njit(cache=True)
def _free(G, k, covered):
    for s in range(G.shape[1]):
        e = G[k, s]
        if e >= 0 and covered[e]:
            return False
    return True


@njit(cache=True)
def _select(G, rp, ptr, lst, axis_of, covered, slack, rem):
    """Branching row: the uncovered row with the fewest live candidates (Knuth's
    rule).  ``slack`` = limit - base - acc.  Returns ``(row, bound)``; row -1: some
    row has no live candidate (dead node).  ``bound`` = max over axes of the sum of
    each uncovered row's least live reduced cost (one candidate per row per axis)."""
    rem[:] = 0.0
    best_e = -1
    best_cnt = 1 << 60
    for e in range(ptr.shape[0] - 1):
        if covered[e]:
            continue
        cnt = 0
        first = 0.0
        for p in range(ptr[e], ptr[e + 1]):
            k = lst[p]
            if rp[k] >= slack:
                break
            if _free(G, k, covered):
                if cnt == 0:
                    first = rp[k]
                cnt += 1
                if cnt >= best_cnt:
                    break
        if cnt == 0:
            return -1, INF
        rem[axis_of[e]] += first
        if cnt < best_cnt:
            best_cnt = cnt
            best_e = e
    return best_e, rem.max()


@njit(cache=True)
def dfs(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub, best_sel,
        best_len, budget):
    """Depth-first exact-cover search for a solution cheaper than ``ub``.

    Candidates are tried cheapest reduced cost first; a node is cut when
    ``base + acc + bound`` reaches the improvement limit.  Returns ``(outcome, ub,
    best_len, nodes)``; ``best_sel[:best_len]`` holds the incumbent.  ``COMPLETE``
    means no solution cheaper than the returned ``ub`` exists.
    """
    E = ptr.shape[0] - 1
    covered = np.zeros(E, np.bool_)
    rem = np.zeros(n_axes)
    stack_e = np.empty(E + 1, np.int64)
    stack_p = np.empty(E + 1, np.int64)
    stack_k = np.full(E + 1, -1, np.int64)
    limit = improve_limit(ub, int_costs, tol)
    nodes = 0
    ncov = 0
    acc = 0.0
    e0, bnd = _select(G, rp, ptr, lst, axis_of, covered, limit - base, rem)
    if e0 < 0 or base + bnd >= limit:
        return COMPLETE, ub, best_len, nodes
    d = 0
    stack_e[0] = e0
    stack_p[0] = ptr[e0]
    stack_k[0] = -1
    while d >= 0:
        k = stack_k[d]
        if k >= 0:                                  # undo the last choice here
            for s in range(n_axes):
                e = G[k, s]
                if e >= 0:
                    covered[e] = False
                    ncov -= 1
            acc -= rp[k]
            stack_k[d] = -1
        e = stack_e[d]
        p = stack_p[d]
        found = -1
        slack = limit - base - acc
        while p < ptr[e + 1]:
            k = lst[p]
            p += 1
            if rp[k] >= slack:
                p = ptr[e + 1]
                break
            if _free(G, k, covered):
                found = k
                break
        stack_p[d] = p
        if found < 0:
            d -= 1
            continue
        for s in range(n_axes):
            e = G[found, s]
            if e >= 0:
                covered[e] = True
                ncov += 1
        acc += rp[found]
        stack_k[d] = found
        nodes += 1
        if ncov == E:                               # leaf: an exact cover
            cost = 0.0
            for t in range(d + 1):
                cost += c[stack_k[t]]
            if cost < limit:
                ub = cost
                best_sel[:d + 1] = stack_k[:d + 1]
                best_len = d + 1
                limit = improve_limit(ub, int_costs, tol)
            continue
        if nodes >= budget:
            return BUDGET, ub, best_len, nodes
        e2, bnd = _select(G, rp, ptr, lst, axis_of, covered, limit - base - acc, rem)
        if e2 < 0 or base + acc + bnd >= limit:
            continue
        d += 1
        stack_e[d] = e2
        stack_p[d] = ptr[e2]
        stack_k[d] = -1
    return COMPLETE, ub, best_len, nodes


@njit(cache=True)
def tuple_index(G, pa, pb, pc, na, nb, nc):
    """Dense lookup ``(i_a, i_b, i_c) -> candidate`` for N = 3 (-1: none)."""
    idx = np.full((na + 1) * (nb + 1) * (nc + 1), -1, np.int64)
    for k in range(pa.shape[0]):
        idx[(pa[k] * (nb + 1) + pb[k]) * (nc + 1) + pc[k]] = k
    return idx


@njit(cache=True)
def recover3(c, pa, pb, chosen, idx, nb, nc, sel):
    """Primal recovery for N = 3 (Pattipati et al.): keep the relaxed solution's
    kept-axes pairs, attach the third axis by a 2-D assignment with misses (pair
    alone, or the index alone).  Fills ``sel``; returns ``(n, cost)``, ``n = -1`` if
    that assignment is infeasible."""
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


# solve() outcomes
PROVEN = 0         # incumbent optimal (or infeasible if there is none)
STOPPED = 1        # budget spent: incumbent (if any) and a bound
INFEASIBLE = 2     # the kept axes admit no assignment


@njit(cache=True)
def solve(G, pa, pb, c, relaxed, a, b, off_a, off_b, na, nb, plain, axis_of, ptr, lst,
          int_costs, tol, y0, max_iter, probe_every, probe_budget, budget,
          lam0, patience, lam_min, deflect, recover_every, n3, off_c, n_c, warm_start):
    """Subgradient ascent on ``L(y)`` with periodic DFS probes, then a final DFS.

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
        if best_L >= improve_limit(ub, int_costs, tol):
            return PROVEN, best_sel, best_len, ub, best_L, it, nodes
        if probe_every > 0 and (it - 1) % probe_every == 0:
            base = reduced(G, c, ybest, rp, ptr, lst, axis_of)
            sptr, slst = sort_lists(ptr, lst, rp,
                                    improve_limit(ub, int_costs, tol) - base)
            out, ub, best_len, nn = dfs(G, c, rp, base, sptr, slst, axis_of, N,
                                        int_costs, tol, ub, best_sel, best_len,
                                        probe_budget)
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
                                ub, best_sel, best_len, budget)
    nodes += nn
    if out == COMPLETE:
        return PROVEN, best_sel, best_len, ub, best_L, it, nodes
    return STOPPED, best_sel, best_len, ub, best_L, it, nodes


def cached() -> bool:
    """Whether compiled code of the main kernels is on disk (so the first call loads it
    instead of compiling for 15-30 s).  Reads numba's cache index paths, which are not
    public API: on any surprise it answers True (no warning rather than a wrong one)."""
    import os
    try:
        return all(os.path.exists(f._cache._cache_file._index_path)
                   for f in (solve, dfs, prepare))
    except Exception:
        return True
