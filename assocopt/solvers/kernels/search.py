"""Depth-first exact-cover branch and bound on reduced costs (compiled)."""

from __future__ import annotations

import numpy as np
from .jit import njit

from .relaxation import improve_limit

INF = np.inf
#: Rows of a bit word, and the most words, of :func:`_dfs_bits`' row sets (int64
#: words, the sign bit unused, so that they mean the same compiled and as Python).
WORD = 63
MAX_WORDS = 2

from .outcomes import BUDGET, COMPLETE  # noqa: E402,F401  (dfs() outcomes)


@njit(cache=True)
def _mark(G, ptr, lst, blocked, k, n_axes, delta, rp, cut):
    """Add ``delta`` to the blocked count of every candidate sharing a row with ``k``
    whose reduced cost is below ``cut`` (``k`` chosen: +1; undone: -1, with the same
    ``cut``), so that "is it free" is one load.  The lists are sorted by reduced
    cost and every read below ``k``'s choice is of a candidate under the slack then,
    which only shrinks (the incumbent's limit falls, the partial cost grows): the
    counts of the others are never read while ``k`` is chosen, so they are skipped."""
    for s in range(n_axes):
        e = G[k, s]
        if e >= 0:
            for p in range(ptr[e], ptr[e + 1]):
                q = lst[p]
                if rp[q] >= cut:
                    break
                blocked[q] += delta


@njit(cache=True)
def _select(blocked, rp, ptr, lst, axis_of, covered, slack, rem):
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
            if blocked[k] == 0:
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


@njit(cache=True, nogil=True)
def dfs(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub, best_sel,
        best_len, budget, stop, floor, c0=0.0):
    """Depth-first exact-cover search for a solution cheaper than ``ub``.

    Stops as if the node budget were spent when ``stop[0]`` is set non-zero (checked
    at every node: a node's ``_select`` scans the uncovered rows' candidate lists,
    about 1.5 ms on Grundel n = 50 under load, so checking every 1024 nodes overshot a
    5 s limit by 1.1 s; see :func:`.driver.solve`).

    Candidates are tried cheapest reduced cost first; a node is cut when
    ``base + acc + bound`` reaches the improvement limit.  Returns ``(outcome, ub,
    best_len, nodes)``; ``best_sel[:best_len]`` holds the incumbent.  ``COMPLETE``
    means no solution cheaper than the returned ``ub`` exists.  ``floor``: a lower
    bound proven elsewhere (-inf if none); a solution that reaches it ends the search
    at once (the last window of ``lagrangian-exact`` otherwise proved again what the
    smaller windows before it had: Balas-Saltzman n = 22-26, 10-27 ms a window).
    ``c0``: a cost every cover adds (candidates taken before the search, whose rows
    are not in ``G``: :func:`.forcing.force_window`).

    Up to ``WORD * MAX_WORDS`` rows (a tracking scan's components), the search of
    :func:`_dfs_bits`: the same tree, cheaper nodes.
    """
    if ptr.shape[0] - 1 <= WORD * MAX_WORDS:
        return _dfs_bits(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub,
                         best_sel, best_len, budget, stop, floor, c0)
    return _dfs_counts(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub,
                       best_sel, best_len, budget, stop, floor, c0)


@njit(cache=True, nogil=True)
def _dfs_counts(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub, best_sel,
                best_len, budget, stop, floor, c0=0.0):
    """:func:`dfs` for any number of rows: "is it free" is a count of the chosen
    candidates that share a row with it, kept up to date by :func:`_mark`."""
    E = ptr.shape[0] - 1
    covered = np.zeros(E, np.bool_)
    blocked = np.zeros(rp.shape[0], np.int32)    # chosen candidates sharing a row
    rem = np.zeros(n_axes)
    stack_e = np.empty(E + 1, np.int64)
    stack_p = np.empty(E + 1, np.int64)
    stack_k = np.full(E + 1, -1, np.int64)
    stack_s = np.zeros(E + 1)                       # the cut of each choice's marks
    limit = improve_limit(ub, int_costs, tol)
    nodes = 0
    ncov = 0
    acc = 0.0
    e0, bnd = _select(blocked, rp, ptr, lst, axis_of, covered, limit - base, rem)
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
            _mark(G, ptr, lst, blocked, k, n_axes, -1, rp, stack_s[d])
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
            if blocked[k] == 0:
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
        stack_s[d] = limit - base - acc          # the slack below this choice, at most
        _mark(G, ptr, lst, blocked, found, n_axes, 1, rp, stack_s[d])
        stack_k[d] = found
        nodes += 1
        if ncov == E:                               # leaf: an exact cover
            cost = c0
            for t in range(d + 1):
                cost += c[stack_k[t]]
            if cost < limit:
                ub = cost
                best_sel[:d + 1] = stack_k[:d + 1]
                best_len = d + 1
                limit = improve_limit(ub, int_costs, tol)
                if limit <= floor:                  # nothing better can exist
                    return COMPLETE, ub, best_len, nodes
            continue
        if nodes >= budget or stop[0] != 0:
            return BUDGET, ub, best_len, nodes
        e2, bnd = _select(blocked, rp, ptr, lst, axis_of, covered, limit - base - acc, rem)
        if e2 < 0 or base + acc + bnd >= limit:
            continue
        d += 1
        stack_e[d] = e2
        stack_p[d] = ptr[e2]
        stack_k[d] = -1
    return COMPLETE, ub, best_len, nodes


@njit(cache=True)
def _row_sets(G, E):
    """Each candidate's rows as bit words (``(K, W)``, row ``e``: bit ``e % WORD`` of
    word ``e // WORD``) and how many it has."""
    K, N = G.shape
    W = (E + WORD - 1) // WORD
    mask = np.zeros((K, max(W, 1)), np.int64)
    nrow = np.zeros(K, np.int64)
    for k in range(K):
        for s in range(N):
            e = G[k, s]
            if e >= 0:
                mask[k, e // WORD] |= np.int64(1) << np.int64(e % WORD)
                nrow[k] += 1
    return mask, nrow


@njit(cache=True)
def _free(mask, cov, k):
    """Whether none of candidate ``k``'s rows is covered."""
    for w in range(cov.shape[0]):
        if mask[k, w] & cov[w]:
            return False
    return True


@njit(cache=True)
def _select_bits(mask, cov, rp, ptr, lst, axis_of, slack, rem):
    """:func:`_select` with "is it free" read from the row sets: ``(row, bound)``."""
    rem[:] = 0.0
    best_e = -1
    best_cnt = 1 << 60
    for e in range(ptr.shape[0] - 1):
        if (cov[e // WORD] >> np.int64(e % WORD)) & 1:
            continue
        cnt = 0
        first = 0.0
        for p in range(ptr[e], ptr[e + 1]):
            k = lst[p]
            if rp[k] >= slack:
                break
            if _free(mask, cov, k):
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


@njit(cache=True, nogil=True)
def _dfs_bits(G, c, rp, base, ptr, lst, axis_of, n_axes, int_costs, tol, ub, best_sel,
              best_len, budget, stop, floor, c0=0.0):
    """:func:`dfs` for at most ``WORD * MAX_WORDS`` rows: the covered rows are bit
    words, so a candidate is free when its row set misses them (one or two ANDs), and
    choosing or undoing a candidate is an OR or an AND-NOT: no blocked counts to keep
    (their upkeep was half of a node on the components of a tracking scan).  Visits
    the same nodes in the same order, so it returns what :func:`dfs` returns."""
    E = ptr.shape[0] - 1
    mask, nrow = _row_sets(G, E)
    cov = np.zeros(mask.shape[1], np.int64)
    rem = np.zeros(n_axes)
    stack_e = np.empty(E + 1, np.int64)
    stack_p = np.empty(E + 1, np.int64)
    stack_k = np.full(E + 1, -1, np.int64)
    W = cov.shape[0]
    limit = improve_limit(ub, int_costs, tol)
    nodes = 0
    ncov = 0
    acc = 0.0
    e0, bnd = _select_bits(mask, cov, rp, ptr, lst, axis_of, limit - base, rem)
    if e0 < 0 or base + bnd >= limit:
        return COMPLETE, ub, best_len, nodes
    d = 0
    stack_e[0] = e0
    stack_p[0] = ptr[e0]
    stack_k[0] = -1
    while d >= 0:
        k = stack_k[d]
        if k >= 0:                                  # undo the last choice here
            for w in range(W):
                cov[w] &= ~mask[k, w]
            ncov -= nrow[k]
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
            if _free(mask, cov, k):
                found = k
                break
        stack_p[d] = p
        if found < 0:
            d -= 1
            continue
        for w in range(W):
            cov[w] |= mask[found, w]
        ncov += nrow[found]
        acc += rp[found]
        stack_k[d] = found
        nodes += 1
        if ncov == E:                               # leaf: an exact cover
            cost = c0
            for t in range(d + 1):
                cost += c[stack_k[t]]
            if cost < limit:
                ub = cost
                best_sel[:d + 1] = stack_k[:d + 1]
                best_len = d + 1
                limit = improve_limit(ub, int_costs, tol)
                if limit <= floor:                  # nothing better can exist
                    return COMPLETE, ub, best_len, nodes
            continue
        if nodes >= budget or stop[0] != 0:
            return BUDGET, ub, best_len, nodes
        e2, bnd = _select_bits(mask, cov, rp, ptr, lst, axis_of, limit - base - acc, rem)
        if e2 < 0 or base + acc + bnd >= limit:
            continue
        d += 1
        stack_e[d] = e2
        stack_p[d] = ptr[e2]
        stack_k[d] = -1
    return COMPLETE, ub, best_len, nodes
