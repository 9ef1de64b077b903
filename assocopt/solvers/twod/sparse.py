"""Gated (sparse) 2-D assignment with miss costs, never densified.

A tracking scan gates each track to a few measurements: ``n`` up to 10^5 with ``k``
candidates per row.  Pairs with ``w_ij >= rm_i + cm_j`` are dropped first (leaving
both out is never worse, so some optimum avoids them).  The engine is the compiled
shortest-augmenting-path LAP of :mod:`assocopt.solvers.kernels.sparse_lap` (a heap
Dijkstra: a path search touches only the part of the gated graph it reaches, so the
independent clusters of a scan cost what they would solved one by one), on the
smallest of these exact forms:

* no misses at all (``rm``, ``cm`` all ``inf``): the edges as they are, ``n1 = n2``;
* every column may be left out: the *clipped reduced costs* of
  :mod:`assocopt.solvers.twod.dense` in edge-list form, ``n1`` rows by ``n2 + n1``
  columns.  Pair ``(i, j)`` costs ``r_ij = w_ij - cm_j - rm_i`` (``- cm_j`` alone for
  a row that must be assigned) and each row that may be left out gets one private
  column at cost 0 standing for its miss.  Row-complete assignments of this graph and
  2-D solutions correspond one to one (a row on its private column is left out, an
  unused real column is left out), and the costs differ by the constant
  ``sum(cm) + sum of the finite rm``: the same optimum.  With every row free instead,
  the transpose; with both, the smaller side as rows;
* otherwise (some rows *and* some columns must be assigned) the classical
  ``(n1 + n2)``-square augmentation whose dummy block is the transposed edge pattern
  (:func:`assocopt.solvers.twod.lap.augmented_edges`).

Memory grows with the number of edges, not with ``n1 * n2``.  Without numba (a core
dependency) scipy's LAPJVsp (:func:`scipy.sparse.csgraph.min_weight_full_bipartite_matching`)
solves the augmentation instead.  Measured in ``docs/benchmarks-2d.md``.
"""

from __future__ import annotations

import numpy as np

from .lap import LapInfeasibleError, _sparse_lap, augmented_edges

__all__ = ["assign_sparse", "assign_sparse_edges", "prefer_sparse", "prune_dominated",
           "split_candidates", "selected_from_edges"]

#: A candidate list is solved sparse when its matrix has more entries than this ...
SPARSE_MIN_ENTRIES = 1_000
#: ... and fewer than one in this many entries is a candidate.  Measured on random
#: candidate lists with misses: the compiled engine is 1.2 to 4 times faster than
#: densifying from 20 x 20 up at half density or less (1000 x 1000 at half: 118 ms
#: against 139 ms), slower when every pair is a candidate (1000 x 1000: 1.4 times).
SPARSE_DENSITY = 2

_NO_ASSIGNMENT = "no assignment covers every row and column that must be assigned"


def prefer_sparse(sizes: tuple[int, ...], n_edges: int) -> bool:
    """Whether the sparse engine beats densifying ``sizes[0] x sizes[1]``."""
    entries = sizes[0] * sizes[1]
    return entries > SPARSE_MIN_ENTRIES and n_edges * SPARSE_DENSITY < entries


def prune_dominated(rows: np.ndarray, cols: np.ndarray, w: np.ndarray, rm: np.ndarray,
                    cm: np.ndarray) -> np.ndarray:
    """Mask of the pairs worth keeping: those cheaper than leaving both out."""
    bound = rm[rows] + cm[cols]          # inf where a miss is forbidden: always kept
    return w < bound


def split_candidates(problem) -> tuple[np.ndarray, ...]:
    """A 2-D candidate list in one pass: pairs ``(rows, cols, w)`` (0-based) and their
    positions, the miss costs ``rm``, ``cm`` (``inf`` where forbidden) and the
    positions of the miss candidates (``-1`` where forbidden)."""
    n1, n2 = problem.sizes
    T, c = problem.tuples, problem.costs
    a, b = T[:, 0], T[:, 1]
    pos = np.flatnonzero((a > 0) & (b > 0))
    rp = np.flatnonzero(b == 0)
    cp = np.flatnonzero(a == 0)
    rm = np.full(n1, np.inf)
    cm = np.full(n2, np.inf)
    rpos = np.full(n1, -1, np.int64)
    cpos = np.full(n2, -1, np.int64)
    ri, cj = a[rp] - 1, b[cp] - 1
    rm[ri] = c[rp]
    cm[cj] = c[cp]
    rpos[ri] = rp
    cpos[cj] = cp
    return a[pos] - 1, b[pos] - 1, c[pos], pos, rm, cm, rpos, cpos


def selected_from_edges(edge: np.ndarray, cols: np.ndarray, pos: np.ndarray,
                        rpos: np.ndarray, cpos: np.ndarray) -> np.ndarray:
    """Candidate positions of an answer given as the edge of each row (-1: left out):
    the pairs, the rows left out, the columns no pair uses (a ``-1`` position, a
    forbidden miss, is left for the check of :func:`assocopt.solve` to reject)."""
    on = edge >= 0
    e = edge[on]
    unused = np.ones(len(cpos), bool)
    unused[cols[e]] = False
    return np.concatenate([pos[e], rpos[~on], cpos[unused]])


def assign_sparse(n1: int, n2: int, rows: np.ndarray, cols: np.ndarray, w: np.ndarray,
                  rm: np.ndarray, cm: np.ndarray) -> tuple[np.ndarray, str]:
    """Optimal ``col_of_row`` (``-1`` = left out) of a gated problem, and the form used.

    Raises
    ------
    LapInfeasibleError
        When no assignment exists.
    """
    edge, how = assign_sparse_edges(n1, n2, rows, cols, w, rm, cm)
    cor = np.full(n1, -1, np.int64)
    on = edge >= 0
    cor[on] = np.asarray(cols, np.int64)[edge[on]]
    return cor, how


def assign_sparse_edges(n1: int, n2: int, rows: np.ndarray, cols: np.ndarray,
                        w: np.ndarray, rm: np.ndarray, cm: np.ndarray
                        ) -> tuple[np.ndarray, str]:
    """The edge (index into ``rows``/``cols``/``w``) each row is assigned through,
    ``-1`` for a row left out, of an optimal solution; and the form that was solved.

    Raises
    ------
    LapInfeasibleError
        When no assignment exists.
    """
    rows = np.ascontiguousarray(rows, np.int64)
    cols = np.ascontiguousarray(cols, np.int64)
    w = np.ascontiguousarray(w, np.float64)
    free_r, free_c = np.isfinite(rm), np.isfinite(cm)
    all_r, all_c = bool(free_r.all()), bool(free_c.all())
    if not free_r.any() and not free_c.any():
        if n1 != n2:
            raise LapInfeasibleError(f"{n1} rows cannot all meet {n2} columns")
        return _lap(n1, n2, rows, cols, w, len(w)), "sparse"
    kept = np.flatnonzero(prune_dominated(rows, cols, w, rm, cm))
    if len(kept) == len(w):
        kept = None
    else:
        rows, cols, w = rows[kept], cols[kept], w[kept]
    if all_c and (not all_r or n1 <= n2):
        edge = _clipped(n1, n2, rows, cols, w, rm, cm, free_r)
        how = "sparse-reduced"
    elif all_r:
        edge_c = _clipped(n2, n1, cols, rows, w, cm, rm, free_c)
        edge = np.full(n1, -1, np.int64)
        on = edge_c >= 0
        edge[rows[edge_c[on]]] = edge_c[on]
        how = "sparse-reduced-T"
    else:
        size = n1 + n2
        ar, ac, aw = augmented_edges(n1, n2, rows, cols, w, rm, cm)
        edge = _lap(size, size, ar, ac, aw, len(w))[:n1]
        how = "sparse-augmented"
    if kept is not None:
        on = edge >= 0
        edge[on] = kept[edge[on]]
    return edge, how


def _clipped(n_a: int, n_b: int, ra: np.ndarray, cb: np.ndarray, w: np.ndarray,
             am: np.ndarray, bm: np.ndarray, free_a: np.ndarray) -> np.ndarray:
    """Edge of each ``a`` row (-1: left out) on the clipped form; ``bm`` all finite."""
    red = w - bm[cb]
    fa = free_a[ra]
    red[fa] -= am[ra[fa]]
    mine = np.flatnonzero(free_a)               # rows with a private miss column
    er = np.concatenate([ra, mine])
    ec = np.concatenate([cb, n_b + mine])
    ew = np.concatenate([red, np.zeros(len(mine))])
    return _lap(n_a, n_b + n_a, er, ec, ew, len(w))


def _lap(nr: int, nc: int, rows: np.ndarray, cols: np.ndarray, w: np.ndarray,
         n_real: int) -> np.ndarray:
    """Edge of each row in a minimum-cost row-complete assignment; ``-1`` where the
    edge is one of the added ones (index ``>= n_real``)."""
    if nr == 0:
        return np.zeros(0, np.int64)
    kernel = _kernel()
    if kernel is None:
        edge = _scipy_edges(nr, nc, rows, cols, w)
    else:
        from ..kernels import pick
        kernel = pick(kernel, nr, nc, rows, cols, w, work=len(w))
        edge, bad = kernel(nr, nc, rows, cols, w)
        if bad >= 0:
            raise LapInfeasibleError(_NO_ASSIGNMENT)
    edge[edge >= n_real] = -1
    return edge


def _scipy_edges(nr: int, nc: int, rows: np.ndarray, cols: np.ndarray,
                 w: np.ndarray) -> np.ndarray:
    """:func:`_lap` by scipy's LAPJVsp (numba missing): the cheapest edge of each
    matched ``(row, column)`` pair (duplicates cannot occur in the forms above)."""
    if nr > nc:
        raise LapInfeasibleError(_NO_ASSIGNMENT)
    r, c = _sparse_lap(nr, nc, rows, cols, w)
    if len(r) != nr:
        raise LapInfeasibleError(_NO_ASSIGNMENT)
    keys = rows * nc + cols
    order = np.argsort(keys, kind="stable")
    pos = np.searchsorted(keys[order], r * nc + c)
    edge = np.empty(nr, np.int64)
    edge[r] = order[pos]
    return edge


_KERNEL: list = []


def _kernel() -> str | None:
    """The compiled LAP's name for :func:`assocopt.solvers.kernels.pick` (which runs it
    compiled or, on a small problem, interpreted), or None without numba."""
    if not _KERNEL:
        import importlib.util
        _KERNEL.append("sparse_lap.lap_edges" if importlib.util.find_spec("numba")
                       else None)
    return _KERNEL[0]
