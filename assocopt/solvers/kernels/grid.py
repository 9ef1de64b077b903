"""The Lagrangian subproblem of a dense axial 3-D problem (the ``grid`` case of
:class:`assocopt.solvers.lagrangian.relaxation._Relaxation`: every pair of the two
kept axes holds every index of the relaxed one, in order), compiled.

Per subgradient iteration numpy made a reduced-cost tensor, an ``argmin`` over it and
two scipy LAPs: about 1.2 ms at n = 50 (125 000 candidates), most of it temporaries
and calls.  :func:`grid_eval` fuses the minimum over the relaxed axis with the 2-D
assignment (the Hungarian method warm-started from the previous iteration's column
potentials: successive matrices differ little); :func:`grid_recover` is the primal
recovery (one square LAP on the chosen pairs' rows).
"""

from __future__ import annotations

import numpy as np

from .hungarian import hungarian_warm
from .jit import njit


@njit(cache=True)
def grid_eval(Cg, w, n, v0):
    """``L(u)`` of the grid: ``Cg`` (n*n, m) costs by kept pair, ``w`` (m,) the
    multipliers of the relaxed axis, ``v0`` column potentials to start from (empty:
    cold).  Returns ``(ok, value, chosen, am, gmin, v)``: the chosen pair per row
    (``chosen[i] = i * n + j``), the relaxed index minimising each pair (``am``), the
    pair minima, the LAP's column potentials."""
    G, m = Cg.shape
    am = np.empty(G, np.int64)
    gmin = np.empty(G)
    for g in range(G):
        best = np.inf
        k = 0
        for j in range(m):
            x = Cg[g, j] - w[j]
            if x < best:
                best = x
                k = j
        am[g] = k
        gmin[g] = best
    ok, value, chosen, v = assign_pairs(gmin, n, w, v0)
    return ok, value, chosen, am, gmin, v


@njit(cache=True)
def assign_pairs(gmin, n, w, v0):
    """The 2-D step of ``L(u)``: the square LAP of the pair minima ``gmin`` (n*n,)
    warm-started from ``v0``, and ``L(u)`` (its value plus the multipliers ``w``).
    Returns ``(ok, value, chosen, v)``, ``chosen[i] = i * n + j``."""
    ok, col, _, v, _ = hungarian_warm(gmin.reshape(n, n), v0)
    chosen = np.empty(n, np.int64)
    value = 0.0
    for i in range(n):
        chosen[i] = i * n + col[i]
        value += gmin[chosen[i]]
    for j in range(w.shape[0]):
        value += w[j]
    return ok, value, chosen, v


@njit(cache=True)
def grid_recover(Cg, chosen, v0):
    """The cheapest feasible completion of the chosen pairs: the square LAP of
    ``Cg[chosen]`` (pair x relaxed index).  Returns ``(ok, sel, v)``: the candidates
    (``chosen[i] * m + col[i]``, sorted) and the column potentials."""
    n = chosen.shape[0]
    m = Cg.shape[1]
    M = np.empty((n, m))
    for i in range(n):
        M[i, :] = Cg[chosen[i]]
    ok, col, _, v, _ = hungarian_warm(M, v0)
    sel = np.empty(n, np.int64)
    for i in range(n):
        sel[i] = chosen[i] * m + col[i]
    return ok, np.sort(sel), v
