"""The Lagrangian subproblem of a gated (sparse) S-D problem, compiled: the non-grid
path of :class:`assocopt.solvers.lagrangian.relaxation._Relaxation` with
``lap="sparse"`` and miss groups (a tracking scan with dummies).

Per subgradient iteration numpy made about forty calls (reduced costs per relaxed
axis, ``minimum.reduceat``, the augmented edge list, the LAP, ``searchsorted``, the
first minimum per chosen group, a ``bincount``): about 0.3 ms on a 22 000-candidate
scan, most of it call overhead, and the recursive primal recovery about 1 ms (a
``lexsort`` and a LAP per relaxed axis).  :func:`sparse_eval` and
:func:`sparse_recover` do each in one call, step for step as the numpy code does (the
same edge lists in the same order, handed to the same LAP :func:`.sparse_lap.lap_edges`),
so both give the same selections; the sums the numpy code takes pairwise (``L(u)``)
are taken in its order (:func:`.sums.np_sum`), so the values are the same bits too.

Status codes: ``0`` done, ``1`` no assignment exists (numpy: ``LapInfeasibleError``),
``2`` a case this kernel leaves to the numpy code (a LAP without any finite miss
cost, which numpy hands to scipy).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .sparse_lap import lap_edges
from .sums import np_sum

__all__ = ["sparse_eval", "sparse_recover"]


@njit(cache=True, nogil=True)
def _with_misses(n1, n2, rows, cols, w, rm, cm):
    """``assign_with_misses(..., method="sparse")`` on the augmented edge list
    (``augmented_edges``' order).  Returns ``(status, col_of_row, row_of_col)``."""
    cor = np.full(n1, -1, np.int64)
    roc = np.full(n2, -1, np.int64)
    nir = 0
    for i in range(n1):
        if np.isfinite(rm[i]):
            nir += 1
    njc = 0
    for j in range(n2):
        if np.isfinite(cm[j]):
            njc += 1
    if nir == 0 and njc == 0:
        if n1 != n2:
            return 1, cor, roc
        if n1 == 0:
            return 0, cor, roc
        return 2, cor, roc
    ne = len(rows)
    m = 2 * ne + nir + njc
    er = np.empty(m, np.int64)
    ec = np.empty(m, np.int64)
    ew = np.empty(m)
    for e in range(ne):
        er[e] = rows[e]
        ec[e] = cols[e]
        ew[e] = w[e]
        er[ne + nir + njc + e] = n1 + cols[e]
        ec[ne + nir + njc + e] = n2 + rows[e]
        ew[ne + nir + njc + e] = 0.0
    p = ne
    for i in range(n1):
        if np.isfinite(rm[i]):
            er[p] = i
            ec[p] = n2 + i
            ew[p] = rm[i]
            p += 1
    for j in range(n2):
        if np.isfinite(cm[j]):
            er[p] = n1 + j
            ec[p] = j
            ew[p] = cm[j]
            p += 1
    size = n1 + n2
    edge, bad = lap_edges(size, size, er, ec, ew)
    if bad >= 0:
        return 1, cor, roc
    for r in range(size):
        c = ec[edge[r]]
        if r < n1 and c < n2:
            cor[r] = c
            roc[c] = r
    return 0, cor, roc


@njit(cache=True, nogil=True, inline="always")
def _reduced(c, U, upad, k, first):
    """``c[k] - sum_t upad[U[t, k]]`` over ``t >= first``, subtracted in numpy's
    order (``U[t]``: the multiplier slot of every candidate on relaxed axis ``t``)."""
    v = c[k]
    for t in range(first, U.shape[0]):
        v -= upad[U[t, k]]
    return v


@njit(cache=True, nogil=True)
def sparse_eval(c, U, u_off, upad, nf, g_start, g_count, gkey, na, nb,
                pair_g, pr, pc, rm_g, rm_i, cm_g, cm_j):
    """``L(u)``'s pieces at multipliers ``upad`` (layout of ``_Relaxation``; ``U[t]``
    the multiplier slot of each candidate on relaxed axis ``t``).

    Returns ``(status, rc, gmin, chosen, sel, neg, subgradient, col_of_row,
    row_of_col, value, free_value)``: reduced costs, group minima, the chosen groups
    (matched rows, then missed rows, then missed columns), the relaxed solution (each
    chosen group's first minimum, then the negative free candidates ``neg``), ``L(u)``
    and the free candidates' part of it (summed as numpy sums them)."""
    rc = c.copy()
    for t in range(U.shape[0]):          # axis by axis: quicker than candidate-major
        for k in range(len(c)):
            rc[k] -= upad[U[t, k]]
    G = len(g_start)
    gmin = np.empty(G)
    for g in range(G):
        s = g_start[g]
        best = rc[s]
        for k in range(s + 1, s + g_count[g]):
            if rc[k] < best:
                best = rc[k]
        gmin[g] = best
    nneg = 0
    for k in range(nf):
        if rc[k] < 0:
            nneg += 1
    neg = np.empty(nneg, np.int64)
    p = 0
    for k in range(nf):
        if rc[k] < 0:
            neg[p] = k
            p += 1
    pw = np.empty(len(pair_g))
    for e in range(len(pair_g)):
        pw[e] = gmin[pair_g[e]]
    rm = np.full(na, np.inf)
    for e in range(len(rm_g)):
        rm[rm_i[e]] = gmin[rm_g[e]]
    cm = np.full(nb, np.inf)
    for e in range(len(cm_g)):
        cm[cm_j[e]] = gmin[cm_g[e]]
    status, cor, roc = _with_misses(na, nb, pr, pc, pw, rm, cm)
    u_len = len(upad)
    g = np.zeros(u_len)
    if status != 0:
        return status, rc, gmin, np.empty(0, np.int64), np.empty(0, np.int64), neg, g, \
            cor, roc, 0.0, 0.0
    nk = na
    for j in range(nb):
        if roc[j] < 0:
            nk += 1
    keys = np.empty(nk, np.int64)
    w = nb + 1
    p = 0
    for i in range(na):
        if cor[i] >= 0:
            keys[p] = (i + 1) * w + cor[i] + 1
            p += 1
    for i in range(na):
        if cor[i] < 0:
            keys[p] = (i + 1) * w
            p += 1
    for j in range(nb):
        if roc[j] < 0:
            keys[p] = j + 1
            p += 1
    chosen = np.searchsorted(gkey, keys)
    sel = np.empty(nk + nneg, np.int64)
    ns = 0
    for q in range(nk):
        gr = chosen[q]
        s = g_start[gr]
        for k in range(s, s + g_count[gr]):
            if rc[k] == gmin[gr]:
                sel[ns] = k
                ns += 1
                break
    for q in range(nneg):
        sel[ns] = neg[q]
        ns += 1
    sel = sel[:ns]
    cover = np.zeros(u_len, np.int64)
    for t in range(U.shape[0]):
        for q in range(ns):
            cover[U[t, sel[q]]] += 1
    for x in range(u_len):
        g[x] = 1.0 - cover[x]
    for t in range(len(u_off)):
        g[u_off[t]] = 0.0
    picked = np.empty(nk)
    for q in range(nk):
        picked[q] = gmin[chosen[q]]
    free = np.empty(nneg)
    for q in range(nneg):
        free[q] = rc[neg[q]]
    free_value = np_sum(free)
    value = np_sum(picked) + free_value + np_sum(upad)
    return 0, rc, gmin, chosen, sel, neg, g, cor, roc, value, free_value


@njit(cache=True, nogil=True)
def _key_order(jr, lab, nj, nl):
    """A stable order of ``(lab, jr)`` pairs (``jr < nj``, ``lab < nl``): two counting
    sorts, least significant first (numpy: ``lexsort``)."""
    return _counting_pass(lab, nl, _counting_pass(jr, nj, np.arange(len(jr))))


@njit(cache=True, nogil=True)
def _counting_pass(key, nk, src):
    """The positions ``src`` stably sorted by ``key[src]`` (``key < nk``)."""
    cnt = np.zeros(nk + 1, np.int64)
    for y in range(len(src)):
        cnt[key[src[y]] + 1] += 1
    for q in range(nk):
        cnt[q + 1] += cnt[q]
    out = np.empty(len(src), np.int64)
    for y in range(len(src)):
        x = src[y]
        out[cnt[key[x]]] = x
        cnt[key[x]] += 1
    return out


@njit(cache=True, nogil=True)
def sparse_recover(c, U, u_off, sizes, upad, nf, g_start, g_count, chosen):
    """The recursive 2-D recovery from the chosen groups: one assignment with misses
    per relaxed axis, of the current groups against that axis's indices, each edge
    weighted by its cheapest candidate net of the later axes' multipliers (``sizes``:
    the relaxed axes' sizes, ``U`` as in :func:`sparse_eval`).  Returns
    ``(status, sel)``: the feasible solution (sorted positions) when status is 0."""
    G = len(chosen)
    n = nf
    for q in range(G):
        n += g_count[chosen[q]]
    cand = np.empty(n, np.int64)
    lab = np.empty(n, np.int64)
    p = 0
    for q in range(G):
        s = g_start[chosen[q]]
        for k in range(s, s + g_count[chosen[q]]):
            cand[p] = k
            lab[p] = q
            p += 1
    for k in range(nf):
        cand[p] = k
        lab[p] = G
        p += 1
    for step in range(U.shape[0]):
        nr = sizes[step]
        m = len(cand)
        w = np.empty(m)
        jr = np.empty(m, np.int64)
        key = np.empty(m, np.int64)
        for x in range(m):
            k = cand[x]
            w[x] = _reduced(c, U, upad, k, step + 1)
            jr[x] = U[step, k] - u_off[step]
            key[x] = lab[x] * (nr + 1) + jr[x]
        o = _key_order(jr, lab, nr + 1, G + 1)
        # edges in key order: the cheapest candidate of each (group, index) pair
        er = np.empty(m, np.int64)
        ec = np.empty(m, np.int64)
        ew = np.empty(m)
        rm = np.full(G, np.inf)
        cm = np.full(nr, np.inf)
        ne = 0
        x = 0
        while x < m:
            kk = key[o[x]]
            best = w[o[x]]
            y = x + 1
            while y < m and key[o[y]] == kk:
                if w[o[y]] < best:
                    best = w[o[y]]
                y += 1
            ul = kk // (nr + 1)
            uj = kk % (nr + 1)
            if ul < G and uj > 0:
                er[ne] = ul
                ec[ne] = uj - 1
                ew[ne] = best
                ne += 1
            elif ul < G:
                rm[ul] = best
            elif uj > 0:
                cm[uj - 1] = best
            x = y
        status, cor, roc = _with_misses(G, nr, er[:ne], ec[:ne], ew[:ne], rm, cm)
        if status != 0:
            return status, np.empty(0, np.int64)
        lab_of_col = np.full(nr + 1, -1, np.int64)
        nn = 0
        for j in range(nr):
            if roc[j] < 0:
                lab_of_col[j + 1] = G + nn
                nn += 1
        null = G + nn
        lab_of_col[0] = null
        p = 0
        for x in range(m):
            l = lab[x]
            if l < G:
                if jr[x] == cor[l] + 1:
                    cand[p] = cand[x]
                    lab[p] = l
                    p += 1
            else:
                ln = lab_of_col[jr[x]]
                if ln >= 0:
                    cand[p] = cand[x]
                    lab[p] = ln
                    p += 1
        cand = cand[:p]
        lab = lab[:p]
        G = null
    seen = np.zeros(G, np.bool_)
    out = np.empty(len(cand), np.int64)
    p = 0
    for x in range(len(cand)):
        if lab[x] < G:
            if seen[lab[x]]:
                return 1, np.empty(0, np.int64)
            seen[lab[x]] = True
            out[p] = cand[x]
            p += 1
    return 0, np.sort(out[:p])
