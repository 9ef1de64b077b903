"""Exact marginals of a whole problem in one compiled call: clusters, an order per
cluster, the bits of its frontier, and the hypothesis net of each
(:func:`assocopt.solvers.kernels.ehm_net.hypothesis_net`).

Input: ``E`` (K x N), the constraint row of each candidate's entries (``-1`` for a
dummy, the numbering of ``AssignmentProblem.entry_rows``), ``logw`` the candidates'
log weights, ``n`` the number of rows.  Steps (see :mod:`assocopt.ranking.hypothesis_net`
for why):

1. clusters: union-find over the rows each candidate links, numbered by their
   smallest row;
2. order, per cluster: start at a row with the fewest candidates, then take, among the
   rows of the frontier (rows not yet taken that share a candidate with a taken one),
   the one that adds the fewest rows to it (ties: fewest rows not yet taken around
   it, then the smallest row);
3. bits: row ``y`` needs one from the turn of the first candidate that can cover it
   before its own turn, to its own turn; bits are reused once free (at most 64:
   status 3);
4. the net, its status (1: over ``max_nodes``; 2: no hypothesis), ``log Z`` and the
   candidates' probabilities.

After editing ``ehm_net.py`` delete ``__pycache__/ehm_exact.*.nb[ic]`` (numba's cache
does not see a change in a kernel another file calls).
"""

from __future__ import annotations

import numpy as np
from .jit import njit

from .components import _find, labels
from .ehm_net import hypothesis_net

__all__ = ["exact_marginals"]


@njit(cache=True)
def _groups(label, n_groups):
    """CSR of the positions with each label: ``(ptr, members)``, members ascending."""
    ptr = np.zeros(n_groups + 1, np.int64)
    for v in label:
        ptr[v + 1] += 1
    for g in range(n_groups):
        ptr[g + 1] += ptr[g]
    fill = ptr[:-1].copy()
    out = np.empty(len(label), np.int64)
    for i in range(len(label)):
        out[fill[label[i]]] = i
        fill[label[i]] += 1
    return ptr, out


@njit(cache=True)
def exact_marginals(E, logw, n, max_nodes):
    """``(row label, candidate label, P, log Z, status, nodes, frontier)`` per cluster
    (see the module docstring)."""
    K, N = E.shape
    parent = np.arange(n)
    first = np.full(K, -1, np.int64)
    for k in range(K):
        for s in range(N):
            r = E[k, s]
            if r >= 0:
                if first[k] < 0:
                    first[k] = r
                else:
                    a = _find(parent, first[k])
                    b = _find(parent, r)
                    if a != b:
                        parent[max(a, b)] = min(a, b)
    n_comp, label = labels(parent)
    cand_label = np.empty(K, np.int64)
    for k in range(K):
        cand_label[k] = label[first[k]]
    row_ptr, row_of = _groups(label, n_comp)
    cand_ptr, cand_of = _groups(cand_label, n_comp)
    # candidates covering each row (CSR)
    inc_ptr = np.zeros(n + 1, np.int64)
    for k in range(K):
        for s in range(N):
            if E[k, s] >= 0:
                inc_ptr[E[k, s] + 1] += 1
    for r in range(n):
        inc_ptr[r + 1] += inc_ptr[r]
    fill = inc_ptr[:-1].copy()
    inc = np.empty(inc_ptr[n], np.int64)
    for k in range(K):
        for s in range(N):
            r = E[k, s]
            if r >= 0:
                inc[fill[r]] = k
                fill[r] += 1
    P = np.zeros(K)
    log_z = np.zeros(n_comp)
    status = np.zeros(n_comp, np.int64)
    nodes = np.zeros(n_comp, np.int64)
    front_w = np.zeros(n_comp, np.int64)
    pos = np.full(n, -1, np.int64)
    fidx = np.full(n, -1, np.int64)                 # place in the frontier list
    front = np.empty(n, np.int64)
    stamp = np.full(n, -1, np.int64)
    tick = 0
    for c in range(n_comp):
        rows = row_of[row_ptr[c]:row_ptr[c + 1]]
        nc = len(rows)
        # ---- order
        best = rows[0]
        for y in rows:
            if inc_ptr[y + 1] - inc_ptr[y] < inc_ptr[best + 1] - inc_ptr[best]:
                best = y
        nf = 0                                       # frontier: front[:nf]
        for step in range(nc):
            if step > 0:
                best = -1
                b_new = b_around = 0
                for f in range(nf):
                    y = front[f]
                    tick += 1
                    new = 0
                    around = 0
                    for q in range(inc_ptr[y], inc_ptr[y + 1]):
                        k = inc[q]
                        for s in range(N):
                            z = E[k, s]
                            if z >= 0 and z != y and pos[z] < 0 and stamp[z] != tick:
                                stamp[z] = tick
                                around += 1
                                if fidx[z] < 0:
                                    new += 1
                    if best < 0 or new < b_new or (new == b_new and (
                            around < b_around or (around == b_around and y < best))):
                        best, b_new, b_around = y, new, around
                if best < 0:                         # (a disconnected remainder)
                    for y in rows:
                        if pos[y] < 0:
                            best = y
                            break
            pos[best] = step
            if fidx[best] >= 0:                      # out of the frontier: swap-remove
                last = front[nf - 1]
                front[fidx[best]] = last
                fidx[last] = fidx[best]
                fidx[best] = -1
                nf -= 1
            for q in range(inc_ptr[best], inc_ptr[best + 1]):
                k = inc[q]
                for s in range(N):
                    z = E[k, s]
                    if z >= 0 and pos[z] < 0 and fidx[z] < 0:
                        fidx[z] = nf
                        front[nf] = z
                        nf += 1
        # ---- each candidate's turn, each row's first possible cover
        cands = cand_of[cand_ptr[c]:cand_ptr[c + 1]]
        layer = np.empty(len(cands), np.int64)
        for i in range(len(cands)):
            m = nc
            for s in range(N):
                if E[cands[i], s] >= 0:
                    m = min(m, pos[E[cands[i], s]])
            layer[i] = m
        start = np.full(nc, nc, np.int64)             # by turn of the row
        for i in range(len(cands)):
            for s in range(N):
                r = E[cands[i], s]
                if r >= 0 and pos[r] > layer[i]:
                    start[pos[r]] = min(start[pos[r]], layer[i])
        # ---- bits
        slot_end = np.full(64, -1, np.int64)
        slot = np.full(nc, -1, np.int64)              # by turn
        by_start = np.argsort(start, kind="mergesort")
        width = 0
        for t in by_start:
            if start[t] >= t:
                continue
            got = -1
            for s in range(64):
                if slot_end[s] <= start[t]:
                    got = s
                    break
            if got < 0:
                width = 65
                break
            slot[t] = got
            slot_end[got] = t
            width = max(width, got + 1)
        front_w[c] = width
        if width > 64:
            status[c] = 3
            for y in rows:
                pos[y] = -1
            continue
        layer_bit = np.zeros(nc, np.uint64)
        for t in range(nc):
            if slot[t] >= 0:
                layer_bit[t] = np.uint64(1) << np.uint64(slot[t])
        # ---- options by turn
        by = np.argsort(layer, kind="mergesort")
        opt_ptr = np.zeros(nc + 1, np.int64)
        for i in range(len(cands)):
            opt_ptr[layer[i] + 1] += 1
        for t in range(nc):
            opt_ptr[t + 1] += opt_ptr[t]
        opt_mask = np.zeros(len(cands), np.uint64)
        opt_logw = np.empty(len(cands))
        for o in range(len(cands)):
            i = by[o]
            k = cands[i]
            m = np.uint64(0)
            for s in range(N):
                r = E[k, s]
                if r >= 0 and pos[r] > layer[i]:
                    m |= layer_bit[pos[r]]
            opt_mask[o] = m
            opt_logw[o] = logw[k]
        st, lz, prob, nn, _ = hypothesis_net(layer_bit, opt_ptr, opt_mask, opt_logw,
                                             max_nodes)
        status[c] = st
        log_z[c] = lz
        nodes[c] = nn
        if st == 0:
            for o in range(len(cands)):
                P[cands[by[o]]] = prob[o]
        for y in rows:
            pos[y] = -1
    return label, cand_label, P, log_z, status, nodes, front_w
