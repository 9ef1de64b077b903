"""2-D linear assignment engines: dense (scipy or lapx), sparse, with miss costs, duals.

This module owns the 2-D LAP: the engines and the augmentations that turn miss costs
into a plain LAP; everything else on the 2-D path (:mod:`.sparse`, :mod:`.dense`,
the ``scipy-lsa`` and ``lapjv`` back ends, the Lagrangian S-D solver
:mod:`assocopt.solvers.lagrangian`) builds on it and it imports none of them at module
level or inside (the compiled sparse LAP comes from :mod:`assocopt.solvers.kernels.sparse_lap`).

* :func:`linear_assignment` -- a dense (possibly rectangular) LAP, ``inf`` = forbidden,
  scipy's semantics (the smaller side fully assigned).  It runs lapx's Jonker-Volgenant
  code (``pip install lapx``) when that package is installed and the matrix is large
  enough for it to pay off, else :func:`scipy.optimize.linear_sum_assignment`.
* :func:`assign_with_misses` -- 2-D assignment with per-row and per-column
  non-assignment ("miss") costs, from a sparse edge list; it picks a dense matrix or,
  for large gated problems (or ``method="sparse"``), the compiled sparse LAP of
  :mod:`assocopt.solvers.kernels.sparse_lap` (numba installed: no scipy matrix built per call, which
  the Lagrangian ascent makes hundreds of times), else scipy's sparse LAPJVsp
  (:func:`scipy.sparse.csgraph.min_weight_full_bipartite_matching`) on the standard
  augmentation whose dummy-dummy block is the transpose of the edge pattern; memory
  grows with the number of edges, not with ``n1 * n2``.
* :func:`augmented_matrix` / :func:`augmented_edges` -- the ``(n1+n2)``-square
  augmentation of 2-D assignment with miss costs, dense or as an edge list.
* :func:`assignment_duals` -- dual-feasible potentials of an optimal assignment
  (shortest paths in the residual graph, vectorised Bellman-Ford), used for
  reduced-cost fixing.  Feasibility is enforced by construction, so the bounds derived
  from them are valid even if the shortest-path sweeps were cut short.
"""

from __future__ import annotations

import importlib.util
import time
from dataclasses import dataclass

import numpy as np

__all__ = ["LapInfeasibleError", "lapx_available", "linear_assignment",
           "assign_with_misses", "Assignment2D", "assignment_duals", "augmented_matrix",
           "augmented_edges", "LAP_METHODS"]

#: Accepted ``method`` values of :func:`linear_assignment` / :func:`assign_with_misses`.
LAP_METHODS = ("auto", "scipy", "lapx", "sparse")

#: Below this many rows lapx's call overhead outweighs its speed (measured, n = 50: lapx
#: 5 us vs scipy 18 us; n = 10: both about 1 us): scipy is used for smaller matrices.
_LAPX_MIN_N = 32

#: Dense augmented matrices up to this many entries are always dense; beyond it the
#: sparse LAP is used when fewer than 1 in _SPARSE_DENSITY entries is an edge.
_DENSE_MAX_ENTRIES = 1_000_000
_SPARSE_DENSITY = 20

_LAPX: bool | None = None


class LapInfeasibleError(ValueError):
    """No assignment covers every required row and column."""


def lapx_available() -> bool:
    """Whether the optional ``lapx`` package (import name ``lap``) is installed."""
    global _LAPX
    if _LAPX is None:
        try:
            _LAPX = importlib.util.find_spec("lap") is not None
        except (ImportError, ValueError):
            _LAPX = False
    return _LAPX


def linear_assignment(C: np.ndarray, method: str = "auto") -> tuple[np.ndarray, np.ndarray]:
    """Dense LAP with scipy's semantics: ``(rows, cols)``, the smaller side fully assigned.

    ``inf`` entries are forbidden.  ``method``: ``"auto"`` (lapx when installed and
    ``min(C.shape) >= 32``, else scipy), ``"scipy"`` or ``"lapx"``.

    Raises
    ------
    LapInfeasibleError
        When no assignment of the smaller side avoids the forbidden entries.

    Examples
    --------
    >>> r, c = linear_assignment(np.array([[4.0, 1.0], [2.0, 3.0]]), method="scipy")
    >>> r.tolist(), c.tolist()
    ([0, 1], [1, 0])
    """
    if method == "lapx" and not lapx_available():
        from ...runtime.errors import SolverNotInstalledError
        raise SolverNotInstalledError("method 'lapx' needs the Python package 'lapx': "
                                      "pip install lapx")
    if method == "lapx" or (method == "auto" and min(C.shape, default=0) >= _LAPX_MIN_N
                            and lapx_available()):
        import lap
        if C.size == 0:
            return np.zeros(0, np.int64), np.zeros(0, np.int64)
        try:
            _, r, c = lap.lapjvh(np.ascontiguousarray(C, np.float64), extend_cost=True)
        except ValueError as exc:
            raise LapInfeasibleError(str(exc)) from exc
        r = np.asarray(r, np.int64)
        c = np.asarray(c, np.int64)
        if len(r) != min(C.shape) or not np.isfinite(C[r, c]).all():
            raise LapInfeasibleError("cost matrix is infeasible")
        order = np.argsort(r, kind="stable")
        return r[order], c[order]
    from scipy.optimize import linear_sum_assignment
    try:
        r, c = linear_sum_assignment(C)
    except ValueError as exc:
        if "infeasible" in str(exc):
            raise LapInfeasibleError(str(exc)) from exc
        raise
    return r.astype(np.int64, copy=False), c.astype(np.int64, copy=False)


@dataclass
class Assignment2D:
    """Result of :func:`assign_with_misses` (0-based; ``-1`` = left unassigned).

    ``col_of_row[i]``: the column of row i; ``row_of_col[j]``: the row of column j;
    ``method``: the engine that ran (``"plain"``, ``"augmented"`` or ``"sparse"``).
    """

    col_of_row: np.ndarray
    row_of_col: np.ndarray
    method: str


def assign_with_misses(n1: int, n2: int, rows: np.ndarray, cols: np.ndarray,
                       weights: np.ndarray, row_miss: np.ndarray, col_miss: np.ndarray,
                       method: str = "auto", dense: np.ndarray | None = None) -> Assignment2D:
    """Minimum-cost 2-D assignment with miss costs, every row and column covered once.

    Row i is matched to one column (edge ``(rows, cols, weights)``, 0-based) or left
    unassigned at ``row_miss[i]``; likewise for columns.  ``inf`` miss costs forbid
    leaving that row or column unassigned.  ``dense``, when given, is the
    ``n1 x n2`` matrix of the same edges (``inf`` elsewhere), saving its construction.

    Raises
    ------
    LapInfeasibleError
        When no such assignment exists.

    Examples
    --------
    >>> a = assign_with_misses(1, 2, np.array([0, 0]), np.array([0, 1]),
    ...                        np.array([10.0, 10.0]), np.array([1.0]), np.array([2.0, 3.0]))
    >>> a.col_of_row.tolist(), a.row_of_col.tolist()
    ([-1], [-1, -1])
    """
    fin_r = np.isfinite(row_miss)
    fin_c = np.isfinite(col_miss)
    col_of_row = np.full(n1, -1, np.int64)
    row_of_col = np.full(n2, -1, np.int64)
    if not fin_r.any() and not fin_c.any():
        if n1 != n2:
            raise LapInfeasibleError(f"{n1} rows cannot all meet {n2} columns")
        if n1 == 0:
            return Assignment2D(col_of_row, row_of_col, "plain")
        if method == "sparse" or (method == "auto" and dense is None
                                  and _prefer_sparse(n1, len(rows))):
            r, c = _sparse_lap(n1, n1, rows, cols, weights)
            how = "sparse"
        else:
            M = dense if dense is not None else _dense(n1, n2, rows, cols, weights)
            r, c = linear_assignment(M, "auto" if method == "sparse" else method)
            how = "plain"
        col_of_row[r] = c
        row_of_col[c] = r
        return Assignment2D(col_of_row, row_of_col, how)
    size = n1 + n2
    ar, ac, aw = augmented_edges(n1, n2, rows, cols, weights, row_miss, col_miss)
    if method == "sparse" or (method == "auto" and _prefer_sparse(size, len(ar))):
        r, c = _compiled_lap(size, ar, ac, aw) if _compiled_sparse() else \
            _sparse_lap(size, size, ar, ac, aw)
        how = "sparse"
    else:
        M = np.full((size, size), np.inf)
        if dense is not None:
            M[:n1, :n2] = dense
        else:
            M[rows, cols] = weights
        M[np.arange(n1), n2 + np.arange(n1)] = row_miss
        M[n1 + np.arange(n2), np.arange(n2)] = col_miss
        M[n1:, n2:] = 0.0
        r, c = linear_assignment(M, method)
        how = "augmented"
    real = (r < n1) & (c < n2)
    col_of_row[r[real]] = c[real]
    row_of_col[c[real]] = r[real]
    return Assignment2D(col_of_row, row_of_col, how)


def _compiled_sparse() -> bool:
    """Whether the compiled sparse LAP (:mod:`assocopt.solvers.kernels.sparse_lap`) can run."""
    from ..base import module_installed
    return module_installed("numba")


def _compiled_lap(size: int, rows, cols, weights) -> tuple[np.ndarray, np.ndarray]:
    """A perfect matching of the square edge list by the compiled sparse LAP (no scipy
    matrix built per call, which the Lagrangian ascent makes hundreds of times)."""
    from ..kernels import pick
    args = (size, size, np.ascontiguousarray(rows, np.int64),
            np.ascontiguousarray(cols, np.int64), np.ascontiguousarray(weights, np.float64))
    edge, bad = pick("sparse_lap.lap_edges", *args, work=len(args[4]))(*args)
    if bad >= 0:
        raise LapInfeasibleError("no perfect matching of the augmented edges")
    return np.arange(size), args[3][edge]


def _prefer_sparse(size: int, n_edges: int) -> bool:
    return size * size > _DENSE_MAX_ENTRIES and n_edges * _SPARSE_DENSITY < size * size


def _dense(n1: int, n2: int, rows, cols, weights) -> np.ndarray:
    M = np.full((n1, n2), np.inf)
    M[rows, cols] = weights
    return M


def augmented_matrix(C: np.ndarray, row_miss: np.ndarray, col_miss: np.ndarray) -> np.ndarray:
    """The ``(n1+n2) x (n2+n1)`` LAP equivalent to 2-D assignment with miss costs.

    Row ``n1 + j`` paired with column ``j`` means column j unassigned; column
    ``n2 + i`` paired with row ``i`` means row i unassigned; dummy rows and dummy
    columns pair with each other at cost 0.
    """
    n1, n2 = C.shape
    big = np.full((n1 + n2, n2 + n1), np.inf)
    big[:n1, :n2] = C
    big[np.arange(n1), n2 + np.arange(n1)] = row_miss
    big[n1 + np.arange(n2), np.arange(n2)] = col_miss
    big[n1:, n2:] = 0.0
    return big


def augmented_edges(n1: int, n2: int, rows: np.ndarray, cols: np.ndarray,
                    weights: np.ndarray, row_miss: np.ndarray, col_miss: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Edges of the ``(n1+n2)``-square augmentation, dummy block = transposed pattern.

    Row ``n1 + j`` paired with column ``j`` leaves column j unassigned; column
    ``n2 + i`` paired with row ``i`` leaves row i unassigned; dummy row ``n1 + j`` meets
    dummy column ``n2 + i`` (cost 0) exactly when ``(i, j)`` is an edge, which is all a
    perfect matching needs: every 2-D solution maps to one of the same cost and back.
    """
    ir = np.flatnonzero(np.isfinite(row_miss))
    jc = np.flatnonzero(np.isfinite(col_miss))
    er = np.concatenate([rows, ir, n1 + jc, n1 + cols])
    ec = np.concatenate([cols, n2 + ir, jc, n2 + rows])
    ew = np.concatenate([weights, row_miss[ir], col_miss[jc], np.zeros(len(rows))])
    return er.astype(np.int64), ec.astype(np.int64), ew


def _sparse_lap(nr: int, nc: int, rows, cols, weights) -> tuple[np.ndarray, np.ndarray]:
    """LAPJVsp on an edge list; weights shifted to be positive (explicit zeros are
    dropped by scipy), which leaves the optimal perfect matching unchanged."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import min_weight_full_bipartite_matching

    if len(weights) == 0:
        raise LapInfeasibleError("no edges")
    w = np.asarray(weights, np.float64)
    lo = float(w.min())
    shift = 1.0 - lo if lo <= 0 else 0.0
    G = sp.csr_matrix((w + shift, (rows, cols)), shape=(nr, nc))
    try:
        r, c = min_weight_full_bipartite_matching(G)
    except ValueError as exc:
        raise LapInfeasibleError(str(exc)) from exc
    return np.asarray(r, np.int64), np.asarray(c, np.int64)


def assignment_duals(size: int, rows: np.ndarray, cols: np.ndarray, weights: np.ndarray,
                     col_of_row: np.ndarray, max_sweeps: int | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Dual-feasible potentials ``(alpha, beta)`` for a square assignment.

    ``weights[e] - alpha[rows[e]] - beta[cols[e]] >= 0`` holds for every edge (by
    construction: ``alpha`` is recomputed from ``beta`` at the end), so
    ``alpha.sum() + beta.sum()`` is a valid lower bound on every perfect matching and
    ``bound + reduced cost of e`` on every perfect matching that uses edge e.  With an
    optimal ``col_of_row`` and converged sweeps the bound equals the optimum.

    ``beta`` is the shortest-path distance from a virtual source in the residual graph
    (arc ``col_of_row[i] -> j`` of weight ``w(i, j) - w(i, col_of_row[i])``), computed by
    vectorised Bellman-Ford sweeps over the edge list.
    """
    rows = np.asarray(rows, np.int64)
    cols = np.asarray(cols, np.int64)
    w = np.asarray(weights, np.float64)
    match_w = np.full(size, np.inf)
    on = col_of_row[rows] == cols
    match_w[rows[on]] = w[on]
    src = col_of_row[rows]
    arc_w = w - match_w[rows]
    keep = ~on & np.isfinite(arc_w)
    src, dst, arc_w = src[keep], cols[keep], arc_w[keep]
    order = np.argsort(dst, kind="stable")
    src, dst, arc_w = src[order], dst[order], arc_w[order]
    if len(dst):
        starts = np.concatenate(([0], np.flatnonzero(dst[1:] != dst[:-1]) + 1))
        targets = dst[starts]
    beta = np.zeros(size)
    sweeps = size if max_sweeps is None else max_sweeps
    for _ in range(sweeps):
        if not len(dst):
            break
        best = np.minimum.reduceat(beta[src] + arc_w, starts)
        cur = beta[targets]
        better = best < cur - 1e-12 * (1.0 + np.abs(cur))
        if not better.any():
            break
        beta[targets[better]] = best[better]
    alpha = np.full(size, np.inf)
    np.minimum.at(alpha, rows, w - beta[cols])
    alpha[~np.isfinite(alpha)] = 0.0   # rows without edges cannot occur in a matching
    return alpha, beta
