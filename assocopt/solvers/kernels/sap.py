"""Rectangular linear assignment by shortest augmenting paths, warm-startable
(Jonker-Volgenant / Crouse style, one Dijkstra per row); compiled with numba.

Problem: an ``nr x nc`` matrix ``A`` (``nr <= nc``, ``inf`` = forbidden), every row
assigned to a distinct column, columns free at no cost.  State: ``x[i]`` the column of
row ``i`` (-1: none), ``y[j]`` the row of column ``j`` (-1: free), duals ``u`` (rows),
``v`` (columns) with reduced costs ``A[i, j] - u[i] - v[j] >= 0`` on every allowed
entry and ``= 0`` on the pairs of ``x``.  One augmentation (:func:`augment`) takes an
unassigned row to a free column along the path of least total reduced cost and moves
the duals so that both conditions still hold; when every row is assigned, the duals
prove the assignment optimal.  For a rectangular matrix the proof also needs the free
columns to share the largest ``v`` (``v <= 0`` with ``v = 0`` on the free columns, up to
a constant moved from ``v`` to ``u``): a cold start (``v = 0``) keeps that, since only
columns on a path change (lowered, and assigned from then on).

Warm starts: any state that satisfies those conditions may be handed in (a partial
assignment with its duals).  Rows and columns can be taken out of the problem
altogether (Murty's fixed pairs) by leaving them out of ``cols`` and never augmenting
those rows: that only removes constraints.

Re-solving after a row lost its column (Murty's children): forbidding the pair
(``A[i, x[i]] = inf``) and taking row ``i`` out keeps the reduced costs >= 0, but in a
rectangular matrix the freed column may have ``v < 0`` and so may not simply stay free.
The matrix is then read as square, with ``nc - nr`` implicit zero rows holding the free
columns (the duals above are feasible for it, the zero rows' potentials being minus the
``v`` of the column each holds, the largest ``v`` of all); the one free column is the
freed one, and one augmenting path ends there (``sink``).  A path may pass through a
zero row: reaching a free column at distance ``h`` lets a zero row move from it to any
column ``j`` at ``h + v[free] - v[j]``; since all free columns share the largest ``v``,
only the first one reached needs expanding.  Every state this leaves again satisfies
the conditions above, for the next child.
"""

from __future__ import annotations

import numpy as np
from .jit import njit

INF = np.inf


@njit(cache=True)
def augment(A, i, sink, x, y, u, v, cols, ncols, d, pred, done, scanned):
    """One shortest augmenting path from the unassigned row ``i`` over the columns
    ``cols[:ncols]``; updates ``x, y, u, v`` in place.

    ``sink < 0``: the path ends at any free column (a cold or partial solve).
    ``sink >= 0``: it ends at that column, and every other free column counts as held by
    one of the ``nc - nr`` implicit zero rows that make the matrix square (Murty's
    re-solve after a row lost its column ``sink``; see the module docstring).
    ``d, pred, done, scanned``: work arrays of length ``nc`` (``done`` all False on
    entry and on return).  Returns the path's length (the rise of the optimum), or
    ``inf`` when no path exists (nothing is changed then).  Ties go to the lowest
    column index, preferring the end of the path: the same path every run.
    """
    for t in range(ncols):
        d[cols[t]] = INF
    r = i                      # row to relax from: >= 0 real, -1 the zero rows, -2 none
    h = 0.0
    ur = 0.0
    vz = 0.0                   # the zero rows' column potential, once reached
    jz = -1
    nscan = 0
    while True:
        best = INF             # relax from row r and pick the nearest column, one pass
        jb = -1
        if r >= 0:
            ur = u[r]
        for t in range(ncols):
            j = cols[t]
            if done[j]:
                continue
            if r >= 0:
                a = A[r, j]
                if a < INF:
                    val = h + (a - ur - v[j])
                    if val < d[j]:
                        d[j] = val
                        pred[j] = r
            elif r == -1:      # reduced cost of a zero row: v[held column] - v[j]
                val = h + (vz - v[j])
                if val < d[j]:
                    d[j] = val
                    pred[j] = -2 - jz
            dj = d[j]
            if dj < best or (dj == best and jb >= 0 and _ends(j, sink, y)
                             and not _ends(jb, sink, y)):
                best = dj
                jb = j
        if jb < 0 or best == INF:
            for t in range(nscan):
                done[scanned[t]] = False
            return INF
        done[jb] = True
        scanned[nscan] = jb
        nscan += 1
        if _ends(jb, sink, y):
            break
        h = best
        if y[jb] >= 0:
            r = y[jb]
        elif jz < 0:           # the first column held by a zero row: expand them once
            r = -1             # (all such columns share the largest v: the others
            jz = jb            # are dominated)
            vz = v[jb]
        else:
            r = -2
    delta = d[jb]
    u[i] += delta
    for t in range(nscan - 1):          # the scanned columns before the end
        j = scanned[t]
        step = delta - d[j]
        v[j] -= step
        if y[j] >= 0:
            u[y[j]] += step
    for t in range(nscan):
        done[scanned[t]] = False
    j = jb
    while True:
        p = pred[j]
        if p >= 0:
            y[j] = p
            nxt = x[p]
            x[p] = j
            if p == i:
                break
            j = nxt
        else:                  # a zero row moves to j from the column it held
            y[j] = -1
            j = -2 - p
    return delta


@njit(cache=True)
def _ends(j, sink, y):
    """Whether a path may end at column ``j``."""
    return j == sink if sink >= 0 else y[j] < 0


@njit(cache=True)
def row_start(A, u):
    """Cold-start row duals ``u[i] = min_j A[i, j]`` (with ``v = 0``); False if a row
    has no allowed entry."""
    for i in range(A.shape[0]):
        m = INF
        for j in range(A.shape[1]):
            if A[i, j] < m:
                m = A[i, j]
        if m == INF:
            return False
        u[i] = m
    return True


@njit(cache=True)
def lap_warm(A, x, y, u, v):
    """Assign every unassigned row of ``A`` (``nr <= nc``) from the state
    ``x, y, u, v`` (see the module docstring), in place.  Returns False when no
    assignment of every row exists (the state is then partial)."""
    nr, nc = A.shape
    cols = np.arange(nc)
    d = np.empty(nc)
    pred = np.empty(nc, np.int64)
    done = np.zeros(nc, np.bool_)
    scanned = np.empty(nc, np.int64)
    free = np.int64(-1)     # not the literal -1: one specialisation of augment, not two
    for i in range(nr):
        if x[i] < 0:
            if augment(A, i, free, x, y, u, v, cols, nc, d, pred, done, scanned) == INF:
                return False
    return True


@njit(cache=True)
def lap(A):
    """Cold solve of ``A`` (``nr <= nc``): ``(ok, col_of_row, u, v, cost)``."""
    nr, nc = A.shape
    x = np.full(nr, -1, np.int64)
    y = np.full(nc, -1, np.int64)
    u = np.zeros(nr)
    v = np.zeros(nc)
    if not row_start(A, u) or not lap_warm(A, x, y, u, v):
        return False, x, u, v, INF
    cost = 0.0
    for i in range(nr):
        cost += A[i, x[i]]
    return True, x, u, v, cost
