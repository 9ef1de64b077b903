"""Many small S-D problems in one compiled call: ``bnb``'s driver over a batch.

A gated scan splits into hundreds of independent components of a few candidates
each (:mod:`assocopt.solving.decompose`); one ``solve()`` per component would cost far more
in Python than the search itself.  :func:`solve_batch` takes the components'
candidates concatenated (each component's tuples relabelled to its own indices
``1..n_cs``) and runs, for each, the same steps as the ``bnb`` back end: ``prepare``
then the driver's ascent and search (:mod:`.driver`, :func:`.search.dfs`), with the
two largest axes kept.
"""

from __future__ import annotations

import numpy as np
from .jit import njit

from .driver import PROVEN, STOPPED, solve
from .relaxation import prepare

#: Largest dense lookup of the N = 3 primal recovery (as ``bnb.MAX_DENSE``).
MAX_DENSE = 4_000_000


@njit(cache=True)
def _kept(sz):
    """The two largest axes, the lower axis number first on ties (``kept_axes``)."""
    N = sz.shape[0]
    a = 0
    for s in range(1, N):
        if sz[s] > sz[a]:
            a = s
    b = -1
    for s in range(N):
        if s != a and (b < 0 or sz[s] > sz[b]):
            b = s
    return min(a, b), max(a, b)


@njit(cache=True, nogil=True)
def solve_batch(T, c, kp, sizes, tol, max_iter, probe_every, probe_budget, budget, lam0,
                patience, lam_min, deflect, recover_every, warm_start, stall_tol, stop):
    """Solve components ``i`` = candidates ``kp[i]:kp[i+1]`` of ``T`` / ``c`` (local
    tuples, ``sizes[i]`` their axis sizes).

    Returns ``(outcome, ub, bound, chosen)``: per component the driver's outcome
    (``PROVEN``, ``STOPPED``, ``INFEASIBLE``; ``STOPPED`` also for components not
    reached because ``stop`` was set), its incumbent's cost and its bound; ``chosen``
    marks the selected candidates (of proven components only).
    """
    C = kp.shape[0] - 1
    N = T.shape[1]
    outcome = np.full(C, STOPPED, np.int64)
    ub = np.full(C, np.inf)
    lb = np.full(C, -np.inf)
    chosen = np.zeros(T.shape[0], np.int8)
    for i in range(C):
        if stop[0] != 0:
            break
        k0 = kp[i]
        k1 = kp[i + 1]
        Tc = T[k0:k1].copy()
        cc = c[k0:k1].copy()
        sz = sizes[i].copy()
        off = np.zeros(N, np.int64)
        for s in range(1, N):
            off[s] = off[s - 1] + sz[s - 1]
        a, b = _kept(sz)
        G, ptr, lst, y0, axis_of, int_costs, plain = prepare(Tc, off, sz, cc, a, b)
        relaxed = np.empty(N - 2, np.int64)
        m = 0
        for s in range(N):
            if s != a and s != b:
                relaxed[m] = s
                m += 1
        n3 = False
        off_c = 0
        n_c = 0
        if N == 3:
            n_c = sz[relaxed[0]]
            off_c = off[relaxed[0]]
            n3 = (sz[0] + 1) * (sz[1] + 1) * (sz[2] + 1) <= MAX_DENSE
        pa = Tc[:, a].copy()
        pb = Tc[:, b].copy()
        out, sel, n_sel, u, bound, iters, nodes = solve(
            G, pa, pb, cc, relaxed, a, b, off[a], off[b], sz[a], sz[b], plain, axis_of,
            ptr, lst, int_costs, tol, y0, max_iter, probe_every, probe_budget, budget,
            lam0, patience, lam_min, deflect, recover_every, n3, off_c, n_c,
            warm_start, stall_tol, stop)
        outcome[i] = out
        ub[i] = u
        lb[i] = bound
        if out == PROVEN:
            for j in range(n_sel):
                chosen[k0 + sel[j]] = 1
    return outcome, ub, lb, chosen
