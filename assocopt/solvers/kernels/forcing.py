"""Forced candidates of a search window (compiled): unit propagation before the search.

The window searches of ``lagrangian-exact`` look for an exact cover cheaper than a
limit among the candidates that reduced-cost fixing left.  Many rows of such a window
hold a single candidate below the limit: every cover that the search may accept uses
it, so it is taken at once, the candidates that share a row with it are dropped, and
that may leave further rows with one candidate.  :func:`force_window` repeats this to
the end and hands the search what is left, with the rows renumbered
(:func:`window_lists`: with the search's row lists, in one call): on a gated
N = 4 scan's window of 419 candidates over 443 rows, 102 candidates were forced and
206 over 163 rows were left, and each search node scans every uncovered row.

May import: numpy and the kernels' :mod:`.jit` and :mod:`.relaxation`.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .relaxation import prepare, sort_lists

__all__ = ["force_window", "window_lists"]


@njit(cache=True, nogil=True)
def _rows_csr(T, off, E, alive):
    """The alive candidates of each row (CSR ``ptr``, ``lst``) and their count."""
    K, N = T.shape
    cnt = np.zeros(E, np.int64)
    for k in range(K):
        if alive[k]:
            for s in range(N):
                if T[k, s] > 0:
                    cnt[off[s] + T[k, s] - 1] += 1
    ptr = np.zeros(E + 1, np.int64)
    for e in range(E):
        ptr[e + 1] = ptr[e] + cnt[e]
    fill = ptr[:E].copy()
    lst = np.empty(ptr[E], np.int64)
    for k in range(K):
        if alive[k]:
            for s in range(N):
                if T[k, s] > 0:
                    e = off[s] + T[k, s] - 1
                    lst[fill[e]] = k
                    fill[e] += 1
    return cnt, ptr, lst


@njit(cache=True, nogil=True)
def _none(N, sizes):
    """:func:`force_window`'s answer when no cover below the limit exists."""
    e = np.empty(0, np.int64)
    return 1, e, e.copy(), np.zeros((0, N), np.int64), sizes.copy(), 0.0, 0.0


@njit(cache=True, nogil=True)
def force_window(T, c, off, sizes, rp, slack):
    """Unit propagation over the candidates with ``rp < slack`` (the others cannot be
    in a cover below the limit: ``slack`` = limit - base).

    ``T`` (K, N) the window's tuples (the problem's indices, 0 = dummy) and ``c``
    their costs, ``off`` the row of index 1 of each axis, ``sizes`` (N,) the axis
    sizes.  Returns ``(status, forced, rest, T_rest, sizes_rest, c0, r0)``: ``status``
    1 when some row is left without a candidate (no cover below the limit exists),
    else 0; ``forced`` the candidates every such cover uses (in the order taken) and
    ``c0``, ``r0`` the sums of their ``c`` and ``rp`` in that order; ``rest`` the
    candidates still free (ascending), ``T_rest`` their tuples renumbered over the
    uncovered rows of each axis (1..``sizes_rest[s]``).
    """
    K, N = T.shape
    E = 0
    for s in range(N):
        E += sizes[s]
    alive = np.empty(K, np.bool_)
    for k in range(K):
        alive[k] = rp[k] < slack
    cnt, ptr, lst = _rows_csr(T, off, E, alive)
    covered = np.zeros(E, np.bool_)
    forced = np.empty(min(K, E), np.int64)
    nf = 0
    queue = np.empty(E, np.int64)               # a row reaches one candidate once
    qh = 0
    qt = 0
    for e in range(E):
        if cnt[e] == 0:
            return _none(N, sizes)
        if cnt[e] == 1:
            queue[qt] = e
            qt += 1
    while qh < qt:
        e = queue[qh]
        qh += 1
        if covered[e]:
            continue
        k = -1
        for p in range(ptr[e], ptr[e + 1]):
            if alive[lst[p]]:
                k = lst[p]
                break
        if k < 0:
            return _none(N, sizes)
        forced[nf] = k
        nf += 1
        alive[k] = False
        for s in range(N):
            if T[k, s] > 0:
                covered[off[s] + T[k, s] - 1] = True
        for s in range(N):                   # drop the candidates sharing a row
            if T[k, s] <= 0:
                continue
            r = off[s] + T[k, s] - 1
            for p in range(ptr[r], ptr[r + 1]):
                q = lst[p]
                if not alive[q]:
                    continue
                alive[q] = False
                for s2 in range(N):
                    if T[q, s2] > 0:
                        r2 = off[s2] + T[q, s2] - 1
                        cnt[r2] -= 1
                        if not covered[r2]:
                            if cnt[r2] == 0:
                                return _none(N, sizes)
                            if cnt[r2] == 1:
                                queue[qt] = r2
                                qt += 1
    new = np.zeros(E, np.int64)                  # renumbered rows, 1-based per axis
    sizes_rest = np.zeros(N, np.int64)
    for s in range(N):
        for i in range(sizes[s]):
            e = off[s] + i
            if not covered[e]:
                sizes_rest[s] += 1
                new[e] = sizes_rest[s]
    m = 0
    for k in range(K):
        if alive[k]:
            m += 1
    rest = np.empty(m, np.int64)
    T_rest = np.zeros((m, N), np.int64)
    m = 0
    for k in range(K):
        if alive[k]:
            rest[m] = k
            for s in range(N):
                if T[k, s] > 0:
                    T_rest[m, s] = new[off[s] + T[k, s] - 1]
            m += 1
    c0 = 0.0
    r0 = 0.0
    for q in range(nf):
        c0 += c[forced[q]]
        r0 += rp[forced[q]]
    return 0, forced[:nf].copy(), rest, T_rest, sizes_rest, c0, r0


@njit(cache=True, nogil=True)
def window_lists(T, c, off, sizes, rp, slack):
    """:func:`force_window`, then the search's arrays over what is left (as
    ``prepare`` and ``sort_lists`` give them).  Returns ``(status, forced, rest, c0,
    r0, G, ptr, lst, axis_of, c_rest, rp_rest)``; the lists hold the candidates of
    ``rest`` (by their place in it) below the slack left, ``slack - r0``."""
    status, forced, rest, T2, sizes2, c0, r0 = force_window(T, c, off, sizes, rp, slack)
    N = T.shape[1]
    off2 = np.zeros(N, np.int64)
    for s in range(1, N):
        off2[s] = off2[s - 1] + sizes2[s - 1]
    m = rest.shape[0]
    c2 = np.empty(m)
    rp2 = np.empty(m)
    for q in range(m):
        c2[q] = c[rest[q]]
        rp2[q] = rp[rest[q]]
    G, ptr, lst, _, axis_of, _, _ = prepare(T2, off2, sizes2, c2, 0, 1)
    sptr, slst = sort_lists(ptr, lst, rp2, slack - r0)
    return status, forced, rest, c0, r0, G, sptr, slst, axis_of, c2, rp2
