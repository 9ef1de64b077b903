"""Murty's ranked assignments, each subproblem solved from its parent's solution and
duals by one shortest augmenting path; compiled with numba.

The matrix ``A`` (``nr x nc``, ``nr <= nc``, ``inf`` = forbidden; every row assigned,
columns free at no cost) is a 2-D problem in LAP form (:mod:`assocopt.ranking.kbest2d` builds
it); its first ``P`` rows are the *real* rows, whose choices of column define a 2-D
solution, any others are dummy rows whose assignment follows from the real rows' (up to
equal-cost permutations among zero-cost dummy entries).  Murty's partition is taken
over the real rows only, so every 2-D solution is reported exactly once, however many
LAP solutions map to it.

A subproblem is ``(fixed rows, forbidden pairs)``.  When the best solution ``x`` of a
subproblem is reported, its free real rows ``r_1 .. r_m`` (in an order chosen below)
give the children "``r_1 .. r_{t-1}`` keep their columns, ``r_t`` loses its column
``x[r_t]``", ``t = 1..m``: every other solution of the subproblem lies in exactly one
child.  A child starts from its parent's ``x`` and duals: forbidding ``(r_t, x[r_t])``
and fixing rows keep the duals feasible (reduced costs stay >= 0), so taking row
``r_t`` out and re-inserting it along one shortest augmenting path that ends at the
freed column (:func:`assocopt.solvers.kernels.sap.augment`, which reads a rectangular
matrix as square with implicit zero rows) gives the child's optimum, at cost
``parent + path length`` (Miller, Stone & Cox 1997; Crouse 2016).

Lazy evaluation: children go on the heap unsolved, keyed by a lower bound on their
cost, and are solved only when they reach the top.  The bound: the path leaves row
``r_t`` by another column and enters the freed column ``x[r_t]`` from another row (or a
zero row), two different edges of reduced cost >= 0, so the child costs at least
``parent + (cheapest other reduced cost in row r_t) + (cheapest other reduced cost
into column x[r_t])``; a child whose bound is infinite is empty and never made.  Order
of the partition: the rows with the largest bounds (taken over the parent's free rows
and columns) are split first, so that the promising children (small bounds, the
likeliest to be expanded next) carry the most fixed rows and are the smallest problems;
each child's bound is then tightened over its own free rows and columns (the rows
split before it, and their columns, are fixed), so that fewer children reach the top
of the heap only to be solved and found dear.

Heap entries ``(key, kind, seq, ...)``: ``kind`` 0 for a solved subproblem (key = its
cost) before 1 for an unsolved one (key = its bound less a rounding tolerance) at equal
keys, then ``seq``, the order of creation: ties are broken the same way on every run.
"""

from __future__ import annotations

import heapq

import numpy as np
from .jit import njit

from .sap import augment, lap_warm, row_start

INF = np.inf


@njit(cache=True)
def _grow(a, cap):
    """The 1-D ``a`` copied into an array of length ``cap`` (a plain loop: slice
    assignment brings numba's broadcasting machinery, seconds of compilation)."""
    b = np.empty(cap, a.dtype)
    for i in range(a.shape[0]):
        b[i] = a[i]
    return b


@njit(cache=True)
def _grow2(a, cap):
    """The 2-D ``a`` (rows = slots) copied into an array of ``cap`` rows (a loop,
    as in :func:`_grow`)."""
    b = np.empty((cap, a.shape[1]), a.dtype)
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            b[i, j] = a[i, j]
    return b


@njit(cache=True)
def _forbid(A, FR, FC, FV, FN, h, on):
    """Set (``on``) or restore (to the values ``FV``) the forbidden pairs of the chain
    starting at ``h``."""
    while h >= 0:
        A[FR[h], FC[h]] = INF if on else FV[h]
        h = FN[h]


@njit(cache=True)
def _active_cols(x, fixed, colfixed, cols):
    """The columns not held by a fixed row, into ``cols``; returns their number."""
    colfixed[:] = False
    for r in range(x.shape[0]):
        if fixed[r]:
            colfixed[x[r]] = True
    n = 0
    for j in range(colfixed.shape[0]):
        if not colfixed[j]:
            cols[n] = j
            n += 1
    return n


@njit(cache=True)
def _bounds(A, x, u, v, fixed, P, cols, ncols, base):
    """The free real rows of a solved subproblem in the order of the partition
    (largest bound first, equal bounds by row index) and their children's lower
    bounds, tightened to each child's own fixed rows (see the module docstring)."""
    nr = A.shape[0]
    m1 = np.full(A.shape[1], INF)   # per column: least reduced cost over active rows,
    m2 = np.full(A.shape[1], INF)   # the second least, and the row of the least
    a1 = np.full(A.shape[1], -1, np.int64)
    active = 0
    for r in range(nr):
        if fixed[r]:
            continue
        active += 1
        ur = u[r]
        for t in range(ncols):
            j = cols[t]
            a = A[r, j]
            if a < INF:
                rc = a - ur - v[j]
                if rc < m1[j]:
                    m2[j] = m1[j]
                    m1[j] = rc
                    a1[j] = r
                elif rc < m2[j]:
                    m2[j] = rc
    vmax = -INF                     # zero rows (free columns) hold the largest v
    if ncols > active:
        for t in range(ncols):
            vmax = max(vmax, v[cols[t]])
    rows = np.empty(P, np.int64)
    b = np.empty(P)
    m = 0
    for r in range(P):
        if fixed[r]:
            continue
        c = x[r]
        ur = u[r]
        rowmin = INF
        for t in range(ncols):
            j = cols[t]
            if j != c and A[r, j] < INF:
                rc = A[r, j] - ur - v[j]
                if rc < rowmin:
                    rowmin = rc
        colmin = m2[c] if a1[c] == r else m1[c]
        if vmax > -INF:
            colmin = min(colmin, vmax - v[c])
        rows[m] = r
        b[m] = INF if rowmin == INF or colmin == INF else \
            base + max(rowmin, 0.0) + max(colmin, 0.0)
        m += 1
    order = np.argsort(-b[:m], kind="mergesort")
    rows = rows[:m][order]
    b = b[:m][order]
    # tighten: child t also has rows[:t] fixed, their columns gone
    gone_r = fixed.copy()
    gone_c = np.zeros(A.shape[1], np.bool_)
    for t in range(m):
        r = rows[t]
        if b[t] < INF:
            c = x[r]
            ur = u[r]
            rowmin = INF
            for q in range(ncols):
                j = cols[q]
                if j != c and not gone_c[j] and A[r, j] < INF:
                    rc = A[r, j] - ur - v[j]
                    if rc < rowmin:
                        rowmin = rc
            colmin = vmax - v[c] if vmax > -INF else INF
            for q in range(nr):
                if q != r and not gone_r[q] and A[q, c] < INF:
                    rc = A[q, c] - u[q] - v[c]
                    if rc < colmin:
                        colmin = rc
            b[t] = INF if rowmin == INF or colmin == INF else \
                base + max(rowmin, 0.0) + max(colmin, 0.0)
        gone_r[r] = True
        gone_c[x[r]] = True
    return rows, b


@njit(cache=True)
def _cost(A, x):
    c = 0.0
    for r in range(x.shape[0]):
        c += A[r, x[r]]
    return c


@njit(cache=True)
def murty(A, P, k, tol):
    """The ``k`` best assignments of ``A`` (see the module docstring).

    Returns ``(cols, costs, n, exhausted, solved)``: ``cols[q, :P]`` the columns of
    the real rows in the ``q``-th best (``q < n``), ``costs[q]`` its cost (float sum
    in row order), ``exhausted`` True when no further solution exists, ``solved`` the
    number of subproblems solved (root included).  ``tol``: subtracted from the lower
    bounds, so that rounding never ranks a child too late.  ``A`` is changed during
    the call (forbidden pairs set to ``inf``) and restored before it returns.
    """
    nr, nc = A.shape
    ocap = min(k, 256)
    out_x = np.empty((ocap, P), np.int64)
    out_c = np.empty(ocap)
    x = np.full(nr, -1, np.int64)
    y = np.full(nc, -1, np.int64)
    u = np.zeros(nr)
    v = np.zeros(nc)
    if not row_start(A, u) or not lap_warm(A, x, y, u, v):
        return out_x[:0], out_c[:0], 0, True, 1
    d = np.empty(nc)
    pred = np.empty(nc, np.int64)
    done = np.zeros(nc, np.bool_)
    scanned = np.empty(nc, np.int64)
    cols = np.empty(nc, np.int64)
    colfixed = np.zeros(nc, np.bool_)
    fixed = np.zeros(nr, np.bool_)
    cap = 64
    SX = np.empty((cap, nr), np.int64)     # per solved subproblem (slot): solution,
    SU = np.empty((cap, nr))               # duals, fixed rows, partition order and
    SV = np.empty((cap, nc))               # its length, forbidden chain, cost
    SF = np.zeros((cap, nr), np.bool_)
    SO = np.empty((cap, P), np.int64)
    SN = np.zeros(cap, np.int64)
    SH = np.full(cap, -1, np.int64)
    SC = np.empty(cap)
    fcap = 256
    FR = np.empty(fcap, np.int64)          # forbidden pairs, as linked lists
    FC = np.empty(fcap, np.int64)
    FN = np.empty(fcap, np.int64)
    FV = np.empty(fcap)
    SX[0] = x
    SU[0] = u
    SV[0] = v
    SC[0] = _cost(A, x)
    nslot = 1
    nf = 0
    seq = 1
    solved = 1
    n = 0
    exhausted = True
    heap = [(SC[0], 0, 0, 0, -1, -1)]
    while len(heap) > 0:
        key, kind, _, s, t, h = heapq.heappop(heap)
        if kind == 1:                      # an unsolved child: solve it now
            if nslot == cap:
                cap *= 2
                SX, SU, SV = _grow2(SX, cap), _grow2(SU, cap), _grow2(SV, cap)
                SF, SO = _grow2(SF, cap), _grow2(SO, cap)
                SN, SH, SC = _grow(SN, cap), _grow(SH, cap), _grow(SC, cap)
            x[:] = SX[s]
            u[:] = SU[s]
            v[:] = SV[s]
            fixed[:] = SF[s]
            for q in range(t):
                fixed[SO[s, q]] = True
            ncols = _active_cols(x, fixed, colfixed, cols)
            y[:] = -1
            for r in range(nr):
                y[x[r]] = r
            i = SO[s, t]
            c = x[i]
            y[c] = -1
            x[i] = -1
            _forbid(A, FR, FC, FV, FN, h, True)
            delta = augment(A, i, c, x, y, u, v, cols, ncols, d, pred, done, scanned)
            _forbid(A, FR, FC, FV, FN, h, False)
            solved += 1
            if delta == INF:
                continue
            if n == k:                     # a further solution exists
                exhausted = False
                break
            SX[nslot] = x
            SU[nslot] = u
            SV[nslot] = v
            SF[nslot] = fixed
            SH[nslot] = h
            SC[nslot] = _cost(A, x)
            heapq.heappush(heap, (SC[nslot], 0, seq, nslot, -1, -1))
            seq += 1
            nslot += 1
            continue
        if n == k:
            exhausted = False
            break
        if n == ocap:
            ocap = min(2 * ocap, k)
            out_x, out_c = _grow2(out_x, ocap), _grow(out_c, ocap)
        out_x[n] = SX[s, :P]
        out_c[n] = SC[s]
        n += 1
        _forbid(A, FR, FC, FV, FN, SH[s], True)
        ncols = _active_cols(SX[s], SF[s], colfixed, cols)
        rows, b = _bounds(A, SX[s], SU[s], SV[s], SF[s], P, cols, ncols, SC[s])
        _forbid(A, FR, FC, FV, FN, SH[s], False)
        m = rows.shape[0]
        SO[s, :m] = rows
        SN[s] = m
        for q in range(m):
            if b[q] == INF:
                continue
            if nf == fcap:
                fcap *= 2
                FR, FC, FN = _grow(FR, fcap), _grow(FC, fcap), _grow(FN, fcap)
                FV = _grow(FV, fcap)
            FR[nf] = rows[q]
            FC[nf] = SX[s, rows[q]]
            FV[nf] = A[rows[q], FC[nf]]
            FN[nf] = SH[s]
            heapq.heappush(heap, (b[q] - tol, 1, seq, s, q, nf))
            seq += 1
            nf += 1
    return out_x[:n], out_c[:n], n, exhausted, solved
