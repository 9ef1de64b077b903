"""Compiled rectangular reading (the paper's: each reference pair's 2-D assignment,
then the gate) for all n1 n2 reference pairs of a step, with the distances laid out
for vector instructions.

The rectangular reading needs every distance of every reference pair that has any
entry under its gate exactly (the assignment sees them all), so the distances, not
the lower-bound skip of the dummy reading, dominate its time.  Here each track's
state and covariance (heading term included) are stored once per reference track as
structure-of-arrays, ``X[u, c, i]`` and the upper triangle ``Q[u, k, i]``, so that the
inner loop over the sensor-2 neighbours ``j`` is a straight run of loads, adds,
square roots and divisions over contiguous memory that LLVM turns into SIMD code (the
Cholesky form without branches: a non positive definite ``B`` gives ``inf`` by a final
select).  The assignments are the dense Hungarian kernel of
:mod:`assocopt.solvers.kernels`, as in :mod:`._topology_kernel`, whose plain loop
(:func:`~._topology_kernel.phi_kernel` with ``dummy=False``) this replaces and
against which the tests check it.
"""

from __future__ import annotations

import numpy as np

from ...solvers.kernels.hungarian import hungarian, hungarian_warm
from ...solvers.kernels.jit import njit

INF = np.inf


@njit(cache=True)
def soa(Xr, Pr, J, var, inflate):
    """``(X, Q)``: ``X[u, c, i] = Xr[u, i, c]`` and ``Q[u, k, i]`` the k-th upper
    triangle entry (row-major: 00 01 02 03 11 12 13 22 23 33) of
    ``Pr[u, i] + var[u] J[u, i] J[u, i]^T`` (the heading term only when ``inflate``)."""
    n = Xr.shape[0]
    m = Xr.shape[1]
    X = np.empty((n, 4, m))
    Q = np.empty((n, 10, m))
    for u in range(n):
        a = var[u] if inflate else 0.0
        for i in range(m):
            for c in range(4):
                X[u, c, i] = Xr[u, i, c]
            k = 0
            for r in range(4):
                for c in range(r, 4):
                    Q[u, k, i] = Pr[u, i, r, c] + a * J[u, i, r] * J[u, i, c]
                    k += 1
    return X, Q


@njit(cache=True, error_model="numpy")
def fill_exact(X1, Q1, X2, Q2, u, v, euclid, G):
    """``G[i, j] = gamma_ij(u, v)`` exactly for every (i, j) (the squared Euclidean
    distance of the positions when ``euclid``); ``inf`` where ``B`` is not positive
    definite.  The loop over ``j`` has no branch, so it vectorises."""
    n1 = X1.shape[2]
    n2 = X2.shape[2]
    x2 = X2[v]
    q2 = Q2[v]
    for i in range(n1):
        y0 = X1[u, 0, i]
        y1 = X1[u, 1, i]
        y2 = X1[u, 2, i]
        y3 = X1[u, 3, i]
        if euclid:
            for j in range(n2):
                d0 = y0 - x2[0, j]
                d1 = y1 - x2[1, j]
                G[i, j] = d0 * d0 + d1 * d1
            continue
        a00 = Q1[u, 0, i]
        a01 = Q1[u, 1, i]
        a02 = Q1[u, 2, i]
        a03 = Q1[u, 3, i]
        a11 = Q1[u, 4, i]
        a12 = Q1[u, 5, i]
        a13 = Q1[u, 6, i]
        a22 = Q1[u, 7, i]
        a23 = Q1[u, 8, i]
        a33 = Q1[u, 9, i]
        for j in range(n2):
            d0 = y0 - x2[0, j]
            d1 = y1 - x2[1, j]
            d2 = y2 - x2[2, j]
            d3 = y3 - x2[3, j]
            b00 = a00 + q2[0, j]
            b01 = a01 + q2[1, j]
            b02 = a02 + q2[2, j]
            b03 = a03 + q2[3, j]
            b11 = a11 + q2[4, j]
            b12 = a12 + q2[5, j]
            b13 = a13 + q2[6, j]
            b22 = a22 + q2[7, j]
            b23 = a23 + q2[8, j]
            b33 = a33 + q2[9, j]
            s0 = b00
            l00 = np.sqrt(s0)
            l10 = b01 / l00
            l20 = b02 / l00
            l30 = b03 / l00
            s1 = b11 - l10 * l10
            l11 = np.sqrt(s1)
            l21 = (b12 - l20 * l10) / l11
            l31 = (b13 - l30 * l10) / l11
            s2 = b22 - l20 * l20 - l21 * l21
            l22 = np.sqrt(s2)
            l32 = (b23 - l30 * l20 - l31 * l21) / l22
            s3 = b33 - l30 * l30 - l31 * l31 - l32 * l32
            l33 = np.sqrt(s3)
            z0 = d0 / l00
            z1 = (d1 - l10 * z0) / l11
            z2 = (d2 - l20 * z0 - l21 * z1) / l22
            z3 = (d3 - l30 * z0 - l31 * z1 - l32 * z2) / l33
            g = z0 * z0 + z1 * z1 + z2 * z2 + z3 * z3
            pd = (s0 > 0.0) & (s1 > 0.0) & (s2 > 0.0) & (s3 > 0.0)
            G[i, j] = g if pd else INF


@njit(cache=True)
def _solve_pair(X1, Q1, X2, Q2, u, v, euclid, t, exclude_ref, G, A, col, V, have, warm):
    """The rectangular assignment of reference pair (u, v) into ``col`` (``-1``:
    none), ``G`` its exact distances; False when no entry is under the gate ``t``
    (other than (u, v) when ``exclude_ref``): nothing can be confirmed then.

    ``warm``: start the Hungarian from the column duals ``V[u, v]`` of this pair's
    previous solve where ``have[u, v]`` (the previous step: the matrices change
    little), and store this solve's duals there (speed only; same optimum)."""
    n1 = G.shape[0]
    n2 = G.shape[1]
    n = A.shape[0]
    fill_exact(X1, Q1, X2, Q2, u, v, euclid, G)
    under = 0
    for i in range(n1):
        for j in range(n2):
            if G[i, j] <= t and not (exclude_ref and i == u and j == v):
                under += 1
    if under == 0:
        return False
    for i in range(n):
        for j in range(n):
            A[i, j] = min(G[i, j], 1e300) if (i < n1 and j < n2) else 0.0
    if warm and have[u, v]:
        _, c, _, vd, _ = hungarian_warm(A, V[u, v])
    else:
        _, c, _, vd, _ = hungarian(A)
    if warm:
        V[u, v, :] = vd
        have[u, v] = True
    for i in range(n1):
        col[i] = c[i] if c[i] < n2 else -1
    return True


@njit(cache=True)
def rect_assign_kernel(X1, Q1, X2, Q2, euclid, thr, active, V, have, warm):
    """:func:`~._topology_kernel.assign_kernel` of the rectangular reading on the
    :func:`soa` arrays: ``(cols, gam)``, ``cols[u, v, i]`` the sensor-2 track assigned
    to neighbour i under (u, v) (``-1``: none, or the pair not solved) and
    ``gam[u, v, i]`` its distance (``inf`` where ``cols`` is ``-1``); ``V``, ``have``,
    ``warm`` as in :func:`_solve_pair`."""
    n1 = X1.shape[2]
    n2 = X2.shape[2]
    out = np.full((n1, n2, n1), -1, np.int64)
    gam = np.full((n1, n2, n1), INF)
    G = np.empty((n1, n2))
    A = np.zeros((max(n1, n2), max(n1, n2)))
    col = np.empty(n1, np.int64)
    for u in range(n1):
        for v in range(n2):
            if not active[u, v]:
                continue
            if not _solve_pair(X1, Q1, X2, Q2, u, v, euclid, thr[u, v], False, G, A, col,
                               V, have, warm):
                continue
            for i in range(n1):
                j = col[i]
                if j >= 0:
                    out[u, v, i] = j
                    gam[u, v, i] = G[i, j]
    return out, gam


@njit(cache=True)
def rect_phi_kernel(X1, Q1, X2, Q2, euclid, thr, exclude_ref, min_pairs, active, large,
                    objective, V, have, warm):
    """:func:`~._topology_kernel.phi_kernel` of the rectangular reading on the
    :func:`soa` arrays: ``(phi, M)``, lambda_uv and the confirmed-pair count
    (``V``, ``have``, ``warm`` as in :func:`_solve_pair`)."""
    n1 = X1.shape[2]
    n2 = X2.shape[2]
    phi = np.full((n1, n2), large)
    M = np.zeros((n1, n2), np.int64)
    G = np.empty((n1, n2))
    A = np.zeros((max(n1, n2), max(n1, n2)))
    col = np.empty(n1, np.int64)
    for u in range(n1):
        for v in range(n2):
            t = thr[u, v]
            if not active[u, v] or not _solve_pair(X1, Q1, X2, Q2, u, v, euclid, t,
                                                   exclude_ref, G, A, col,
                                                   V, have, warm):
                continue
            s = 0.0
            m = 0
            for i in range(n1):
                j = col[i]
                if j >= 0 and G[i, j] <= t and not (exclude_ref and i == u and j == v):
                    s += G[i, j]
                    m += 1
            M[u, v] = m
            if m > 0 and m >= min_pairs:
                nn = min(n1, n2) - (1 if exclude_ref else 0)
                phi[u, v] = (s + (nn - m) * t) / nn if objective else s / m
    return phi, M
