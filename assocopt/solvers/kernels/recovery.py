"""The N = 3 primal recovery of ``bnb`` as a sparse LAP (gated problems).

:func:`assocopt.solvers.kernels.driver.recover3` attaches the third axis to the
relaxed solution's kept-axes pairs by a 2-D assignment with misses.  As a square
matrix (pairs and third-axis indices on both sides) it is mostly forbidden entries
on a gated tracking scan, and the dense Hungarian on it took three quarters of
``bnb``'s time on the 300-500-candidate components of such scans (about 1 ms a
call, every ascent iteration).  When every third-axis index has its single-index
candidate, the same assignment is a rectangular LAP on the edges that exist: each
pair row takes a third-axis index ``t`` (cost ``c(pair, t) - c(t alone)``) or its
own miss column (cost ``c(pair alone)``), every index not taken stays alone; the
compiled sparse LAP (:mod:`.sparse_lap`) solves it in microseconds.
"""

from __future__ import annotations

import numpy as np
from .jit import njit

from .sparse_lap import lap_edges

INF = np.inf


@njit(cache=True, nogil=True)
def recover3_sparse(c, base_of, npair, idx, nc, sel):
    """Recovery for pairs ``base_of[:npair]`` (dense lookup offsets into ``idx``),
    every third-axis index having its single-index candidate ``idx[t + 1]``.  Fills
    ``sel``; returns ``(n, cost)``, ``n = -1`` when no assignment exists."""
    alone = 0.0
    for t in range(nc):
        alone += c[idx[t + 1]]
    m = 0
    for g in range(npair):
        if idx[base_of[g]] >= 0:
            m += 1
        for t in range(nc):
            if idx[base_of[g] + t + 1] >= 0:
                m += 1
    rows = np.empty(m, np.int64)
    cols = np.empty(m, np.int64)
    w = np.empty(m)
    cand = np.empty(m, np.int64)
    m = 0
    for g in range(npair):
        k = idx[base_of[g]]
        if k >= 0:
            rows[m] = g
            cols[m] = nc + g
            w[m] = c[k]
            cand[m] = k
            m += 1
        for t in range(nc):
            k = idx[base_of[g] + t + 1]
            if k >= 0:
                rows[m] = g
                cols[m] = t
                w[m] = c[k] - c[idx[t + 1]]
                cand[m] = k
                m += 1
    edge, bad = lap_edges(npair, nc + npair, rows, cols, w)
    if bad >= 0:
        return -1, INF
    taken = np.zeros(nc, np.bool_)
    n = 0
    cost = 0.0
    for g in range(npair):
        e = edge[g]
        sel[n] = cand[e]
        cost += c[cand[e]]
        n += 1
        if cols[e] < nc:
            taken[cols[e]] = True
    for t in range(nc):
        if not taken[t]:
            sel[n] = idx[t + 1]
            cost += c[idx[t + 1]]
            n += 1
    return n, cost
