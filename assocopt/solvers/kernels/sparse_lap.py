"""Compiled sparse rectangular LAP (numba): shortest augmenting paths, Dijkstra on a heap.

Every row is assigned to one column, each column at most once, at least total edge
cost; the graph is an edge list, never a matrix.  This is the Jonker-Volgenant /
Crouse shortest-augmenting-path method (the one behind
:func:`scipy.optimize.linear_sum_assignment`) with the dense scan for the closest
column replaced by a binary heap over the columns reached so far: one augmentation
costs ``O(e log e)`` in the ``e`` edges it reaches.  On a gated tracking scan a new
track's path almost always ends a few gates away, so the whole solve is close to
linear in the number of edges -- where scipy's LAPJVsp
(:func:`scipy.sparse.csgraph.min_weight_full_bipartite_matching`) scans every column
still in its list on each step of a path.

Duals: ``u`` (rows) and ``v`` (columns) keep ``w_e - u_i - v_j >= 0`` on every edge of
an assigned row, with equality on its assigned edge; the path lengths are those
reduced costs, so Dijkstra is exact, and each augmentation is a shortest one, which
keeps the assignment optimal among those of the rows done so far (the classical
successive-shortest-path argument).  A row whose search runs out of columns before it
finds a free one cannot be added: by Hall's theorem no assignment of all rows exists.

Imported only when the sparse 2-D engine runs (importing numba costs half a second);
compiled on first use and cached on disk (``cache=True``).
"""

from __future__ import annotations

import numpy as np
from .jit import njit

__all__ = ["lap_edges"]


@njit(cache=True, nogil=True)
def _csr(nr: int, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row pointers and the row-sorted order of the edges (counting sort, stable)."""
    indptr = np.zeros(nr + 1, np.int64)
    for e in range(len(rows)):
        indptr[rows[e] + 1] += 1
    for i in range(nr):
        indptr[i + 1] += indptr[i]
    fill = indptr[:-1].copy()
    order = np.empty(len(rows), np.int64)
    for e in range(len(rows)):
        i = rows[e]
        order[fill[i]] = e
        fill[i] += 1
    return indptr, order


@njit(cache=True, nogil=True, inline="always")
def _push(hk: np.ndarray, hv: np.ndarray, size: int, key: float, val: int) -> int:
    i = size
    while i > 0:
        p = (i - 1) >> 1
        if hk[p] <= key:
            break
        hk[i] = hk[p]
        hv[i] = hv[p]
        i = p
    hk[i] = key
    hv[i] = val
    return size + 1


@njit(cache=True, nogil=True, inline="always")
def _pop(hk: np.ndarray, hv: np.ndarray, size: int) -> int:
    """Remove the top (read ``hk[0]``, ``hv[0]`` first); the new size."""
    size -= 1
    key = hk[size]
    val = hv[size]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and hk[c + 1] < hk[c]:
            c += 1
        if hk[c] >= key:
            break
        hk[i] = hk[c]
        hv[i] = hv[c]
        i = c
    hk[i] = key
    hv[i] = val
    return size


@njit(cache=True, nogil=True)
def _reduce_rows(indptr: np.ndarray, adj: np.ndarray, cost: np.ndarray, u: np.ndarray,
                 v: np.ndarray, edge_of_row: np.ndarray, row4col: np.ndarray,
                 free: np.ndarray, nfree: int) -> int:
    """One pass of Jonker and Volgenant's augmenting row reduction over
    ``free[:nfree]``; the rows still free are left in ``free``, their number returned.

    Each free row takes its cheapest column (reduced cost ``w - v``) and lowers that
    column's ``v`` to the gap to its second cheapest, displacing the previous owner
    (processed next while prices fall, else left for the next pass).  Every assigned
    row keeps its cheapest column at reduced cost ``u_i``, so the duals stay those the
    shortest-path phase needs, wherever this stops (after a step budget: price wars
    of many tiny decrements are left to the exact phase)."""
    current = 0
    left = 0
    steps = 0
    budget = 4 * nfree + 16
    while current < nfree:
        i = free[current]
        current += 1
        steps += 1
        j1 = -1
        e1 = -1
        j2 = -1
        e2 = -1
        u1 = np.inf
        u2 = np.inf
        for e in range(indptr[i], indptr[i + 1]):
            j = adj[e]
            r = cost[e] - v[j]
            if r < u2:
                if r < u1:
                    u2 = u1
                    j2 = j1
                    e2 = e1
                    u1 = r
                    j1 = j
                    e1 = e
                else:
                    u2 = r
                    j2 = j
                    e2 = e
        if j1 < 0:                      # no edge: left to the exact phase (infeasible)
            free[left] = i
            left += 1
            continue
        i0 = row4col[j1]
        lowers = j2 >= 0 and u1 < u2 and steps < budget
        if lowers:
            v[j1] -= u2 - u1
            u[i] = u2
        else:
            u[i] = u1
            if i0 >= 0 and j2 >= 0 and u2 == u1:
                j1 = j2
                e1 = e2
                i0 = row4col[j2]
        if i0 >= 0:
            edge_of_row[i0] = -1
            if lowers:
                current -= 1
                free[current] = i0
            else:
                free[left] = i0
                left += 1
        edge_of_row[i] = e1
        row4col[j1] = i
    return left


@njit(cache=True, nogil=True)
def lap_edges(nr: int, nc: int, rows: np.ndarray, cols: np.ndarray,
              w: np.ndarray) -> tuple[np.ndarray, int]:
    """The edge assigned to each row (an index into ``rows``/``cols``/``w``) of a
    minimum-cost assignment of every row, and ``-1``; or, when none exists, the
    first row that cannot be added in place of ``-1``."""
    indptr, order = _csr(nr, rows)
    adj = cols[order]
    cost = w[order]
    m = len(rows)
    u = np.zeros(nr)
    v = np.zeros(nc)
    edge_of_row = np.full(nr, -1, np.int64)     # CSR position of the row's edge
    row4col = np.full(nc, -1, np.int64)
    dist = np.full(nc, np.inf)
    via = np.empty(nc, np.int64)                # CSR position of the edge reaching j
    prev = np.empty(nc, np.int64)               # ... and its row
    done = np.zeros(nc, np.bool_)
    touched = np.empty(nc, np.int64)
    seen = np.empty(nr, np.int64)
    hk = np.empty(m + 1)
    hv = np.empty(m + 1, np.int64)
    free = np.arange(nr)
    nfree = nr
    for _ in range(2):
        nfree = _reduce_rows(indptr, adj, cost, u, v, edge_of_row, row4col, free, nfree)
    for f in range(nfree):
        cur = free[f]
        u[cur] = 0.0
        nt = 0
        ns = 0
        size = 0
        i = cur
        low = 0.0
        best = np.inf           # label of the closest free column reached so far ...
        sink = -1               # ... and that column (never pushed on the heap)
        while True:
            seen[ns] = i
            ns += 1
            base = low - u[i]
            for e in range(indptr[i], indptr[i + 1]):
                j = adj[e]
                if done[j]:
                    continue
                r = base + cost[e] - v[j]
                if r < dist[j] and r < best:      # no use beyond the closest free one
                    if dist[j] == np.inf:
                        touched[nt] = j
                        nt += 1
                    dist[j] = r
                    via[j] = e
                    prev[j] = i
                    if row4col[j] < 0:
                        best = r
                        sink = j
                    else:
                        size = _push(hk, hv, size, r, j)
            j = -1
            while size > 0:
                key = hk[0]
                if key >= best:
                    break
                top = hv[0]
                size = _pop(hk, hv, size)
                if not done[top] and key <= dist[top]:
                    j = top
                    break
            if j < 0:
                if sink < 0:
                    return np.empty(0, np.int64), cur
                low = best
                done[sink] = True
                break
            low = dist[j]
            done[j] = True
            i = row4col[j]
        u[cur] += low
        for s in range(1, ns):
            i = seen[s]
            u[i] += low - dist[adj[edge_of_row[i]]]
        for t in range(nt):
            j = touched[t]
            if done[j]:
                v[j] -= low - dist[j]
            dist[j] = np.inf
            done[j] = False
        j = sink
        while True:
            e = via[j]
            i = prev[j]
            row4col[j] = i
            old = edge_of_row[i]
            edge_of_row[i] = e
            if i == cur:
                break
            j = adj[old]
    out = np.empty(nr, np.int64)
    for i in range(nr):
        out[i] = order[edge_of_row[i]]
    return out, -1

