"""Gated (sparse) 2-D assignment with miss costs, never densified.

A tracking scan gates each track to a few measurements: ``n`` up to 10^5 with ``k``
candidates per row.  The engine is scipy's LAPJVsp
(:func:`scipy.sparse.csgraph.min_weight_full_bipartite_matching`) on the classical
``(n1 + n2)``-square augmentation whose dummy block is the transposed edge pattern
(:func:`assocopt.solvers.lap.augmented_edges`), after dropping every pair with
``w_ij >= rm_i + cm_j``: leaving both out is never worse, so some optimum avoids it.
Memory grows with the number of edges, not with ``n1 * n2``.

Measured (``benchmarks/twod.py``): the rectangular ``n1 x (n2 + n1)`` form that serves
the dense engine so well (one miss column per row, reduced weights) is two to three
times *slower* under LAPJVsp than this square augmentation, so it is not used here.
"""

from __future__ import annotations

import numpy as np

from .lap import LapInfeasibleError, _sparse_lap, augmented_edges

__all__ = ["assign_sparse", "prefer_sparse", "prune_dominated"]

#: A candidate list is solved sparse when its matrix has more entries than this ...
SPARSE_MIN_ENTRIES = 100_000
#: ... and fewer than one in this many entries is a candidate.
SPARSE_DENSITY = 20


def prefer_sparse(sizes: tuple[int, ...], n_edges: int) -> bool:
    """Whether the sparse engine beats densifying ``sizes[0] x sizes[1]``."""
    entries = sizes[0] * sizes[1]
    return entries > SPARSE_MIN_ENTRIES and n_edges * SPARSE_DENSITY < entries


def prune_dominated(rows: np.ndarray, cols: np.ndarray, w: np.ndarray, rm: np.ndarray,
                    cm: np.ndarray) -> np.ndarray:
    """Mask of the pairs worth keeping: those cheaper than leaving both out."""
    bound = rm[rows] + cm[cols]          # inf where a miss is forbidden: always kept
    return w < bound


def assign_sparse(n1: int, n2: int, rows: np.ndarray, cols: np.ndarray, w: np.ndarray,
                  rm: np.ndarray, cm: np.ndarray) -> tuple[np.ndarray, str]:
    """Optimal ``col_of_row`` (``-1`` = left out) of a gated problem, and the form used.

    Raises
    ------
    LapInfeasibleError
        When no assignment exists.
    """
    cor = np.full(n1, -1, np.int64)
    if np.isinf(rm).all() and np.isinf(cm).all():
        if n1 != n2:
            raise LapInfeasibleError(f"{n1} rows cannot all meet {n2} columns")
        if n1 == 0:
            return cor, "sparse"
        r, c = _sparse_lap(n1, n2, rows, cols, w)
        cor[r] = c
        return cor, "sparse"
    keep = prune_dominated(rows, cols, w, rm, cm)
    rows, cols, w = rows[keep], cols[keep], w[keep]
    size = n1 + n2
    r, c = _sparse_lap(size, size, *augmented_edges(n1, n2, rows, cols, w, rm, cm))
    real = (r < n1) & (c < n2)
    cor[r[real]] = c[real]
    return cor, "sparse-augmented"
