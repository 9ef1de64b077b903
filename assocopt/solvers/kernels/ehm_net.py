"""The hypothesis net of an exact-cover problem (EHM class), compiled with numba.

The caller (:mod:`assocopt.ranking.hypothesis_net`) orders the real indices of one
cluster into *layers*; at layer ``l`` index ``x_l`` is either already covered (its bit
is set in the node's key: the node passes, clearing the bit) or takes one of its
*options*: a candidate whose other indices all come later and are still free (their
bits, ``opt_mask``, are clear and become set).  A node is (layer, key), the key the set
of later indices already covered, as bits of ``uint64`` slots; nodes with equal keys
merge (an open-addressing hash table per layer).  Forward (``alpha``) and backward
(``beta``) sums run in log space (per-node log-sum-exp over the edges); the marginal
of an option is ``sum over its edges exp(alpha[parent] + w + beta[child] - log Z)``.

A memory budget: more than ``max_nodes`` nodes or ``8 * max_nodes`` edges in all stops
the build with status 1 (the caller raises a clear error); status 2: no hypothesis.

May import nothing of assocopt (see :mod:`assocopt.solvers.kernels`).
"""

from __future__ import annotations

import numpy as np
from .jit import njit

__all__ = ["hypothesis_net"]


@njit(cache=True)
def _slot(key, size_mask):
    """Start of the probe sequence of ``key`` (xor-folded, masked to the table)."""
    h = key ^ (key >> np.uint64(17)) ^ (key >> np.uint64(31)) ^ (key >> np.uint64(47))
    return np.int64(h & size_mask)


@njit(cache=True)
def _net(layer_bit, opt_ptr, opt_mask, opt_logw, max_nodes, e_par, e_chi, e_opt, alpha):
    """Build the net in the given work arrays and sum it (see the module docstring).
    Returns ``(status, log_Z, option probabilities, nodes, edges)``; ``status`` 0 ok, 1
    over budget, 2 empty, 4 / 5: the edge / node arrays are too small (``nodes`` is
    then the size needed)."""
    L = len(layer_bit)
    n_opt = len(opt_mask)
    prob = np.zeros(n_opt)
    node_ptr = np.zeros(L + 2, np.int64)
    edge_ptr = np.zeros(L + 1, np.int64)
    keys = np.zeros(1, np.uint64)
    alpha[0] = 0.0
    node_ptr[1] = 1
    ne = 0
    zero = np.uint64(0)
    for l in range(L):
        n0 = node_ptr[l]
        n = node_ptr[l + 1] - n0
        bit = layer_bit[l]
        o0 = opt_ptr[l]
        o1 = opt_ptr[l + 1]
        room = n * max(1, o1 - o0)
        if ne + room > 8 * max_nodes:
            room = 8 * max_nodes - ne + 1     # the build stops when it is used up
        if ne + room > len(e_par):
            return 4, -np.inf, prob, ne + room, ne
        size = 16
        while size < 2 * room:
            size *= 2
        size_mask = np.uint64(size - 1)
        t_key = np.empty(size, np.uint64)
        t_id = np.full(size, -1, np.int64)
        new_keys = np.empty(min(room, size), np.uint64)
        nc = 0
        e_start = ne
        for p in range(n):
            key = keys[p]
            passing = bit != zero and (key & bit) != zero
            lo = o1 - 1 if passing else o0
            for o in range(lo, o1):
                if passing:
                    child = key & ~bit
                    oid = -1
                else:
                    m = opt_mask[o]
                    if (key & m) != zero:
                        continue
                    child = key | m
                    oid = o
                if ne - e_start >= room:
                    return 1, -np.inf, prob, node_ptr[l + 1] + nc, ne
                h = _slot(child, size_mask)
                while t_id[h] >= 0 and t_key[h] != child:
                    h = (h + 1) & (size - 1)
                if t_id[h] < 0:
                    t_id[h] = nc
                    t_key[h] = child
                    new_keys[nc] = child
                    nc += 1
                e_par[ne] = n0 + p
                e_chi[ne] = node_ptr[l + 1] + t_id[h]
                e_opt[ne] = oid
                ne += 1
        edge_ptr[l + 1] = ne
        if nc == 0:
            return 2, -np.inf, prob, node_ptr[l + 1], ne
        c0 = node_ptr[l + 1]
        node_ptr[l + 2] = c0 + nc
        if c0 + nc > max_nodes:
            return 1, -np.inf, prob, c0 + nc, ne
        if c0 + nc > len(alpha):
            return 5, -np.inf, prob, c0 + nc, ne
        for c in range(c0, c0 + nc):
            alpha[c] = -np.inf
        for e in range(e_start, ne):
            v = alpha[e_par[e]] + (opt_logw[e_opt[e]] if e_opt[e] >= 0 else 0.0)
            if v > alpha[e_chi[e]]:
                alpha[e_chi[e]] = v
        acc = np.zeros(nc)
        for e in range(e_start, ne):
            c = e_chi[e]
            v = alpha[e_par[e]] + (opt_logw[e_opt[e]] if e_opt[e] >= 0 else 0.0)
            if alpha[c] > -np.inf:
                acc[c - c0] += np.exp(v - alpha[c])
        for c in range(c0, c0 + nc):
            if alpha[c] > -np.inf:
                alpha[c] += np.log(acc[c - c0])
        keys = new_keys[:nc]
    total = node_ptr[L + 1]
    log_z = alpha[total - 1]
    if not log_z > -np.inf:
        return 2, log_z, prob, total, ne
    beta = np.full(total, -np.inf)
    beta[total - 1] = 0.0
    for l in range(L - 1, -1, -1):
        n0 = node_ptr[l]
        n = node_ptr[l + 1] - n0
        for e in range(edge_ptr[l], edge_ptr[l + 1]):
            v = beta[e_chi[e]] + (opt_logw[e_opt[e]] if e_opt[e] >= 0 else 0.0)
            if v > beta[e_par[e]]:
                beta[e_par[e]] = v
        acc = np.zeros(n)
        for e in range(edge_ptr[l], edge_ptr[l + 1]):
            p = e_par[e]
            if beta[p] > -np.inf:
                v = beta[e_chi[e]] + (opt_logw[e_opt[e]] if e_opt[e] >= 0 else 0.0)
                acc[p - n0] += np.exp(v - beta[p])
        for p in range(n0, n0 + n):
            if beta[p] > -np.inf:
                beta[p] += np.log(acc[p - n0])
        for e in range(edge_ptr[l], edge_ptr[l + 1]):
            o = e_opt[e]
            if o >= 0:
                prob[o] += np.exp(alpha[e_par[e]] + opt_logw[o] + beta[e_chi[e]] - log_z)
    return 0, log_z, prob, total, ne


@njit(cache=True)
def hypothesis_net(layer_bit, opt_ptr, opt_mask, opt_logw, max_nodes):
    """Build the net and sum it (see the module docstring).  Returns ``(status, log_Z,
    option probabilities, nodes, edges)``; ``status`` 0 ok, 1 over budget, 2 empty.

    The work arrays are allocated here and the build restarted with larger ones when
    they run out (at least doubling, so at most about twice the work): growing them
    inside the build loop tripled the kernel's compile time (11 s against 4.7 s)."""
    ecap = 1 << 18
    ncap = 1 << 16
    while True:
        e_par = np.empty(ecap, np.int32)
        e_chi = np.empty(ecap, np.int32)
        e_opt = np.empty(ecap, np.int32)
        alpha = np.empty(ncap)
        st, lz, prob, need, ne = _net(layer_bit, opt_ptr, opt_mask, opt_logw, max_nodes,
                                      e_par, e_chi, e_opt, alpha)
        if st == 4:
            ecap = max(need, 2 * ecap)
        elif st == 5:
            ncap = max(need, 2 * ncap)
        else:
            return st, lz, prob, need, ne
