"""Compiled inner loop of the topology association: for every reference pair (u, v),
the distance matrix gamma(u, v), its 2-D assignment (dense Hungarian), the gate and
lambda_uv.  One call per time step; :func:`assocopt.tracking.decide.topology.phi_matrix`
is the entry point and :func:`~assocopt.tracking.decide.topology.phi_reference` the
same computation through :func:`assocopt.solve`, one pair at a time (the check)."""

from __future__ import annotations

import numpy as np

from ...solvers.kernels.hungarian import hungarian
from ...solvers.kernels.jit import njit

INF = np.inf


@njit(cache=True)
def _quad4(b00, b01, b02, b03, b11, b12, b13, b22, b23, b33, d0, d1, d2, d3):
    """``d^T B^-1 d`` for a symmetric positive definite 4 x 4 ``B`` given by its upper
    triangle (Cholesky, scalars only); ``inf`` when ``B`` is not positive definite."""
    if b00 <= 0.0:
        return INF
    l00 = np.sqrt(b00)
    l10 = b01 / l00
    l20 = b02 / l00
    l30 = b03 / l00
    s = b11 - l10 * l10
    if s <= 0.0:
        return INF
    l11 = np.sqrt(s)
    l21 = (b12 - l20 * l10) / l11
    l31 = (b13 - l30 * l10) / l11
    s = b22 - l20 * l20 - l21 * l21
    if s <= 0.0:
        return INF
    l22 = np.sqrt(s)
    l32 = (b23 - l30 * l20 - l31 * l21) / l22
    s = b33 - l30 * l30 - l31 * l31 - l32 * l32
    if s <= 0.0:
        return INF
    l33 = np.sqrt(s)
    y0 = d0 / l00
    y1 = (d1 - l10 * y0) / l11
    y2 = (d2 - l20 * y0 - l21 * y1) / l22
    y3 = (d3 - l30 * y0 - l31 * y1 - l32 * y2) / l33
    return y0 * y0 + y1 * y1 + y2 * y2 + y3 * y3


@njit(cache=True)
def _quad2(b00, b01, b11, d0, d1):
    """``d^T B^-1 d`` for a 2 x 2 ``B``: a lower bound of the 4-D form when ``B`` and
    ``d`` are its position block (a marginal's Mahalanobis distance never exceeds the
    joint one); ``inf`` when ``B`` is not positive definite."""
    det = b00 * b11 - b01 * b01
    if b00 <= 0.0 or det <= 0.0:
        return INF
    return (b11 * d0 * d0 - 2.0 * b01 * d0 * d1 + b00 * d1 * d1) / det


@njit(cache=True)
def _entry(x1, p1, j1, x2, p2, j2, a1, a2, euclid, cut):
    """One ``gamma_ij(u, v)`` (or squared Euclidean distance of the positions when
    ``euclid``); the position-block lower bound instead when that is ``>= cut``."""
    d0 = x1[0] - x2[0]
    d1 = x1[1] - x2[1]
    if euclid:
        return d0 * d0 + d1 * d1
    b00 = p1[0, 0] + p2[0, 0] + a1 * j1[0] * j1[0] + a2 * j2[0] * j2[0]
    b01 = p1[0, 1] + p2[0, 1] + a1 * j1[0] * j1[1] + a2 * j2[0] * j2[1]
    b11 = p1[1, 1] + p2[1, 1] + a1 * j1[1] * j1[1] + a2 * j2[1] * j2[1]
    lb = _quad2(b00, b01, b11, d0, d1)
    if lb >= cut:
        return lb
    d2 = x1[2] - x2[2]
    d3 = x1[3] - x2[3]
    b02 = p1[0, 2] + p2[0, 2] + a1 * j1[0] * j1[2] + a2 * j2[0] * j2[2]
    b03 = p1[0, 3] + p2[0, 3] + a1 * j1[0] * j1[3] + a2 * j2[0] * j2[3]
    b12 = p1[1, 2] + p2[1, 2] + a1 * j1[1] * j1[2] + a2 * j2[1] * j2[2]
    b13 = p1[1, 3] + p2[1, 3] + a1 * j1[1] * j1[3] + a2 * j2[1] * j2[3]
    b22 = p1[2, 2] + p2[2, 2] + a1 * j1[2] * j1[2] + a2 * j2[2] * j2[2]
    b23 = p1[2, 3] + p2[2, 3] + a1 * j1[2] * j1[3] + a2 * j2[2] * j2[3]
    b33 = p1[3, 3] + p2[3, 3] + a1 * j1[3] * j1[3] + a2 * j2[3] * j2[3]
    return _quad4(b00, b01, b02, b03, b11, b12, b13, b22, b23, b33, d0, d1, d2, d3)


@njit(cache=True)
def pair_matrix(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v, inflate, euclid, G, cut):
    """Fill ``G[i, j] = gamma_ij(u, v)`` (or the squared Euclidean distance of the
    positions when ``euclid``).  Entries whose position-block lower bound is already
    ``>= cut`` hold that bound instead (pass ``cut = inf`` for exact values)."""
    n1 = X1r.shape[1]
    n2 = X2r.shape[1]
    a1 = var1[u] if inflate else 0.0
    a2 = var2[v] if inflate else 0.0
    for i in range(n1):
        for j in range(n2):
            G[i, j] = _entry(X1r[u, i], P1r[u, i], J1[u, i], X2r[v, j], P2r[v, j],
                             J2[v, j], a1, a2, euclid, cut)


@njit(cache=True)
def _gated_matching(G, t, rows, cols, A):
    """Optimal assignment with a dummy per row and column at ``t / 2`` (entries
    ``min(G - t, 0)``), solved only over the rows and columns that have an entry under
    the gate.  Returns ``col_of_row`` (``-1``: unassigned)."""
    n1, n2 = G.shape
    out = np.full(n1, -1, np.int64)
    nr = 0
    nc = 0
    cidx = np.full(n2, -1, np.int64)
    simple = True
    for i in range(n1):
        k = 0
        last = -1
        for j in range(n2):
            if G[i, j] < t:
                k += 1
                last = j
                if cidx[j] < 0:
                    cidx[j] = nc
                    cols[nc] = j
                    nc += 1
                else:
                    simple = False       # column already wanted by another row
        if k > 0:
            rows[nr] = i
            nr += 1
            if k > 1:
                simple = False
            out[i] = last
    if simple or nr == 0:
        return out
    n = max(nr, nc)
    for a in range(n):
        for b in range(n):
            A[a, b] = 0.0
    for a in range(nr):
        for b in range(nc):
            g = G[rows[a], cols[b]]
            A[a, b] = g - t if g < t else 0.0
    ok, col, _, _, _ = hungarian(A[:n, :n].copy())
    for a in range(nr):
        b = col[a]
        out[rows[a]] = cols[b] if b < nc and A[a, b] < 0.0 else -1
    return out


@njit(cache=True)
def _pair_assignment(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v, inflate, euclid, t,
                     dummy, exclude_ref, G, A, rows, cols, col):
    """The assignment of one reference pair (u, v) into ``col`` (``-1``: none), with
    ``G`` exact wherever ``G <= t``; False (``col`` untouched) when no entry is under
    the gate ``t`` (other than (u, v) when ``exclude_ref``), so nothing can be
    confirmed whatever the assignment -- told by the position-block lower bounds alone.

    ``dummy`` False: the rectangular assignment (the smaller side assigned completely,
    the matrix padded with zero rows or columns, every distance exact); True: a dummy
    per row and column at half the gate, solved over the gated entries only."""
    n1 = X1r.shape[1]
    n2 = X2r.shape[1]
    n = A.shape[0]
    pair_matrix(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v, inflate, euclid, G, t)
    under = 0
    for i in range(n1):
        for j in range(n2):
            if G[i, j] <= t and not (exclude_ref and i == u and j == v):
                under += 1
    if under == 0:
        return False
    if dummy:
        c = _gated_matching(G, t, rows, cols, A)
        for i in range(n1):
            col[i] = c[i]
        return True
    pair_matrix(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v, inflate, euclid, G, INF)
    for i in range(n):
        for j in range(n):
            A[i, j] = min(G[i, j], 1e300) if (i < n1 and j < n2) else 0.0
    _, c, _, _, _ = hungarian(A)
    for i in range(n1):
        col[i] = c[i] if c[i] < n2 else -1
    return True


@njit(cache=True)
def _workspace(n1, n2):
    """The scratch arrays of :func:`_pair_assignment` for ``n1`` x ``n2`` tracks:
    ``(G, A, rows, cols, col)``, ``A`` square of side ``max(n1, n2)``, zeroed."""
    n = max(n1, n2)
    return (np.empty((n1, n2)), np.zeros((n, n)), np.empty(n1, np.int64),
            np.empty(n2, np.int64), np.empty(n1, np.int64))


@njit(cache=True)
def assign_kernel(X1r, P1r, X2r, P2r, J1, var1, J2, var2, inflate, euclid, thr, dummy,
                  active):
    """Every reference pair's assignment: ``(cols, gam)`` with ``cols[u, v, i]`` the
    sensor-2 track assigned to neighbour i under (u, v) (``-1``: none, or the pair
    not solved because nothing is under its gate or it is not ``active``) and
    ``gam[u, v, i]`` its distance (``inf`` where ``cols`` is ``-1``)."""
    n1 = X1r.shape[1]
    n2 = X2r.shape[1]
    out = np.full((n1, n2, n1), -1, np.int64)
    gam = np.full((n1, n2, n1), INF)
    G, A, rows, cols, col = _workspace(n1, n2)
    for u in range(n1):
        for v in range(n2):
            if not active[u, v]:
                continue
            if not _pair_assignment(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v,
                                    inflate, euclid, thr[u, v], dummy, False, G, A,
                                    rows, cols, col):
                continue
            for i in range(n1):
                j = col[i]
                if j >= 0:
                    out[u, v, i] = j
                    gam[u, v, i] = G[i, j]
    return out, gam


@njit(cache=True)
def phi_kernel(X1r, P1r, X2r, P2r, J1, var1, J2, var2, inflate, euclid, thr, dummy,
               exclude_ref, min_pairs, active, large, objective):
    """``(phi, M)``: lambda_uv and the number of confirmed pairs for every (u, v).

    Per pair the assignment of :func:`_pair_assignment` (rectangular, or with dummies
    at half the gate); then the assigned pairs with ``gamma <= t`` are confirmed (the
    pair (u, v) itself not, when ``exclude_ref``).  Pairs with ``active`` False are
    skipped (``large``, 0).  ``objective``: lambda is the assignment's cost per track
    with every unconfirmed track at the gate, ``(sum of confirmed gamma + (N - M) t) /
    N``, ``N = min(n1, n2)`` (less the reference pair when it is left out), instead of
    the mean over the confirmed pairs.
    """
    n1 = X1r.shape[1]
    n2 = X2r.shape[1]
    phi = np.full((n1, n2), large)
    M = np.zeros((n1, n2), np.int64)
    G, A, rows, cols, col = _workspace(n1, n2)
    for u in range(n1):
        for v in range(n2):
            if not active[u, v]:
                continue
            t = thr[u, v]
            if not _pair_assignment(X1r, P1r, X2r, P2r, J1, var1, J2, var2, u, v,
                                    inflate, euclid, t, dummy, exclude_ref, G, A, rows,
                                    cols, col):
                continue
            s = 0.0
            m = 0
            for i in range(n1):
                j = col[i]
                if j < 0:
                    continue
                g = G[i, j]
                if g <= t and not (exclude_ref and i == u and j == v):
                    s += g
                    m += 1
            M[u, v] = m
            if m > 0 and m >= min_pairs:
                if objective:
                    nn = min(n1, n2) - (1 if exclude_ref else 0)
                    phi[u, v] = (s + (nn - m) * t) / nn
                else:
                    phi[u, v] = s / m
    return phi, M
