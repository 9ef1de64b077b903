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
                patience, lam_min, deflect, recover_every, warm_start, stall_tol, todo,
                work_cap, outcome, ub, lb, chosen, stop):
    """Solve components ``i`` in ``todo`` (in that order), ``i`` = candidates
    ``kp[i]:kp[i+1]`` of ``T`` / ``c`` (local tuples, ``sizes[i]`` their axis sizes).

    Writes per component the driver's outcome into ``outcome`` (``PROVEN``,
    ``STOPPED``, ``INFEASIBLE``; left as it is for components not reached), its
    incumbent's cost into ``ub`` and its bound into ``lb``; ``chosen`` marks the
    selected candidates (of proven components only).  Returns how many of ``todo``
    it solved: it stops when ``stop`` is set, and before a component once the work
    done (candidates x (iterations + nodes), summed) exceeds ``work_cap``.
    """
    N = T.shape[1]
    work = 0.0
    for j in range(todo.shape[0]):
        if stop[0] != 0 or work > work_cap:
            return j
        i = todo[j]
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
            for q in range(n_sel):
                chosen[k0 + sel[q]] = 1
        work += (k1 - k0) * (iters + nodes)
    return todo.shape[0]
