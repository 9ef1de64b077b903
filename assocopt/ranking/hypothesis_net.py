"""Exact marginals of one cluster by a hypothesis net (the EHM / EHM2 class).

A joint hypothesis is an exact cover of the cluster's real indices (tracks,
measurements, or the measurements of S sensors) by disjoint candidate tuples.  The
indices are put in an order (below); at its turn an index is either already covered
(by a candidate taken at an earlier index) or takes a candidate whose other indices
all come later and are still free.  The state between two turns is the set of *later*
indices already covered, and only indices that some earlier-taken candidate can reach
need a bit: the net's nodes are (turn, state), merged when equal, so the net grows
with the *frontier* of the order, not with the number of joint events.  For a 2-D
problem with tracks first this is EHM2: a node per (track, set of measurements used
so far that later tracks may still want); a measurement takes its turn right after
the last track that gates it, as "used, or clutter".  The compiled sums are in
:mod:`assocopt.solvers.kernels.ehm_net`.

Order: the indices are taken one at a time, each time the one that leaves the
smallest frontier (ties: one already in the frontier, then fewest neighbours left),
and, for large clusters, also the reverse Cuthill-McKee order; the one with the
smaller frontier profile is used.  More than 64 frontier bits, or a net over
``max_nodes`` nodes (``8 * max_nodes`` edges), is :class:`ProblemTooLargeError`
naming the cluster's size: never a silent approximation.
"""

from __future__ import annotations

import heapq

import numpy as np

from ..runtime.errors import ProblemTooLargeError
from ..problems.problem import AssignmentProblem
from .clusters import Cluster

__all__ = ["cluster_marginals", "MAX_NODES", "describe"]

#: Default memory budget of one cluster's net: nodes (about 8 bytes each for the sums)
#: and up to eight times as many edges (12 bytes each): about 250 MB at most.
MAX_NODES = 2_000_000
#: Above this many indices the greedy order (quadratic per step) is not tried.
_GREEDY_MAX = 300


def describe(problem: AssignmentProblem, cluster: Cluster) -> str:
    """``"a cluster of 12 x 15 indices (20 candidates)"``-style size of a cluster."""
    sizes = " x ".join(map(str, cluster.sizes(problem)))
    return f"a cluster of {sizes} indices ({len(cluster.candidates)} candidates)"


def cluster_marginals(problem: AssignmentProblem, cluster: Cluster, logw: np.ndarray,
                      max_nodes: int = MAX_NODES) -> tuple[float, np.ndarray, int]:
    """``(log Z, P, nodes)`` of one cluster: ``logw[c]`` the log weight of candidate
    ``c`` (all of the problem's), ``P`` the marginals of ``cluster.candidates``,
    ``nodes`` the size of the net.  ``log Z`` is ``-inf`` when the cluster has no
    hypothesis."""
    from ..solvers.kernels.ehm_net import hypothesis_net

    rows, cands = cluster.rows, cluster.candidates
    n = len(rows)
    loc = np.full(problem.n_rows, -1, np.int64)
    loc[rows] = np.arange(n)
    R = problem.entry_rows[cands]
    E = np.where(R >= 0, loc[np.maximum(R, 0)], -1)        # local indices, -1 dummy
    order = _order(E, n)
    pos = np.empty(n, np.int64)
    pos[order] = np.arange(n)
    P = np.where(E >= 0, pos[np.maximum(E, 0)], n)          # turn of each entry
    layer = P.min(axis=1)                                   # the candidate's turn
    later = (E >= 0) & (P > layer[:, None])
    start = np.full(n, n, np.int64)                         # first turn that may set it
    np.minimum.at(start, E[later], np.broadcast_to(layer[:, None], E.shape)[later])
    slot = _slots(start, pos)
    if slot.max(initial=-1) >= 64:
        raise ProblemTooLargeError(
            f"method='exact': {describe(problem, cluster)} has a frontier of "
            f"{slot.max() + 1} indices, more than the net's 64; use method='kbest' "
            "or method='lbp'")
    bit = np.where(slot >= 0, np.left_shift(np.uint64(1), np.maximum(slot, 0).astype(np.uint64)),
                   np.uint64(0)).astype(np.uint64)
    ebit = np.where(later, bit[np.maximum(E, 0)], np.uint64(0)).astype(np.uint64)
    mask = np.bitwise_or.reduce(ebit, axis=1) if E.shape[1] else np.zeros(len(E), np.uint64)
    by = np.argsort(layer, kind="stable")
    opt_ptr = np.searchsorted(layer[by], np.arange(n + 1)).astype(np.int64)
    status, log_z, prob, nodes, edges = hypothesis_net(
        np.ascontiguousarray(bit[order]), opt_ptr, np.ascontiguousarray(mask[by]),
        np.ascontiguousarray(logw[cands][by]), int(max_nodes))
    if status == 1:
        raise ProblemTooLargeError(
            f"method='exact': {describe(problem, cluster)} needs a hypothesis net of "
            f"more than max_nodes={max_nodes} nodes (or {8 * max_nodes} edges); raise "
            "max_nodes or use method='kbest' or method='lbp'")
    out = np.zeros(len(cands))
    out[by] = prob
    return float(log_z), out, int(nodes)


def _order(E: np.ndarray, n: int) -> np.ndarray:
    """A processing order of the ``n`` local indices with a small frontier."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    a, b = [], []
    N = E.shape[1]
    for s in range(N):
        for t in range(N):
            if s != t:
                ok = (E[:, s] >= 0) & (E[:, t] >= 0)
                a.append(E[ok, s])
                b.append(E[ok, t])
    a = np.concatenate(a) if a else np.zeros(0, np.int64)
    b = np.concatenate(b) if b else np.zeros(0, np.int64)
    G = sp.csr_matrix((np.ones(len(a), np.int8), (a, b)), shape=(n, n))
    G.sum_duplicates()
    orders = [np.asarray(reverse_cuthill_mckee(G, symmetric_mode=True), np.int64)]
    if n <= _GREEDY_MAX:
        orders.append(_greedy(G.toarray() > 0))
    return min(orders, key=lambda o: _profile(G, o))


def _greedy(A: np.ndarray) -> np.ndarray:
    """Take the index leaving the smallest frontier next (see the module docstring)."""
    n = len(A)
    unproc = np.ones(n, bool)
    front = np.zeros(n, bool)
    left = A.sum(axis=1)
    out = np.empty(n, np.int64)
    for step in range(n):
        U = np.flatnonzero(unproc)
        M = (A[U] | front) & unproc
        M[np.arange(len(U)), U] = False
        score = (M.sum(axis=1) * 2 + ~front[U]) * (n + 1) + left[U]
        t = U[np.argmin(score)]
        out[step] = t
        unproc[t] = False
        front = (front | A[t]) & unproc
        left = left - A[t]
    return out


def _profile(G, order: np.ndarray) -> tuple[int, int]:
    """(largest, total) frontier of ``order``: index y counts from its first
    neighbour's turn until its own."""
    n = len(order)
    pos = np.empty(n, np.int64)
    pos[order] = np.arange(n)
    coo = G.tocoo()
    first = np.full(n, n, np.int64)
    np.minimum.at(first, coo.row, pos[coo.col])
    live = first < pos
    diff = np.zeros(n + 1, np.int64)
    np.add.at(diff, first[live], 1)
    np.add.at(diff, pos[live], -1)
    f = np.cumsum(diff)
    return int(f.max(initial=0)), int(f.sum())


def _slots(start: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """A bit per index over ``[start, pos)`` (-1: none needed), bits reused once free
    (interval colouring, fewest bits)."""
    slot = np.full(len(pos), -1, np.int64)
    need = np.flatnonzero(start < pos)
    busy: list[tuple[int, int]] = []        # (end, slot)
    free: list[int] = []
    used = 0
    for y in need[np.argsort(start[need], kind="stable")]:
        while busy and busy[0][0] <= start[y]:
            heapq.heappush(free, heapq.heappop(busy)[1])
        if free:
            s = heapq.heappop(free)
        else:
            s, used = used, used + 1
        slot[y] = s
        heapq.heappush(busy, (int(pos[y]), s))
    return slot
