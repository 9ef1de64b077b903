"""Rectangular linear assignment by shortest augmenting paths, warm-startable
(Jonker-Volgenant / Crouse style, one Dijkstra per row); compiled with numba.

Problem: an ``nr x nc`` matrix ``A`` (``nr <= nc``, ``inf`` = forbidden), every row
assigned to a distinct column, columns free at no cost.  State: ``x[i]`` the column of
row ``i`` (-1: none), ``y[j]`` the row of column ``j`` (-1: free), duals ``u`` (rows),
``v`` (columns) with reduced costs ``A[i, j] - u[i] - v[j] >= 0`` on every allowed
entry and ``= 0`` on the pairs of ``x``.  One augmentation (:func:`augment`) takes an
unassigned row to a free column along the path of least total reduced cost and moves
the duals so that both conditions still hold; when every row is assigned, the duals
prove the assignment optimal.  For a rectangular matrix the proof also needs
``v <= 0``, and ``v[j] = 0`` on free columns: a cold start (``v = 0``) keeps that, since
only columns on a path ever change (and stay assigned).

Warm starts: any state that satisfies those conditions may be handed in (a partial
assignment with its duals).  Forbidding the pair of a row (``A[i, x[i]] = inf``) and
taking the row out keeps the duals feasible, so one augmentation re-solves the matrix
(square matrices: the freed column has no sign condition).  Rows and columns can be
taken out of the problem altogether (Murty's fixed pairs) by leaving them out of
``cols`` and never augmenting those rows: that only removes constraints.
"""

from __future__ import annotations

import numpy as np
from numba import njit

INF = np.inf


@njit(cache=True)
def augment(A, i, x, y, u, v, cols, ncols, d, pred, done, scanned):
    """One shortest augmenting path from the unassigned row ``i`` over the columns
    ``cols[:ncols]``; updates ``x, y, u, v`` in place.

    ``d, pred, done, scanned``: work arrays of length ``nc`` (``done`` all False on
    entry and on return).  Returns the path's length (the rise of the optimum), or
    ``inf`` when no free column can be reached (nothing is changed then).  Ties go to
    the lowest column index, preferring a free column: the same path every run.
    """
    for t in range(ncols):
        d[cols[t]] = INF
    r = i
    h = 0.0
    nscan = 0
    sink = -1
    while True:
        ur = u[r]
        best = INF
        jb = -1
        for t in range(ncols):
            j = cols[t]
            if done[j]:
                continue
            a = A[r, j]
            if a < INF:
                val = h + (a - ur - v[j])
                if val < d[j]:
                    d[j] = val
                    pred[j] = r
            dj = d[j]
            if dj < best or (dj == best and jb >= 0 and y[jb] >= 0 and y[j] < 0):
                best = dj
                jb = j
        if jb < 0 or best == INF:
            for t in range(nscan):
                done[scanned[t]] = False
            return INF
        done[jb] = True
        scanned[nscan] = jb
        nscan += 1
        if y[jb] < 0:
            sink = jb
            break
        r = y[jb]
        h = best
    delta = d[sink]
    u[i] += delta
    for t in range(nscan - 1):          # the scanned columns before the sink
        j = scanned[t]
        step = delta - d[j]
        v[j] -= step
        u[y[j]] += step
    for t in range(nscan):
        done[scanned[t]] = False
    j = sink
    while True:
        r = pred[j]
        y[j] = r
        nxt = x[r]
        x[r] = j
        if r == i:
            break
        j = nxt
    return delta


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
    for i in range(nr):
        if x[i] < 0:
            if augment(A, i, x, y, u, v, cols, nc, d, pred, done, scanned) == INF:
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
