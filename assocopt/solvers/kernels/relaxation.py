"""The Lagrangian relaxation kernels: the arrays from a problem (``prepare``), ``L(y)``
with the kept axes solved by :mod:`.hungarian` (``evaluate``), reduced costs, greedy
dual raising and reduced-cost fixing of the candidate lists."""

from __future__ import annotations

import numpy as np
from .jit import PLAIN, njit

from .hungarian import hungarian_warm

INF = np.inf


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
    cannot be in a solution better than the incumbent), sorted by ``rp`` (ties by
    candidate: deterministic).  Returns the new ``(ptr, lst)``.

    Compiled: one stable sort of the kept candidates (:func:`stable_order`), then a
    counting placement into the rows, not a sort per row: a third of the time on a
    24,000-candidate 3-AP window.  As plain Python (:mod:`.tiers`), the sort per row
    (:func:`_sort_rows`), whose sorts are numpy's: seven times quicker there."""
    if PLAIN:
        return _sort_rows(ptr, lst, rp, slack)
    E = ptr.shape[0] - 1
    K = rp.shape[0]
    start = np.zeros(K + 1, np.int64)          # the rows of each kept candidate (CSR)
    for p in range(lst.shape[0]):
        k = lst[p]
        if rp[k] < slack:
            start[k + 1] += 1
    for k in range(K):
        start[k + 1] += start[k]
    rows = np.empty(start[K], np.int64)
    fill = start[:K].copy()
    for e in range(E):
        for p in range(ptr[e], ptr[e + 1]):
            k = lst[p]
            if rp[k] < slack:
                rows[fill[k]] = e
                fill[k] += 1
    order = stable_order(rp, np.flatnonzero(start[1:] > start[:K]))
    ptr2 = np.zeros(E + 1, np.int64)
    for q in range(rows.shape[0]):
        ptr2[rows[q] + 1] += 1
    for e in range(E):
        ptr2[e + 1] += ptr2[e]
    out = np.empty(rows.shape[0], np.int64)
    at = ptr2[:E].copy()
    for k in order:
        for q in range(start[k], start[k + 1]):
            e = rows[q]
            out[at[e]] = k
            at[e] += 1
    return ptr2, out


@njit(cache=True)
def _sort_rows(ptr, lst, rp, slack):
    """:func:`sort_lists` row by row (the same answer)."""
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
            out[start:n] = seg[np.argsort(rp[seg], kind="mergesort")]
        ptr2[e + 1] = n
    return ptr2, out[:n]


@njit(cache=True)
def stable_order(v, keep):
    """``keep`` (ascending positions) sorted by ``v[keep]``, ties in ``keep`` order.

    A bucket sort (about two entries a bucket, spread over the range of the values)
    then insertion sort inside each bucket, a comparison sort for a crowded one:
    linear time on the reduced costs of a window, where a merge sort of 24,000 of
    them took 2 ms."""
    m = keep.shape[0]
    if m < 64:
        return keep[np.argsort(v[keep], kind="mergesort")]
    lo, hi = INF, -INF
    for k in keep:
        lo = min(lo, v[k])
        hi = max(hi, v[k])
    if not hi > lo or not np.isfinite(hi - lo):
        return keep[np.argsort(v[keep], kind="mergesort")] if not hi == lo else keep.copy()
    B = m // 2
    scale = B / (hi - lo)
    bucket = np.empty(m, np.int64)
    first = np.zeros(B + 1, np.int64)
    for q in range(m):
        b = min(int((v[keep[q]] - lo) * scale), B - 1)
        bucket[q] = b
        first[b + 1] += 1
    for b in range(B):
        first[b + 1] += first[b]
    out = np.empty(m, np.int64)
    at = first[:B].copy()
    for q in range(m):
        b = bucket[q]
        out[at[b]] = keep[q]
        at[b] += 1
    for b in range(B):
        i0, i1 = first[b], first[b + 1]
        if i1 - i0 > 32:
            seg = out[i0:i1].copy()
            out[i0:i1] = seg[np.argsort(v[seg], kind="mergesort")]
            continue
        for i in range(i0 + 1, i1):
            k = out[i]
            x = v[k]
            j = i
            while j > i0 and v[out[j - 1]] > x:
                out[j] = out[j - 1]
                j -= 1
            out[j] = k
    return out
