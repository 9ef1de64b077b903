"""Dense min-cost perfect matching with potentials (Hungarian method, shortest
augmenting paths), cold or warm-started; compiled with numba."""

from __future__ import annotations

import numpy as np
from .jit import njit

INF = np.inf


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
